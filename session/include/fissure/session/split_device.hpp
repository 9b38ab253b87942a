#pragma once
// Pieces the ends of a split deployment and `fissure hil latency` share: opening the device an
// rt end drives, a device decorator that times each exchange (the HIL "device round trip"), and
// a clock decorator that remembers when the rt loop last woke (so the HIL benchmark can time
// the tick without touching RtLoop).
#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fissure/falcon_hw/haptic_device.hpp"
#include "fissure/falcon_hw/sim_falcon.hpp"
#include "fissure/shared/clock.hpp"
#include "fissure/shared/transport_spec.hpp"
#include "fissure/session/usb_falcon.hpp"

namespace fissure::session {

/// The device behind an rt end: SimFalcon (optionally with a scene's hand script) or the USB
/// Falcon (opened, firmware checked, homed — setup time, may prompt on stderr).
class SplitDevice {
 public:
  /// Throws SessionError naming the device on failure.
  static std::unique_ptr<SplitDevice> open_sim(const std::optional<HandScript>& hand, const Clock& clock);
  static std::unique_ptr<SplitDevice> open_usb(Clock& clock);
  ~SplitDevice();
  falcon::HapticDevice& device() noexcept;
  /// Null for the USB Falcon.
  [[nodiscard]] const falcon::SimFalcon* sim() const noexcept { return sim_.get(); }

 private:
  SplitDevice() = default;
  std::unique_ptr<falcon::SimFalcon> sim_;
  std::unique_ptr<UsbFalcon> usb_;  ///< null for sim
};

/// Wraps a device and records how long each try_exchange took [ns] into a buffer sized up
/// front (no allocation on the rt thread; exchanges beyond the capacity are only counted).
/// Read the samples after the rt thread stopped.
class TimedDevice final : public falcon::HapticDevice {
 public:
  TimedDevice(falcon::HapticDevice& inner, const Clock& clock, std::size_t capacity);
  /// Forwards the inner name: rt_core tells SimFalcon apart by it.
  [[nodiscard]] const char* name() const noexcept override { return inner_.name(); }
  falcon::IoStatus try_exchange(const falcon::DeviceCommand& command, falcon::DeviceReading& reading) noexcept override;
  [[nodiscard]] const std::vector<TimeNs>& samples_ns() const noexcept { return samples_ns_; }
  [[nodiscard]] std::size_t recorded() const noexcept { return count_ < samples_ns_.size() ? count_ : samples_ns_.size(); }
  [[nodiscard]] std::size_t exchanges() const noexcept { return count_; }

 private:
  falcon::HapticDevice& inner_;
  const Clock& clock_;
  std::vector<TimeNs> samples_ns_;
  std::size_t count_ = 0;
};

/// A clock that forwards to another and remembers the time its last sleep_until() returned:
/// the rt loop's wake-up, so tick time = now() after RtLoop::step() − last_wake_ns().
/// last_wake_ns() is meant for the thread that sleeps (the rt thread).
class WakeRecordingClock final : public Clock {
 public:
  explicit WakeRecordingClock(Clock& inner) noexcept : inner_(inner) {}
  [[nodiscard]] TimeNs now() const noexcept override { return inner_.now(); }
  TimeNs sleep_until(TimeNs deadline) noexcept override {
    last_wake_ns_ = inner_.sleep_until(deadline);
    return last_wake_ns_;
  }
  [[nodiscard]] TimeNs last_wake_ns() const noexcept { return last_wake_ns_; }

 private:
  Clock& inner_;
  TimeNs last_wake_ns_ = 0;
};

/// parse_transport_spec + open_carrier for a split end, with the failures turned into one
/// SessionError line (`can:` on a kernel without AF_CAN lands here). `inproc` is refused
/// with a pointer to `fissure run` (it has no carrier).
std::unique_ptr<transport::FrameCarrier> open_split_carrier(const std::string& text, wire::Role role, const Clock& clock,
                                                            const char* command);

/// Human form of a transport spec for logs: "udp:127.0.0.1:47000".
std::string describe_transport(const transport::TransportSpec& spec);

}  // namespace fissure::session
