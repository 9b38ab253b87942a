#pragma once
// RecordingDevice: a HapticDevice in front of another (SimFalcon or the USB driver) that
// keeps every exchange — reply and command as Falcon wire packets, status, timestamps — for a
// device recording (device_recording.hpp). It answers exactly what the device answered and
// reports the device's own name(), so a recorded session runs as it would unrecorded.
//
// try_exchange() runs in the RT tick: it only pushes into a wait-free ring (never allocates,
// never writes the file); a non-RT thread drains the ring into a RecordingWriter. A full ring
// drops the record and counts it (records_lost()); the file then says so and is not replayed.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "fissure/falcon_hw/device_recording.hpp"
#include "fissure/falcon_hw/haptic_device.hpp"
#include "fissure/shared/clock.hpp"
#include "fissure/shared/spsc_ring.hpp"

namespace fissure::falcon {

class RecordingDevice final : public HapticDevice {
 public:
  /// 16 s of exchanges at 1 kHz between drains (a lockstep host step or a 10 ms real-time
  /// drain is far shorter); ~0.9 MB.
  static constexpr std::size_t kRingCapacity = 16384;

  /// Times count from now on `clock`. `inner` and `clock` must outlive the RecordingDevice.
  RecordingDevice(HapticDevice& inner, const Clock& clock);

  [[nodiscard]] const char* name() const noexcept override { return inner_.name(); }
  IoStatus try_exchange(const DeviceCommand& command, DeviceReading& reading) noexcept override;

  /// Consumer side (one non-RT thread): writes every queued exchange; returns how many.
  std::size_t drain(RecordingWriter& writer);
  [[nodiscard]] std::uint64_t records_lost() const noexcept { return lost_.load(std::memory_order_relaxed); }
  /// `time_ns` on the clock, as a recording time (from the RecordingDevice's construction).
  [[nodiscard]] TimeNs recording_time(TimeNs time_ns) const noexcept { return time_ns - start_ns_; }

 private:
  HapticDevice& inner_;
  const Clock& clock_;
  TimeNs start_ns_;
  std::unique_ptr<SpscRing<RecordedExchange, kRingCapacity>> ring_;
  std::atomic<std::uint64_t> lost_{0};
};

}  // namespace fissure::falcon
