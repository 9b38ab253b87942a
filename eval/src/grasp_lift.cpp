// Grasp and lift (grasp.hpp): the lift scene's own trajectory, with the vessel's centre of mass,
// the nodes on the jaws and the per-jaw forces followed step by step.
//
// Phases are read off the scripted trajectory, not off the simulation: the hold is the time the
// clamp sits at its highest point with the jaws closed, "closed" is the first step at the
// smallest jaw gap, and the release starts when the gap starts to grow again.
#include "fissure/eval/grasp.hpp"

#include <fissure/host_sim/host_simulation.hpp>
#include <fissure/host_sim/scene_loader.hpp>
#include <fissure/host_sim/soft_world.hpp>

#include <BulletSoftBody/btSoftBody.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "grasp_detail.hpp"

namespace fissure::eval {

namespace detail {

double vessel_mass_kg(const btSoftBody& soft) {
  double mass = 0.0;
  for (int i = 0; i < soft.m_nodes.size(); ++i)
    if (soft.m_nodes[i].m_im > 0.0) mass += 1.0 / soft.m_nodes[i].m_im;
  return mass;
}

Eigen::Vector3d centre_of_mass_world_m(const btSoftBody& soft) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double mass = 0.0;
  for (int i = 0; i < soft.m_nodes.size(); ++i) {
    if (!(soft.m_nodes[i].m_im > 0.0)) continue;
    const double m = 1.0 / soft.m_nodes[i].m_im;
    const btVector3& x = soft.m_nodes[i].m_x;
    sum += m * Eigen::Vector3d(x.x(), x.y(), x.z());
    mass += m;
  }
  return mass > 0.0 ? Eigen::Vector3d(sum / mass) : Eigen::Vector3d::Zero();
}

std::vector<JawNode> nodes_on_jaws(const host::HostSimulation& sim, double tolerance_m) {
  std::vector<JawNode> out;
  const auto& nodes = sim.node_positions_world_m();
  for (int part = 0; part < sim.last().part_count; ++part) {
    const host::ToolNodes* tool = sim.tool_nodes(part);
    if (tool == nullptr) continue;
    const host::ToolPose& pose = sim.part_pose(part);
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      const Eigen::Vector3d p = pose.orientation_world.conjugate() * (nodes[i] - pose.position_world_m);
      // Signed distance to the convex jaw: the largest plane height; ≤ tolerance is on (or in) it.
      int face = -1;
      double height = -std::numeric_limits<double>::infinity();
      for (std::size_t q = 0; q < tool->planes().size(); ++q) {
        const double h = tool->planes()[q].normal_tool.dot(p) - tool->planes()[q].offset_m;
        if (h > height) {
          height = h;
          face = static_cast<int>(q);
        }
      }
      if (face >= 0 && height <= tolerance_m) out.push_back(JawNode{static_cast<int>(i), part, face, p});
    }
  }
  return out;
}

double tangential_slide_m(const host::HostSimulation& sim, const JawNode& node) {
  const host::ToolPose& pose = sim.part_pose(node.part);
  const Eigen::Vector3d p = pose.orientation_world.conjugate() * (sim.node_positions_world_m()[static_cast<std::size_t>(node.node)] - pose.position_world_m);
  const Eigen::Vector3d& n = sim.tool_nodes(node.part)->planes()[static_cast<std::size_t>(node.face)].normal_tool;
  Eigen::Vector3d d = p - node.start_tool_m;
  d -= n.dot(d) * n;
  return d.norm();
}

JawForces jaw_forces(const host::HostStepResult& r, const Eigen::Vector3d& closing_axis_world) {
  JawForces f;
  for (int part = 0; part < std::min(r.part_count, 2); ++part) {
    const Eigen::Vector3d& friction = r.part_results[static_cast<std::size_t>(part)].friction_force_on_tool_world_n;
    const Eigen::Vector3d normal = r.part_force_world_n[static_cast<std::size_t>(part)] - friction;
    f.normal_n[static_cast<std::size_t>(part)] = std::abs(normal.dot(closing_axis_world));
    f.normal_vector_world_n[static_cast<std::size_t>(part)] = normal;
    f.friction_world_n[static_cast<std::size_t>(part)] = friction;
  }
  return f;
}

Eigen::Vector3d closing_axis_world(const host::SceneDescription& scene) {
  // The jaws face each other across the tool's local y (thin_tool.hpp, clamp).
  return scene_orientation(scene) * Eigen::Vector3d::UnitY();
}

Eigen::Quaterniond scene_orientation(const host::SceneDescription& scene) {
  const auto& q = scene.trajectory.start.orientation_world;
  return Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized();
}

void set_friction(host::SceneDescription& scene, double static_ratio, double kinetic_ratio) {
  scene.simulation.contact_response = host::ContactResponse::kInSolver;
  scene.tool.friction_static_ratio = static_ratio;
  scene.tool.friction_kinetic_ratio = kinetic_ratio;
}

}  // namespace detail

host::SceneDescription grasp_lift_scene() { return host::load_scene(host::resolve_scene_path("clamp-vessel-lift")); }

