#pragma once
// ReplayDevice: a HapticDevice that answers from a device recording (device_recording.hpp)
// instead of a Falcon — the hardware-in-the-loop workflow: record on the lab's Falcon, replay
// in CI. Replay is open loop: the grip moves as it moved when recorded, whatever force the
// replayed session commands (the recorded hand answered the recorded forces).
//
// Each exchange answers with the latest record whose time is at or before clock.now() (both
// counted from construction), so any rt rate and any clock replay the same motion. Records
// are consumed in order: of several with the same time (a tick's exchange and the zero command
// sent after the loop stopped) each exchange at that time takes the next one. So on a
// LockstepClock at the recorded rate every exchange gets its own recorded exchange and the
// session is reproduced exactly. Before the first record's time it answers with the first
// record (a replay at a higher rate ticks before the recorded session's first tick, which
// lockstep takes one period after the start); after the last one it holds the last answer for
// kHoldAfterEnd_ns (a replay at
// another host rate stops up to a host step after the recorded session), then reads as
// disconnected (rt_core zeroes the force).
// try_exchange() is noexcept, allocation-free and O(1) amortised.
#include <cstdint>

#include "fissure/falcon_hw/device_recording.hpp"
#include "fissure/falcon_hw/haptic_device.hpp"
#include "fissure/shared/clock.hpp"

namespace fissure::falcon {

struct ReplayCounters {
  std::int64_t exchanges = 0;
  std::int64_t records_used = 0;       ///< distinct records answered with
  /// Exchanges whose command differs from the recorded one: 0 when a session reproduces the
  /// recorded one (same scene, rate, method and host rate), else how far it went its own way.
  std::int64_t commands_differing = 0;
  std::int64_t after_end = 0;          ///< exchanges answered kDisconnected past the recording's end
};

class ReplayDevice final : public HapticDevice {
 public:
  /// How long past the last record the last answer is held [ns]: longer than any host step
  /// (a scene's time_step_s is at most 0.005 s) by a margin, far shorter than a session.
  static constexpr TimeNs kHoldAfterEnd_ns = 250'000'000;

  /// `recording` and `clock` must outlive the ReplayDevice. Throws RecordingError for a
  /// recording without exchanges.
  ReplayDevice(const DeviceRecording& recording, const Clock& clock);

  [[nodiscard]] const char* name() const noexcept override { return "replay"; }
  IoStatus try_exchange(const DeviceCommand& command, DeviceReading& reading) noexcept override;

  [[nodiscard]] const ReplayCounters& counters() const noexcept { return counters_; }

 private:
  const DeviceRecording& recording_;
  const Clock& clock_;
  TimeNs start_ns_;
  TimeNs end_ns_;            ///< last record's time + kHoldAfterEnd_ns
  std::size_t next_ = 0;     ///< first record after the current one
  std::size_t last_used_ = 0;
  ReplayCounters counters_;
};

}  // namespace fissure::falcon
