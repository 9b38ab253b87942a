#include "fissure/session/scene_plausibility.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <variant>

#include <Eigen/Core>

#include "fissure/config/scene_error.hpp"
#include "fissure/config/table_reader.hpp"
#include "fissure/falcon_hw/falcon_geometry.hpp"
#include "fissure/falcon_hw/kinematics.hpp"
#include "fissure/host_sim/scene_loader.hpp"
#include "fissure/session/session_error.hpp"

namespace fissure::session {
namespace {

// Plausible ranges. A scene is a tissue specimen on a bench a Falcon reaches through a
// device mapping (docs/scenes.md, "Plausible values").
/// Soft body extents [m]: a 1 mm vessel to a 0.5 m organ block.
constexpr double kSoftExtentMin_m = 1e-3;
constexpr double kSoftExtentMax_m = 0.5;
/// Soft body mass [kg]: 0.1 g to 10 kg.
constexpr double kSoftMassMin_kg = 1e-4;
constexpr double kSoftMassMax_kg = 10.0;
/// |gravity| [m/s²]: 0 (no gravity) to 10 g.
constexpr double kGravityMax_m_per_s2 = 100.0;
/// Hunt-Crossley: the force the law gives for 1 cm of indentation over 10 cm² of contact (per
/// unit area) or on one triangle (per triangle) must stay below 1 kN — over a hundred times the
/// Falcon's ~9 N peak force (BRIEF §6); stiffer than that no contact can render.
constexpr double kHcProbeDepth_m = 0.01;
constexpr double kHcProbeArea_m2 = 1e-3;
constexpr double kHcProbeSpeed_m_per_s = 0.1;
constexpr double kHcForceMax_n = 1000.0;
/// The scripted hand's grip [N/m]: arm impedance studies put a relaxed-to-firm grip at
/// ~100–1000 N/m (shared/session_config.hpp); an order of magnitude either side is allowed.
constexpr double kGripStiffnessMin_n_per_m = 10.0;
constexpr double kGripStiffnessMax_n_per_m = 1e4;
/// How far below the ground's top a settled soft node may sit before the body counts as fallen
/// through [m]: Bullet lets a resting node sink into the ground by up to its collision margins.
constexpr double kSettledBelowGroundTolerance_m = 0.005;
/// The longest collision sub-step at which spatula-sphere's ball keeps 95 % of its height after
/// 1 s of settling [s] (measured: docs/scenes.md, "Plausible values").
constexpr double kMaxSettlingSubStep_s = 0.002;
/// A settled body under this fraction of its loaded height is warned about.
constexpr double kSettledHeightWarning = 0.5;

std::string number(double v) {
  char text[64];
  std::snprintf(text, sizeof text, "%.4g", v);
  return text;
}

std::string vector_text(const Vec3& v, const char* unit) {
  return "[" + number(v[0]) + ", " + number(v[1]) + ", " + number(v[2]) + "] " + unit;
}

struct Findings {
  std::vector<ImplausibleValue> list;
  void add(std::string field, std::string value, std::string plausible) {
    list.push_back({std::move(field), std::move(value), std::move(plausible)});
  }
  void extent(const std::string& field, double v) {
    if (v < kSoftExtentMin_m || v > kSoftExtentMax_m) {
      add(field, number(v) + " m", "1 mm .. 0.5 m, a specimen on the Falcon's bench (millimetres typed as metres?)");
    }
  }
};

void check_soft_body(const host::SceneDescription& scene, Findings& out) {
  const host::SoftBodyDescription& soft = scene.soft_bodies.front();
  if (const auto* s = std::get_if<host::SoftSphere>(&soft.shape)) {
    out.extent("soft_body.radius_m", s->radius_m);
  } else if (const auto* c = std::get_if<host::SoftCylinder>(&soft.shape)) {
    out.extent("soft_body.radius_m", c->radius_m);
    out.extent("soft_body.length_m", c->length_m);
  } else if (const auto* b = std::get_if<host::SoftSlab>(&soft.shape)) {
    for (double e : b->size_m) {
      if (e < kSoftExtentMin_m || e > kSoftExtentMax_m) {
        out.add("soft_body.size_m", vector_text(b->size_m, "m"), "every extent 1 mm .. 0.5 m, a specimen on the Falcon's bench");
        break;
      }
    }
  } else if (const auto* m = std::get_if<host::SoftMesh>(&soft.shape)) {
    // The mesh's bounding box: a file in millimetres read as metres is 1000 times too large.
    Vec3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
    for (const Vec3& v : m->vertices_world_m) {
      for (std::size_t k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], v[k]);
        hi[k] = std::max(hi[k], v[k]);
      }
    }
    const Vec3 size{hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
    for (double e : size) {
      if (e < kSoftExtentMin_m || e > kSoftExtentMax_m) {
        out.add("soft_body.mesh_path", "a mesh of " + vector_text(size, "m"),
                "every extent 1 mm .. 0.5 m, a specimen on the Falcon's bench (a file in millimetres read as metres?)");
        break;
      }
    }
  }
  if (soft.mass_kg < kSoftMassMin_kg || soft.mass_kg > kSoftMassMax_kg) {
    out.add("soft_body.mass_kg", number(soft.mass_kg) + " kg", "0.1 g .. 10 kg, a tissue specimen");
  }
}

void check_simulation(const host::SceneDescription& scene, Findings& out) {
  const double g = as_eigen(scene.simulation.gravity_world_m_per_s2).norm();
  if (g > kGravityMax_m_per_s2) {
    out.add("simulation.gravity_world_m_per_s2", vector_text(scene.simulation.gravity_world_m_per_s2, "m/s²"),
            "|g| 0 .. 100 m/s² (Earth: 9.81)");
  }
}

void check_tool(const host::SceneDescription& scene, Findings& out) {
  if (scene.device_mapping.clamp_mode && scene.tool.kind != host::ToolKind::kClamp) {
    out.add("device_mapping.clamp_mode", "true", "false: tool.kind is not 'clamp', so no jaws close along the clamp axis");
  }
}

void check_hunt_crossley(const host::SceneDescription& scene, Findings& out) {
  const host::HuntCrossleyParams& hc = scene.hunt_crossley;
  const double area = hc.per_unit_area ? kHcProbeArea_m2 : 1.0;
  const double depth_pow = std::pow(kHcProbeDepth_m, hc.n);
  const double k_max = kHcForceMax_n / (depth_pow * area);
  const double lambda_max = kHcForceMax_n / (depth_pow * kHcProbeSpeed_m_per_s * area);
  const std::string probe = hc.per_unit_area ? "over 10 cm²" : "on one triangle";
  const std::string k_key = hc.per_unit_area ? "hunt_crossley.stiffness_pa_per_m_pow_n" : "hunt_crossley.stiffness_n_per_m_pow_n";
  const std::string l_key =
      hc.per_unit_area ? "hunt_crossley.damping_pa_s_per_m_pow_n_plus_1" : "hunt_crossley.damping_n_s_per_m_pow_n_plus_1";
  if (hc.k > k_max) {
    out.add(k_key, number(hc.k), "0 .. " + number(k_max) + " at exponent " + number(hc.n) + ": 1 cm of indentation " + probe +
                                     " gives at most 1 kN, over 100x the Falcon's ~9 N");
  }
  if (hc.lambda > lambda_max) {
    out.add(l_key, number(hc.lambda), "0 .. " + number(lambda_max) + " at exponent " + number(hc.n) + ": 1 cm at 0.1 m/s " +
                                          probe + " gives at most 1 kN of damping force");
  }
}

void check_hand(const host::SceneDescription& scene, Findings& out) {
  const HandScript& hand = scene.hand;
  if (hand.grip_stiffness_n_per_m < kGripStiffnessMin_n_per_m || hand.grip_stiffness_n_per_m > kGripStiffnessMax_n_per_m) {
    out.add("hand.grip_stiffness_n_per_m", number(hand.grip_stiffness_n_per_m) + " N/m",
            "10 .. 1e4 N/m (a human grip: ~100 to 1000 N/m)");
  }
  const falcon::FalconGeometry geometry;
  char workspace[128];
  std::snprintf(workspace, sizeof workspace, "inside the Falcon's workspace, the %.0f mm ball around [%.3g, %.3g, %.3g] m (device frame)",
                falcon::kWorkspaceRadius_m * 1e3, falcon::kWorkspaceCentre_device_m[0], falcon::kWorkspaceCentre_device_m[1],
                falcon::kWorkspaceCentre_device_m[2]);
  const auto reachable = [&](const Vec3& p) { return falcon::in_workspace(geometry, as_eigen(p)); };
  if (!reachable(hand.start_position_device_m)) {
    out.add("hand.start_position_device_m", vector_text(hand.start_position_device_m, "m"), workspace);
  }
  for (std::size_t i = 0; i < hand.waypoints.size(); ++i) {
    if (!reachable(hand.waypoints[i].position_device_m)) {
      out.add("hand.waypoint[" + std::to_string(i) + "].position_device_m", vector_text(hand.waypoints[i].position_device_m, "m"),
              workspace);
    }
  }
}

void check_trajectory(const host::SceneDescription& scene, Findings& out) {
  const double ground_y = scene.ground.top_height_m;
  const std::string above = "world y >= " + number(ground_y) + " m, the ground's top (the tool would start inside the ground)";
  if (scene.trajectory.start.position_world_m[1] < ground_y) {
    out.add("trajectory.start_position_world_m", vector_text(scene.trajectory.start.position_world_m, "m"), above);
  }
  for (std::size_t i = 0; i < scene.trajectory.waypoints.size(); ++i) {
    const Vec3& p = scene.trajectory.waypoints[i].position_world_m;
    if (p[1] < ground_y) out.add("trajectory.waypoint[" + std::to_string(i) + "].position_world_m", vector_text(p, "m"), above);
  }
}

}  // namespace