GraspLiftResult run_grasp_lift(const GraspLiftOptions& options) {
  host::SceneDescription scene = options.scene;
  if (options.friction_ratio_override >= 0.0) detail::set_friction(scene, options.friction_ratio_override, options.friction_ratio_override);
  GraspLiftResult out;
  out.friction_static_ratio = scene.tool.friction_static_ratio;
  out.friction_kinetic_ratio = scene.tool.friction_kinetic_ratio;

  host::HostSimulation sim(scene);
  sim.settle(options.settle_s);
  const btSoftBody& soft = sim.world().soft();
  out.vessel_mass_kg = detail::vessel_mass_kg(soft);
  const Eigen::Vector3d closing = detail::closing_axis_world(scene);
  const Eigen::Vector3d up(0.0, 1.0, 0.0);

  const double dt = scene.simulation.time_step_s;
  const double duration = host::trajectory_duration_s(scene);
  const long steps = std::lround(duration / dt);
  // The script's phases, sampled at the step times the simulation will see.
  double top_y = -std::numeric_limits<double>::infinity();
  double min_gap = std::numeric_limits<double>::infinity();
  for (long i = 1; i <= steps; ++i) {
    const host::TrajectorySample s = host::sample_trajectory(scene, static_cast<double>(i) * dt);
    top_y = std::max(top_y, s.pose.position_world_m[1]);
    min_gap = std::min(min_gap, s.jaw_gap_m);
  }
  constexpr double kPhaseTolerance_m = 1e-9;

  double closed_jaw_y = 0.0;
  double closed_centroid_y = 0.0;
  bool closed = false;
  bool holding = false;
  bool held = false;
  bool opening = false;
  std::vector<detail::JawNode> hold_nodes;
  double grip_sum = 0.0, friction_up_sum = 0.0;
  int hold_steps = 0;
  double clear_time = -1.0;
  double last_nonzero_time = -1.0;
  for (long i = 0; i < steps; ++i) {
    const host::TrajectorySample target = sim.scripted_target();
    const host::HostStepResult& r = sim.step(host::to_tool_pose(target.pose), target.jaw_gap_m);
    const Eigen::Vector3d com = detail::centre_of_mass_world_m(soft);
    const detail::JawForces f = detail::jaw_forces(r, closing);
    out.finite = out.finite && r.force_on_tool_world_n.allFinite() && com.allFinite();
    out.time_s.push_back(r.time_s);
    out.jaw_gap_m.push_back(r.jaw_gap_m);
    out.centroid_height_m.push_back(com.y());
    out.jaw_a_normal_n.push_back(f.normal_n[0]);
    out.jaw_b_normal_n.push_back(f.normal_n[1]);
    out.jaw_a_friction_n.push_back(f.friction_world_n[0].norm());
    out.jaw_b_friction_n.push_back(f.friction_world_n[1].norm());
    out.crossed_nodes_max = std::max(out.crossed_nodes_max, r.crossing.crossed_nodes);
    if (i % 10 == 0) out.cut_triangles_max = std::max(out.cut_triangles_max, sim.triangles_cut_by_tool(1e-4));

    const double jaw_y = sim.tool_pose().position_world_m.y();
    if (!closed && r.jaw_gap_m <= min_gap + kPhaseTolerance_m) {
      closed = true;
      closed_jaw_y = jaw_y;
      closed_centroid_y = com.y();
    }
    const bool at_top = closed && jaw_y >= top_y - kPhaseTolerance_m && r.jaw_gap_m <= min_gap + kPhaseTolerance_m;
    if (at_top && !holding && !held) {
      holding = true;
      hold_nodes = detail::nodes_on_jaws(sim, detail::kOnJawTolerance_m);
      out.hold_contact_nodes = static_cast<int>(hold_nodes.size());
    }
    if (holding && !at_top) {
      holding = false;
      held = true;
    }
    if (holding) {
      for (const detail::JawNode& node : hold_nodes) out.hold_slide_max_m = std::max(out.hold_slide_max_m, detail::tangential_slide_m(sim, node));
      out.rise_shortfall_max_m = std::max(out.rise_shortfall_max_m, (jaw_y - closed_jaw_y) - (com.y() - closed_centroid_y));
      out.jaw_rise_m = jaw_y - closed_jaw_y;
      out.centroid_rise_m = com.y() - closed_centroid_y;
      grip_sum += 0.5 * (f.normal_n[0] + f.normal_n[1]);
      // The force on the tool is the reaction: the vessel is pushed up by −(friction on the tool).
      friction_up_sum += -(f.friction_world_n[0] + f.friction_world_n[1]).dot(up);
      ++hold_steps;
    }
    if (held && !opening && r.jaw_gap_m > min_gap + kPhaseTolerance_m) opening = true;
    if (opening) {
      const Eigen::AlignedBox3d bounds = sim.soft_bounds_world_m();
      const double width = (bounds.max() - bounds.min()).dot(closing.cwiseAbs());
      if (clear_time < 0.0 && r.jaw_gap_m > width) clear_time = r.time_s;
      if (r.force_on_tool_world_n.norm() > 0.0) last_nonzero_time = r.time_s;
    }
  }
  if (hold_steps > 0) {
    out.hold_grip_n = grip_sum / hold_steps;
    out.hold_friction_up_n = friction_up_sum / hold_steps;
  }
  if (clear_time >= 0.0) {
    out.release_delay_s = std::max(0.0, last_nonzero_time - clear_time + dt);
    for (std::size_t k = 0; k < out.time_s.size(); ++k)
      if (out.time_s[k] >= clear_time) {
        out.force_at_clear_n = out.jaw_a_normal_n[k] + out.jaw_b_normal_n[k] + out.jaw_a_friction_n[k] + out.jaw_b_friction_n[k];
        break;
      }
  }
  return out;
}

}  // namespace fissure::eval
