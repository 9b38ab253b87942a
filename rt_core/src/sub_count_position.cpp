#include "fissure/rt_core/sub_count_position.hpp"

namespace fissure::rt {

void reset(SubCountPositionState& state) noexcept { state = SubCountPositionState{}; }

Eigen::Vector3d update_sub_count_position(SubCountPositionState& state, const Eigen::Vector3d& p_device_m,
                                          const Eigen::Vector3d& v_filtered_m_per_s, double period_s) noexcept {
  if (!state.primed) {
    state.p_device_m = p_device_m;
    state.primed = true;
    return p_device_m;
  }
  const Eigen::Vector3d predicted = state.p_device_m + v_filtered_m_per_s * period_s;
  const Eigen::Vector3d half = Eigen::Vector3d::Constant(kSubCountHalfWidth_m);
  state.p_device_m = predicted.cwiseMax(p_device_m - half).cwiseMin(p_device_m + half);
  return state.p_device_m;
}

}  // namespace fissure::rt
