#pragma once
// The device interface rt_core talks to. The USB Falcon and SimFalcon both implement it,
// and rt_core cannot tell them apart except by name() (PX4's rule: only the leaf driver
// changes between hardware and simulation). Values are the Falcon's raw wire values —
// encoder counts in, motor command counts out — so the same kinematics and quantisation
// run in both cases.
#include <array>
#include <cstdint>

#include "fissure/shared/time.hpp"

namespace fissure::falcon {

/// What the host sends each ping-pong (BRIEF §6: three int16 motor commands + flags).
struct DeviceCommand {
  std::array<std::int16_t, 3> motor_counts{};  ///< per-arm motor command, clamped to ±4095
  bool homing_mode = false;                    ///< byte 13 bit 0
  std::uint8_t leds = 0;                       ///< byte 13: 0x2 green, 0x4 blue, 0x8 red
};

/// What the device answers each ping-pong.
struct DeviceReading {
  std::array<std::int16_t, 3> encoder_counts{};  ///< per-arm encoder count since homing
  std::uint8_t buttons = 0;                      ///< low nibble: grip buttons
  std::uint8_t homed_mask = 0;                   ///< bit i: arm i homed
  TimeNs receive_time_ns = 0;                    ///< when the reply was received
};

enum class IoStatus : std::uint8_t {
  kOk = 0,
  kTimeout,       ///< no complete reply within the I/O deadline
  kTornPacket,    ///< bytes arrived but no valid packet yet (parser resynchronising)
  kDisconnected,  ///< device or transport gone; stays so until reopened
  kNotRunning,    ///< device not in its running state (closed, uploading, homing)
};

const char* to_string(IoStatus status) noexcept;

/// A haptic device in its running state. try_exchange() is the only call made from the
/// RT tick: it sends one command and returns the matching reply, bounded in time, never
/// throwing and never allocating.
class HapticDevice {
 public:
  virtual ~HapticDevice() = default;
  [[nodiscard]] virtual const char* name() const noexcept = 0;
  virtual IoStatus try_exchange(const DeviceCommand& command, DeviceReading& reading) noexcept = 0;
};

}  // namespace fissure::falcon
