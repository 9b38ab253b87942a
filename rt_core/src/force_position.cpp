#include "fissure/rt_core/force_position.hpp"

namespace fissure::rt {

Eigen::Vector3d force_position(ForcePositionState& state, const Eigen::Vector3d& p_device_m) noexcept {
  const Eigen::Vector3d previous = state.primed ? state.p_prev_device_m : p_device_m;
  state.p_prev_device_m = p_device_m;
  state.primed = true;
  return p_device_m - kForcePositionPreviousWeight * (p_device_m - previous);
}

double force_position_lag_s(double period_s) noexcept { return kForcePositionPreviousWeight * period_s; }

}  // namespace fissure::rt
