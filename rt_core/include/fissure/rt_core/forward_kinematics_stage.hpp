#pragma once
// Pipeline stage: forward kinematics, warm-started from the previous tick's solution
// (falcon_hw's damped Newton: 2–3 iterations at 1 kHz hand speeds). After a failure or a
// device fault the next solve starts cold from the workspace centre, which converges from
// anywhere in the workspace.
#include <Eigen/Core>

#include "fissure/falcon_hw/falcon_geometry.hpp"
#include "fissure/falcon_hw/kinematics.hpp"

namespace fissure::rt {

struct KinematicsState {
  Eigen::Vector3d p_device_m = Eigen::Vector3d::Zero();  ///< last solution (the warm start)
  bool warm = false;                                      ///< p_device_m may seed the next solve
  falcon::FkResult last{};
};

/// True when FK converged to a finite position; on failure the state goes cold.
bool solve_position(const falcon::FalconGeometry& geometry, const falcon::FkOptions& options, KinematicsState& state,
                    const Eigen::Vector3d& theta_rad) noexcept;

}  // namespace fissure::rt