std::vector<ImplausibleValue> implausible_values(const host::SceneDescription& scene) {
  Findings out;
  check_simulation(scene, out);
  check_soft_body(scene, out);
  check_tool(scene, out);
  check_hunt_crossley(scene, out);
  check_hand(scene, out);
  check_trajectory(scene, out);
  return out.list;
}

void require_plausible(const host::SceneDescription& scene) {
  const std::vector<ImplausibleValue> found = implausible_values(scene);
  if (found.empty()) return;
  const ImplausibleValue& first = found.front();
  const int line = scene.source_path.empty() ? 0 : config::line_of_field(scene.source_path, first.field);
  std::string message = first.value + " is implausible (plausible: " + first.plausible + ")";
  if (found.size() > 1) {
    message += "; " + std::to_string(found.size() - 1) + " more implausible value" + (found.size() > 2 ? "s" : "") + ", first ";
    message += found[1].field;
  }
  throw config::SceneError(scene.source_path.empty() ? scene.name : scene.source_path, line, first.field, message);
}

std::string check_settled_on_ground(const Eigen::AlignedBox3d& loaded_bounds_world_m, const Eigen::AlignedBox3d& settled_bounds_world_m,
                                    const host::SceneDescription& scene, double settle_s) {
  // Anchored bodies are tied to the ground and an unsettled one has not fallen yet.
  if (settle_s <= 0.0 || !scene.soft_bodies.front().anchors.empty()) return {};
  const double lowest_y = settled_bounds_world_m.min().y();
  const double ground_y = scene.ground.top_height_m;
  const double tolerance_m = std::max(kSettledBelowGroundTolerance_m, 2.0 * scene.soft_bodies.front().collision_margin_m);
  const std::string step = "simulation.time_step_s = " + number(scene.simulation.time_step_s) + " s with substeps_count = " +
                           std::to_string(scene.simulation.substeps_count);
  const std::string advice = "use a collision sub-step (time_step_s / substeps_count) of at most " + number(kMaxSettlingSubStep_s) +
                             " s (the shipped ball settles to 95 % of its height at that step)";
  // Nodes that went NaN or infinite leave the box empty or unbounded (Eigen's extend skips NaN):
  // its height would print as "-inf %" and its lowest node as "y = -inf m".
  if (settled_bounds_world_m.isEmpty() || !settled_bounds_world_m.min().allFinite() || !settled_bounds_world_m.max().allFinite()) {
    throw SessionError("the soft body's node positions became non-finite while settling (" + number(settle_s) + " s, " + step +
                       "); the scene's values are the usual cause (see docs/scenes.md, \"Plausible values\")");
  }
  if (lowest_y < ground_y - tolerance_m) {
    throw SessionError("the soft body fell through the ground while settling (lowest node at y = " + number(lowest_y) + " m after " +
                       number(settle_s) + " s, ground top " + number(ground_y) + " m): " + step + " is too coarse for the fall; " + advice);
  }
  const double loaded_height_m = loaded_bounds_world_m.max().y() - loaded_bounds_world_m.min().y();
  const double settled_height_m = settled_bounds_world_m.max().y() - settled_bounds_world_m.min().y();
  if (loaded_height_m > 0.0 && settled_height_m < kSettledHeightWarning * loaded_height_m) {
    return "the soft body settled to " + number(100.0 * settled_height_m / loaded_height_m) + " % of its height in " +
           number(settle_s) + " s (" + step + "; a very soft material does this too); " + advice;
  }
  return {};
}

host::SceneDescription load_plausible_scene(std::string_view name_or_path) {
  host::SceneDescription scene = host::load_scene(host::resolve_scene_path(name_or_path));
  require_plausible(scene);
  return scene;
}

}  // namespace fissure::session
