#include "fissure/falcon_hw/recording_device.hpp"

namespace fissure::falcon {

RecordingDevice::RecordingDevice(HapticDevice& inner, const Clock& clock)
    : inner_(inner), clock_(clock), start_ns_(clock.now()), ring_(std::make_unique<SpscRing<RecordedExchange, kRingCapacity>>()) {}

IoStatus RecordingDevice::try_exchange(const DeviceCommand& command, DeviceReading& reading) noexcept {
  const TimeNs begin_ns = clock_.now();
  const IoStatus status = inner_.try_exchange(command, reading);
  RecordedExchange record;
  record.exchange_time_ns = begin_ns - start_ns_;
  record.status = status;
  record.command = encode_command(command);
  if (status == IoStatus::kOk) {
    record.receive_offset_ns = reading.receive_time_ns - begin_ns;
    record.reply = encode_reading(reading);
  }
  if (!ring_->try_push(record)) lost_.fetch_add(1, std::memory_order_relaxed);
  return status;
}

std::size_t RecordingDevice::drain(RecordingWriter& writer) {
  std::size_t count = 0;
  RecordedExchange record;
  while (ring_->try_pop(record)) {
    writer.write(record);
    ++count;
  }
  return count;
}

}  // namespace fissure::falcon
