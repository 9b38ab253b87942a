#pragma once
// Values a scene file may legally hold (the loader's ranges) but that describe no bench a Falcon
// can touch: a 50 m ball (millimetres typed as metres), gravity of −1e9 m/s², Hunt-Crossley
// constants of 1e30, a hand waypoint outside the Falcon's workspace. Each is refused before
// anything runs, in one line naming the field, its value and the plausible range
// (docs/scenes.md, "Plausible values", gives every range and its source).
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

#include "fissure/host_sim/scene_description.hpp"

namespace fissure::session {

struct ImplausibleValue {
  std::string field;      ///< dotted key path as in the file, e.g. "soft_body.radius_m"
  std::string value;      ///< the value with its unit, e.g. "50 m"
  std::string plausible;  ///< the plausible range and why, e.g. "1 mm .. 0.5 m (a specimen on a Falcon's bench)"
};

/// Every implausible value of `scene`, in the order of the file's tables (empty: plausible).
[[nodiscard]] std::vector<ImplausibleValue> implausible_values(const host::SceneDescription& scene);

/// Throws config::SceneError "FILE:LINE: field 'F': V is implausible (plausible: R)" for the first
/// implausible value (the line found by re-reading the scene file; 0 when built in code), and
/// says how many more there are.
void require_plausible(const host::SceneDescription& scene);

/// After settling, the soft body must still rest on the ground. Bullet finds soft-vs-ground
/// contact once per step, so a host step too long for the fall lets the body pass through the
/// ground's box, and everything after is meaningless: throws SessionError naming
/// simulation.time_step_s (the loader's range allows steps this happens at). A body that stayed
/// on the ground but settled to under half its height (a coarse step flattens it; so does a
/// very soft material, which may be meant) gets a one-line warning, returned ("" when none).
[[nodiscard]] std::string check_settled_on_ground(const Eigen::AlignedBox3d& loaded_bounds_world_m,
                                                  const Eigen::AlignedBox3d& settled_bounds_world_m,
                                                  const host::SceneDescription& scene, double settle_s);

/// resolve_scene_path + load_scene + require_plausible: how the commands open a scene.
[[nodiscard]] host::SceneDescription load_plausible_scene(std::string_view name_or_path);

}  // namespace fissure::session
