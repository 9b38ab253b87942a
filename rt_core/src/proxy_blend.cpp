#include "fissure/rt_core/proxy_blend.hpp"

namespace fissure::rt {

void begin_swap(BlendState& state, const Eigen::Vector3d& old_force_device_n,
                const Eigen::Vector3d& new_force_device_n) noexcept {
  state.offset_device_n += old_force_device_n - new_force_device_n;
}

Eigen::Vector3d blend(BlendState& state, const Eigen::Vector3d& new_force_device_n, double max_step_n) noexcept {
  const double remaining = state.offset_device_n.norm();
  if (remaining <= max_step_n) {
    state.offset_device_n.setZero();
  } else {
    state.offset_device_n *= (remaining - max_step_n) / remaining;
  }
  return new_force_device_n + state.offset_device_n;
}

}  // namespace fissure::rt
