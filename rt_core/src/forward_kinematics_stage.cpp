#include "fissure/rt_core/forward_kinematics_stage.hpp"

namespace fissure::rt {

bool solve_position(const falcon::FalconGeometry& geometry, const falcon::FkOptions& options, KinematicsState& state,
                    const Eigen::Vector3d& theta_rad) noexcept {
  state.last = state.warm ? falcon::forward_kinematics(geometry, theta_rad, state.p_device_m, options)
                          : falcon::forward_kinematics_cold(geometry, theta_rad, state.p_device_m, options);
  state.warm = state.last.converged && state.p_device_m.allFinite();
  return state.warm;
}

}  // namespace fissure::rt
