#include "fissure/host_sim/contact_cells.hpp"

#include <algorithm>
#include <cmath>

#include "fissure/host_sim/host_simulation.hpp"
#include "fissure/host_sim/scene_loader.hpp"

namespace fissure::host {

void CellStepCounts::take(const HostStepResult& step, int cut_triangles) {
  crossed_nodes = std::max(crossed_nodes, step.crossing.crossed_nodes);
  inside_nodes = std::max(inside_nodes, step.crossing.inside_nodes);
  max_penetration_m = std::max(max_penetration_m, step.crossing.max_penetration_m);
  max_cut_triangles = std::max(max_cut_triangles, cut_triangles);
  if (cut_triangles > 0) ++steps_with_cut_triangles;
  step_s.push_back(step.times.total_s);
}

LeverResult run_lever_hold(const SceneDescription& scene, SceneCollisionMethod method, double hold_s) {
  const PlungeTool& blade = plunge_tools()[2];
  HostSimulation sim(scene, method);
  const double dt = scene.simulation.time_step_s;
  const PlungeStart start = settle_and_place_above(sim, scene, blade.leading_half_m);
  ToolPose pose = start.pose;
  const double end_y = start.end_y_m;
  LeverResult result;
  auto record = [&](const HostStepResult& r) {
    result.take(r, sim.triangles_cut_by_tool(kInsideToleranceM));
    ++result.steps;
  };
  while (pose.position_world_m.y() > end_y) {
    pose.position_world_m.y() = std::max(end_y, pose.position_world_m.y() - kLeverInsertSpeed_m_s * dt);
    record(sim.step(pose));
  }
  // The leading edge's direction in the world: the blade's tool-frame x (its 40 mm side along the
  // edge) turned by the start orientation.
  const Eigen::Vector3d edge_axis_world = (pose.orientation_world * Eigen::Vector3d::UnitX()).normalized();
  const Eigen::Quaterniond inserted = pose.orientation_world;
  const long turn_steps = std::lround(kLeverAngle_rad / (kLeverRate_rad_s * dt));
  for (long i = 1; i <= turn_steps; ++i) {
    const double angle = kLeverAngle_rad * static_cast<double>(i) / static_cast<double>(turn_steps);
    pose.orientation_world = Eigen::AngleAxisd(angle, edge_axis_world) * inserted;
    record(sim.step(pose));
  }
  const long settle_steps = std::lround(kHoldSettle_s / dt);
  const long hold_steps = std::lround(hold_s / dt);
  result.hold_force_n.reserve(static_cast<std::size_t>(hold_steps));
  for (long i = 0; i < settle_steps + hold_steps; ++i) {
    const HostStepResult& r = sim.step(pose);
    record(r);
    if (i >= settle_steps) result.hold_force_n.push_back(r.force_on_tool_world_n.norm());
  }
  result.hold = hold_force_stats(result.hold_force_n);
  return result;
}

ClampReleaseResult run_clamp_release(const SceneDescription& clamp_scene, SceneCollisionMethod method, double settle_s) {
  HostSimulation sim(clamp_scene, method);
  sim.settle(settle_s);
  ClampReleaseResult result;
  result.settle_s = settle_s;
  const long steps = std::lround(trajectory_duration_s(clamp_scene) / clamp_scene.simulation.time_step_s);
  const double open_m = clamp_scene.tool.clamp.jaw_gap_open_m;
  for (long i = 0; i < steps; ++i) {
    const TrajectorySample target = sim.scripted_target();
    const HostStepResult& r = sim.step(to_tool_pose(target.pose), target.jaw_gap_m);
    const double f = std::max(r.part_force_world_n[0].norm(), r.part_force_world_n[1].norm());
    result.script_max_force_n = std::max(result.script_max_force_n, f);
    if (r.jaw_gap_m >= open_m - 1e-9 && ++result.open_steps > kClampOpenGraceSteps)
      result.open_force_max_n = std::max(result.open_force_max_n, f);
    result.take(r, sim.triangles_cut_by_tool(kInsideToleranceM));
  }
  return result;
}

SceneDescription clamp_cell_scene(ContactResponse response, bool tool_friction) {
  // The in-solver sweep cells' bed and friction (in_solver_plunge_scene), for either response.
  SceneDescription scene = in_solver_plunge_scene(load_scene(resolve_scene_path("clamp-sphere")), tool_friction && response == ContactResponse::kInSolver);
  scene.simulation.contact_response = response;
  return scene;
}

}  // namespace fissure::host
