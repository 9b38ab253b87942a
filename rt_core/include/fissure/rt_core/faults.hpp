#pragma once
// Fault state of the rt loop. Every fault drives the force command to zero; each bit says
// how it recovers (see docs/rt_core.md, "Faults"). Bits are reported in every
// TelemetrySample and in DeviceState::status_flags (device faults) so the status line and
// the host see them.
#include <cstdint>

namespace fissure::rt {

enum RtFaultBits : std::uint32_t {
  kFaultNone = 0,
  /// try_exchange() returned kTimeout / kTornPacket / kNotRunning: no trustworthy reading
  /// this tick. Zero command at once; clears after FaultConfig::recovery_ticks consecutive
  /// good exchanges, then the force ramps in again (SafetyConfig::fault_ramp_in_s).
  kFaultDeviceIo = 1u << 0,
  /// try_exchange() returned kDisconnected. Latched: zero command until the loop is
  /// restarted with a reopened device (rt_core cannot reopen USB from the tick).
  kFaultDeviceDisconnected = 1u << 1,
  /// An encoder moved further in one tick than the arm can physically turn
  /// (FaultConfig::max_joint_rate_rad_per_s). The sample is not used; the next one is
  /// judged against it; clears after recovery_ticks plausible samples, then ramp-in.
  kFaultEncoderJump = 1u << 2,
  /// NaN/inf anywhere (angles, FK, velocity, force) or FK did not converge. Zero command,
  /// FK restarts cold next tick; clears after recovery_ticks clean ticks, then ramp-in.
  kFaultNonFinite = 1u << 3,
  /// The newest proxy failed validate(): rejected and counted, the contact force fades to
  /// zero (ProxyConfig::fade_s); clears when a valid proxy arrives (blended back in).
  kFaultProxyInvalid = 1u << 4,
  /// No new proxy for longer than ProxyConfig::stale_after_s: the contact force fades to
  /// zero within fade_s; clears when a fresh valid proxy arrives (faded and blended in).
  kFaultProxyStale = 1u << 5,
  /// Not a fault of the device: the safety stage had to clamp the force magnitude this tick.
  kFlagForceClamped = 1u << 16,
  /// The safety stage limited the force rate this tick.
  kFlagForceRateLimited = 1u << 17,
  /// The motor command saturated at ±4095 (scaled, direction kept).
  kFlagMotorSaturated = 1u << 18,
  /// The passivity controller added damping this tick.
  kFlagPassivityActive = 1u << 19,
  /// The tool is beyond a workspace soft wall.
  kFlagSoftWall = 1u << 20,

  /// Bits that force a zero command immediately (the device side is not trustworthy).
  kDeviceSideFaults = kFaultDeviceIo | kFaultDeviceDisconnected | kFaultEncoderJump | kFaultNonFinite,
  /// Bits that fade the contact force out (the device is fine, the proxy is not).
  kProxySideFaults = kFaultProxyInvalid | kFaultProxyStale,
  kAnyFault = kDeviceSideFaults | kProxySideFaults,
};

/// Short name of the lowest set fault bit ("none" for 0). Static strings, no allocation.
const char* fault_name(std::uint32_t fault_bits) noexcept;

}  // namespace fissure::rt
