#include "fissure/rt_core/faults.hpp"

namespace fissure::rt {

const char* fault_name(std::uint32_t fault_bits) noexcept {
  if (fault_bits == 0) return "none";
  if ((fault_bits & kFaultDeviceIo) != 0u) return "device i/o (timeout/torn packet)";
  if ((fault_bits & kFaultDeviceDisconnected) != 0u) return "device disconnected";
  if ((fault_bits & kFaultEncoderJump) != 0u) return "encoder jump";
  if ((fault_bits & kFaultNonFinite) != 0u) return "non-finite value / kinematics failure";
  if ((fault_bits & kFaultProxyInvalid) != 0u) return "invalid proxy";
  if ((fault_bits & kFaultProxyStale) != 0u) return "stale proxy";
  if ((fault_bits & kFlagForceClamped) != 0u) return "force clamped";
  if ((fault_bits & kFlagForceRateLimited) != 0u) return "force rate limited";
  if ((fault_bits & kFlagMotorSaturated) != 0u) return "motor saturated";
  if ((fault_bits & kFlagPassivityActive) != 0u) return "passivity controller active";
  if ((fault_bits & kFlagSoftWall) != 0u) return "soft wall";
  return "unknown";
}

}  // namespace fissure::rt
