#include "fissure/rt_core/motor_command.hpp"

#include "fissure/falcon_hw/kinematics.hpp"
#include "fissure/falcon_hw/motor_command.hpp"
#include "fissure/rt_core/faults.hpp"

namespace fissure::rt {

bool force_to_command(const falcon::FalconGeometry& geometry, double newton_metre_per_count,
                      const Eigen::Vector3d& p_device_m, const Eigen::Vector3d& force_device_n,
                      falcon::DeviceCommand& command, std::uint32_t& flags) noexcept {
  command.motor_counts = {0, 0, 0};
  if (force_device_n.isZero(0.0)) return true;  // nothing to render: skip J (also off-workspace)
  Eigen::Matrix3d dp_dtheta;
  if (!falcon::jacobian(geometry, p_device_m, dp_dtheta)) {
    flags |= kFaultNonFinite;
    return false;
  }
  const falcon::MotorCommandResult result =
      falcon::force_to_motor_counts(dp_dtheta, force_device_n, newton_metre_per_count);
  if (result.non_finite) {
    flags |= kFaultNonFinite;
    return false;
  }
  if (result.saturated) flags |= kFlagMotorSaturated;
  command.motor_counts = result.counts;
  return true;
}

}  // namespace fissure::rt
