#pragma once
// Shared by the re-seat tests (host_simulation_test.cpp and tests/app/session_host_test.cpp): the
// spatula scene with its ball anchored as the stress cases anchor it, and a node-distance measure.
#include <algorithm>
#include <variant>
#include <vector>

#include <Eigen/Core>

#include "fissure/host_sim/scene_loader.hpp"

namespace fissure::host::fixture {

/// spatula-sphere with the ball's bottom 1 cm tied to the ground (as the stress cases do), so a
/// tool swept through it drags the ball instead of knocking it away.
inline SceneDescription anchored_spatula_sphere() {
  SceneDescription scene = load_scene(resolve_scene_path("spatula-sphere"));
  const SoftSphere& sphere = std::get<SoftSphere>(scene.soft_bodies.front().shape);
  SoftAnchorBox cap;
  cap.min_world_m = {-0.5, 0.0, -0.5};
  cap.max_world_m = {0.5, sphere.center_world_m[1] - sphere.radius_m + 0.01, 0.5};
  scene.soft_bodies.front().anchors.push_back(cap);
  return scene;
}

/// Largest distance between corresponding nodes of two snapshots [m].
inline double max_distance_m(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b) {
  double out = 0.0;
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) out = std::max(out, (a[i] - b[i]).norm());
  return out;
}

}  // namespace fissure::host::fixture
