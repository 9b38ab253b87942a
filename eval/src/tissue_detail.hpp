#pragma once
// Small helpers shared by the tissue validations (tissue_validation.hpp).
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "fissure/host_sim/fem_material.hpp"
#include "fissure/host_sim/fem_world.hpp"
#include "fissure/host_sim/soft_body_builder.hpp"

namespace fissure::eval::tissue_detail {

inline Eigen::Vector3d e3(const Vec3& v) { return {v[0], v[1], v[2]}; }

/// Indices of the mesh's vertices that satisfy `keep` (rest positions).
inline std::vector<int> nodes_where(const host::VolumeMesh& mesh, const std::function<bool(const Eigen::Vector3d&)>& keep) {
  std::vector<int> out;
  for (std::size_t i = 0; i < mesh.vertices_m.size(); ++i) {
    if (keep(e3(mesh.vertices_m[i]))) out.push_back(static_cast<int>(i));
  }
  return out;
}

inline Eigen::Vector3d sum_over(const std::vector<Eigen::Vector3d>& f, const std::vector<int>& nodes) {
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  for (int n : nodes) s += f[static_cast<std::size_t>(n)];
  return s;
}

/// Bullet's implicit step as a quasi-static solver (the punch, the cantilever, the vessel): steps
/// of kQuasiStaticStepS, far above the specimens' slowest periods (~0.02–0.1 s), each with 3
/// Newton iterations whose CG may run to 5,000 (Bullet's cap of 300 left the cantilever's tip 6 %
/// short: docs/decisions.md). Gravity as given (zero: none).
inline constexpr double kQuasiStaticStepS = 1.0;
inline host::FemWorldConfig quasi_static_config(const Eigen::Vector3d& gravity_world_m_per_s2 = Eigen::Vector3d::Zero()) {
  host::FemWorldConfig config;
  config.implicit = true;
  config.newton_iterations = 3;
  config.cg_max_iterations = 5000;
  config.gravity_world_m_per_s2 = gravity_world_m_per_s2;
  return config;
}

/// Quasi-static solve with Bullet's implicit step (fem_world.hpp): steps of `step_s` until every
/// node of the body moves slower than `speed_tolerance_m_per_s` (the state no longer changes by
/// more than that × step per step) or `max_steps` are done. Backward Euler at a step near the
/// specimen's slowest period damps every mode strongly, and each step's truncated CG (at most
/// 300 iterations in Bullet) continues from where the last one stopped. Returns the steps taken.
inline int settle_implicit(host::FemWorld& world, int body, double step_s, int max_steps, double speed_tolerance_m_per_s) {
  for (int s = 1; s <= max_steps; ++s) {
    world.step(step_s);
    if (world.max_node_speed_m_per_s(body) < speed_tolerance_m_per_s) return s;
  }
  return max_steps;
}

}  // namespace fissure::eval::tissue_detail
