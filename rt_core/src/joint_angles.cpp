#include "fissure/rt_core/joint_angles.hpp"

#include <cmath>

namespace fissure::rt {

JointCheck encoders_to_joint_angles(const falcon::EncoderMapping& mapping, const FaultConfig& faults,
                                    JointState& state, const std::array<std::int16_t, 3>& counts,
                                    double elapsed_s) noexcept {
  const Eigen::Vector3d theta = falcon::encoders_to_theta(mapping, counts);
  if (!theta.allFinite()) {
    state.have_reference = false;
    return JointCheck::kNonFinite;
  }
  const bool first = !state.have_reference;
  const double allowed_rad = faults.max_joint_rate_rad_per_s * elapsed_s + std::fabs(mapping.radians_per_count);
  const bool jumped = !first && (theta - state.theta_rad).cwiseAbs().maxCoeff() > allowed_rad;
  state.theta_rad = theta;
  state.have_reference = true;
  return jumped ? JointCheck::kJump : JointCheck::kOk;
}

}  // namespace fissure::rt
