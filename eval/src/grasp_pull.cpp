// Pull-out (grasp.hpp): the retraction scene's vessel, far end anchored, gripped near its free end
// at a set jaw gap and pulled along its axis, away from the anchor, until it slides through the
// jaws. The anchored vessel's links are far stiffer along its axis than the grip's friction, so the
// jaws slide and the friction force along the pull, once sliding, is what Coulomb's law says:
// kinetic × (the normal force of both jaws).
#include "fissure/eval/grasp.hpp"

#include <fissure/host_sim/host_simulation.hpp>
#include <fissure/host_sim/scene_loader.hpp>
#include <fissure/host_sim/soft_world.hpp>

#include <algorithm>
#include <cmath>

#include "grasp_detail.hpp"

namespace fissure::eval {

namespace {

// The closing leg: as the lift scene closes (docs/scenes.md, clamp-vessel-lift.toml).
constexpr double kCloseSpeed_m_per_s = 0.02;
constexpr double kGripHold_s = 0.2;
// The sliding mean: the pull's last quarter, well after the stick phase has given way.
constexpr double kSlidingShare = 0.25;

}  // namespace

host::SceneDescription grasp_pull_scene() { return host::load_scene(host::resolve_scene_path("clamp-vessel-retract")); }

GraspPullResult run_grasp_pull(const GraspPullOptions& options) {
  host::SceneDescription scene = options.scene;
  detail::set_friction(scene, options.friction_ratio, options.friction_ratio);
  // The pull runs along the scene's own retraction direction: from the start to the last waypoint.
  const Eigen::Vector3d start = as_eigen(scene.trajectory.start.position_world_m);
  if (scene.trajectory.waypoints.empty()) throw std::invalid_argument(scene.source_path + ": the retraction scene has no trajectory waypoint");
  const Eigen::Vector3d pull_direction = (as_eigen(scene.trajectory.waypoints.back().position_world_m) - start).normalized();
  if (!pull_direction.allFinite()) throw std::invalid_argument(scene.source_path + ": the retraction scene's last waypoint is its start");
  const Eigen::Vector3d end = start + options.pull_distance_m * pull_direction;
  scene.trajectory.waypoints.clear();
  scene.trajectory.waypoints.push_back(host::TrajectoryWaypoint{to_vec3(start), kCloseSpeed_m_per_s, kGripHold_s, options.jaw_gap_m});
  scene.trajectory.waypoints.push_back(host::TrajectoryWaypoint{to_vec3(end), options.pull_speed_m_per_s, 0.0, options.jaw_gap_m});

  GraspPullResult out;
  out.jaw_gap_m = options.jaw_gap_m;
  out.friction_ratio = options.friction_ratio;
  host::HostSimulation sim(scene);
  sim.settle(options.settle_s);
  const Eigen::Vector3d closing = detail::closing_axis_world(scene);
  const double dt = scene.simulation.time_step_s;
  const long steps = std::lround(host::trajectory_duration_s(scene) / dt);
  const double pull_s = options.pull_distance_m / options.pull_speed_m_per_s;
  const double pull_start_s = host::trajectory_duration_s(scene) - pull_s;
  const double sliding_from_s = pull_start_s + (1.0 - kSlidingShare) * pull_s;

  std::vector<detail::JawNode> gripped;
  Eigen::Vector3d gripped_start = Eigen::Vector3d::Zero();
  Eigen::Vector3d jaw_start = Eigen::Vector3d::Zero();
  double grip_sum = 0.0, pull_sum = 0.0;
  int sliding_steps = 0;
  auto gripped_centroid = [&] {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (const detail::JawNode& node : gripped) c += sim.node_positions_world_m()[static_cast<std::size_t>(node.node)];
    return gripped.empty() ? c : Eigen::Vector3d(c / static_cast<double>(gripped.size()));
  };
  for (long i = 0; i < steps; ++i) {
    const host::TrajectorySample target = sim.scripted_target();
    const host::HostStepResult& r = sim.step(host::to_tool_pose(target.pose), target.jaw_gap_m);
    out.finite = out.finite && r.force_on_tool_world_n.allFinite();
    out.crossed_nodes_max = std::max(out.crossed_nodes_max, r.crossing.crossed_nodes);
    if (gripped.empty() && r.time_s >= pull_start_s) {
      gripped = detail::nodes_on_jaws(sim, detail::kOnJawTolerance_m);
      gripped_start = gripped_centroid();
      jaw_start = sim.tool_pose().position_world_m;
    }
    if (r.time_s < pull_start_s) continue;
    const detail::JawForces f = detail::jaw_forces(r, closing);
    // The friction on the tool opposes the pull; the force the hand needs is its component against the pull.
    const double pull_n = -(f.friction_world_n[0] + f.friction_world_n[1]).dot(pull_direction);
    out.pull_peak_n = std::max(out.pull_peak_n, pull_n);
    if (r.time_s >= sliding_from_s) {
      grip_sum += 0.5 * (f.normal_n[0] + f.normal_n[1]);
      pull_sum += pull_n;
      ++sliding_steps;
    }
  }
  if (sliding_steps > 0) {
    out.grip_n = grip_sum / sliding_steps;
    out.pull_out_n = pull_sum / sliding_steps;
  }
  const Eigen::Vector3d jaw_travel = sim.tool_pose().position_world_m - jaw_start;
  const Eigen::Vector3d node_travel = gripped_centroid() - gripped_start;
  out.slip_m = (jaw_travel - node_travel).dot(pull_direction);
  return out;
}

}  // namespace fissure::eval
