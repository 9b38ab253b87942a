#pragma once
// Test helper: deterministic points spread uniformly over the documented workspace ball
// (rejection sampling from the bounding cube, fixed seed), plus points on its surface.
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "fissure/falcon_hw/kinematics.hpp"

namespace fissure::falcon::testing {

inline Eigen::Vector3d workspace_centre() {
  return {kWorkspaceCentre_device_m[0], kWorkspaceCentre_device_m[1], kWorkspaceCentre_device_m[2]};
}

/// `count` points uniform in the ball of radius radius_fraction · kWorkspaceRadius_m.
inline std::vector<Eigen::Vector3d> sample_workspace(std::size_t count, std::uint64_t seed,
                                                     double radius_fraction = 1.0) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  points.reserve(count);
  const double radius = radius_fraction * kWorkspaceRadius_m;
  while (points.size() < count) {
    const Eigen::Vector3d v{unit(rng), unit(rng), unit(rng)};
    if (v.squaredNorm() <= 1.0) points.push_back(workspace_centre() + radius * v);
  }
  return points;
}

/// `count` points on the sphere of radius radius_fraction · kWorkspaceRadius_m.
inline std::vector<Eigen::Vector3d> sample_workspace_surface(std::size_t count, std::uint64_t seed,
                                                             double radius_fraction = 1.0) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  points.reserve(count);
  while (points.size() < count) {
    const Eigen::Vector3d v{gauss(rng), gauss(rng), gauss(rng)};
    if (v.norm() < 1e-6) continue;
    points.push_back(workspace_centre() + radius_fraction * kWorkspaceRadius_m * v.normalized());
  }
  return points;
}

}  // namespace fissure::falcon::testing
