#include "fissure/falcon_hw/replay_device.hpp"

#include <algorithm>

namespace fissure::falcon {

ReplayDevice::ReplayDevice(const DeviceRecording& recording, const Clock& clock)
    : recording_(recording), clock_(clock), start_ns_(clock.now()) {
  if (recording.exchanges.empty()) throw RecordingError("the device recording holds no exchanges: nothing to replay");
  end_ns_ = recording.exchanges.back().exchange_time_ns + kHoldAfterEnd_ns;
}

IoStatus ReplayDevice::try_exchange(const DeviceCommand& command, DeviceReading& reading) noexcept {
  ++counters_.exchanges;
  const TimeNs now_ns = clock_.now();
  const TimeNs t_ns = now_ns - start_ns_;
  const auto& exchanges = recording_.exchanges;
  // Records older than now are passed over; of those at exactly now, this exchange takes one.
  while (next_ < exchanges.size() && exchanges[next_].exchange_time_ns < t_ns) ++next_;
  if (next_ < exchanges.size() && exchanges[next_].exchange_time_ns == t_ns) ++next_;
  if (next_ == 0) next_ = 1;  // before the first record: its answer (see the header)
  if (next_ == exchanges.size() && t_ns > end_ns_) {
    ++counters_.after_end;
    return IoStatus::kDisconnected;
  }
  const RecordedExchange& record = exchanges[next_ - 1];
  if (next_ != last_used_) {
    ++counters_.records_used;
    last_used_ = next_;
  }
  if (encode_command(command) != record.command) ++counters_.commands_differing;
  if (record.status != IoStatus::kOk) return record.status;
  // The file was checked when read (read_recording), so the packet decodes.
  if (!decode_reading(record.reply, reading)) return IoStatus::kTornPacket;
  reading.receive_time_ns = now_ns + record.receive_offset_ns;
  return IoStatus::kOk;
}

}  // namespace fissure::falcon
