// The in-solver response (ContactResponse::kInSolver, issue 22): the contacts the detection stages
// decided at the start of Bullet's step are held inside the soft body's position iterations, and
// after the solve each held node's force share is read from where the solve left it.
//
// Why inside the solve: the post-step response overwrites node positions after Bullet's solve,
// and Bullet's next solve (links, pose matching, anchors) pulls the held nodes back — a limit
// cycle between two solvers that makes the held force chatter and keeps an opened clamp's nodes
// on its jaws (docs/decisions.md, "Contact inside the solver"). Projected after every position
// iteration, the contact and the body's own constraints converge together, and the velocity
// Bullet derives from the projected positions (v = (x − q)/h) is the velocity of the node on the
// face: no velocity is written here.
//
// project_contacts, after each iteration, on every candidate node (tool frame, current pose):
//  * a node held on a plane this step (placed by the detection, or caught by an earlier
//    iteration) and now behind that plane goes back on it (+ skin);
//  * a free node whose move since the last projection enters the tool (it ends inside, or it
//    passed through a thin tool within one iteration) goes out on the plane it was held on last
//    step if that one faces a way out within a tool thickness, else on the plane the move entered
//    through (Cyrus–Beck), else (it started inside) on the nearest plane; it is held from then
//    on. So no node ends the solve inside the tool or on its far side.
//  * with friction (friction_static_ratio > 0), a held node's move along its face since its
//    anchor (where it ended the last step it was held, or where it was first held) is undone
//    while undoing it costs at most static × F_n·h²/m — F_n the node's Hunt-Crossley normal force,
//    so F_n·h is the normal impulse the tool gives it in the step — else undone by kinetic ×
//    F_n·h²/m only (Coulomb at position level, Macklin et al. 2014): a node on the tool moves with
//    the tool until the tangential pull exceeds the cone. A sliding node's slip beyond the kinetic
//    cone also meets the contact's viscous shear (friction_shear_damping_pa_s_per_m × its rest
//    area), implicit: the share β/(1+β) of that excess is undone, β = b·h/m. The correction
//    accumulates over the iterations (as XPBD accumulates a multiplier), so several iterations
//    never spend the cone twice, and m·correction/h² is the friction force the node puts on the
//    tool.
// The rim constraint (rim_projection.cpp) runs before this in each pass, so this projection,
// which keeps nodes out of the tool, always has the last word.
// guard_swept_paths, after the solve's velocity update: a node whose straight path over the step
// passes through the tool (carried round a corner by several iterations) goes onto the face that
// path enters by, so no node's step — which Bullet turns into its velocity — crosses the tool.
// take_solved_shares, after the solve: a held node's share of the force is the smoothstep of its
// final gap over release_distance (1 on the face, 0 at release), as the post-step hysteresis
// ramps it; a node beyond release_distance or behind its plane is released.
#include "collision_state.hpp"

#include <BulletSoftBody/btSoftBody.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace fissure::host::thin_body {
namespace {

// Of the tool's planes along the segment a → b: the one it enters the tool by (Cyrus–Beck: of the
// planes a lies in front of and b behind, the one crossed last; -1 when there is none) and the
// one b lies least behind.
struct PlaneCrossing {
  int entered = -1;
  int nearest_to_end = 0;
};

PlaneCrossing cross_tool_planes(const std::vector<ToolPlane>& planes, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  PlaneCrossing out;
  double t_enter = 0.0;
  double nearest_height = -std::numeric_limits<double>::infinity();
  for (std::size_t q = 0; q < planes.size(); ++q) {
    const double fa = planes[q].normal_tool.dot(a) - planes[q].offset_m;
    const double fb = planes[q].normal_tool.dot(b) - planes[q].offset_m;
    if (fb > nearest_height) {
      nearest_height = fb;
      out.nearest_to_end = static_cast<int>(q);
    }
    if (fa > 0.0 && fb < 0.0) {
      const double t = fa / (fa - fb);
      if (t >= t_enter) {
        t_enter = t;
        out.entered = static_cast<int>(q);
      }
    }
  }
  return out;
}

// The plane a free node found inside the tool leaves by (see the file comment for the order).
int exit_plane(const CollisionModel& model, const StepFrame& frame, const CollisionData& data, int node, const Eigen::Vector3d& a,
               const Eigen::Vector3d& p_tool) {
  const auto& planes = model.tool.planes();
  const auto n = static_cast<std::size_t>(node);
  const double reach_m = model.tool.thickness_m() + model.params.skin_m;
  if (data.displacement.hold_stamp[n] == frame.step - 1 && data.displacement.hold_plane[n] >= 0) {
    const ToolPlane& held = planes[static_cast<std::size_t>(data.displacement.hold_plane[n])];
    if (held.offset_m - held.normal_tool.dot(p_tool) <= reach_m) return data.displacement.hold_plane[n];
  }
  const PlaneCrossing crossing = cross_tool_planes(planes, a, p_tool);
  return crossing.entered >= 0 ? crossing.entered : crossing.nearest_to_end;
}

}  // namespace

void start_iterates(const CollisionModel& /*model*/, const StepFrame& frame, const btSoftBody& soft, CollisionData& data) {
  for (const int node : data.broad.candidate_nodes) {
    const auto n = static_cast<std::size_t>(node);
    const Eigen::Vector3d p = to_tool(frame, soft.m_nodes[node].m_x);
    data.solver.iterate_tool_m[n] = p;
    data.solver.friction_correction_tool_m[n].setZero();
    data.solver.friction_sliding[n] = 0;
    if (data.displacement.hold_stamp[n] != frame.step) continue;
    // Placed by the detection: a node not held last step sticks where it was placed.
    if (data.solver.friction_anchor_stamp[n] != frame.step - 1) {
      data.solver.friction_anchor_tool_m[n] = p;
      data.solver.friction_anchor_stamp[n] = frame.step;
    }
  }
}

int project_contacts(const CollisionModel& model, const StepFrame& frame, btSoftBody& soft, CollisionData& data) {
  const auto& planes = model.tool.planes();
  const double skin_m = model.params.skin_m;
  const double mu_static = model.params.friction_static_ratio;
  const double mu_kinetic = model.params.friction_kinetic_ratio;
  const double shear_damping = model.params.friction_shear_damping_pa_s_per_m;
  int projected = 0;
  for (const int node : data.broad.candidate_nodes) {
    btSoftBody::Node& soft_node = soft.m_nodes[node];
    if (soft_node.m_im == 0) continue;  // fixed nodes are never moved
    const auto n = static_cast<std::size_t>(node);
    Eigen::Vector3d p = to_tool(frame, soft_node.m_x);
    int plane_index = -1;
    if (data.displacement.hold_stamp[n] == frame.step) {
      plane_index = data.displacement.hold_plane[n];
    } else {
      // Inside the tool now, or passed through it since the last projection (an iteration moves
      // a node by up to a link's correction, more than a 1 mm blade is thick): out through the
      // face it entered by on that move.
      const Eigen::Vector3d& a = data.solver.iterate_tool_m[n];
      if (segment_clears_tool(planes, a, p)) {
        data.solver.iterate_tool_m[n] = p;
        continue;
      }
      plane_index = exit_plane(model, frame, data, node, a, p);
      data.displacement.hold_stamp[n] = frame.step;
      data.displacement.hold_plane[n] = plane_index;
    }
    const ToolPlane& plane = planes[static_cast<std::size_t>(plane_index)];
    const double push_m = plane.offset_m + skin_m - plane.normal_tool.dot(p);
    bool moved = false;
    if (push_m > 0.0) {
      p += push_m * plane.normal_tool;
      moved = true;
    }
    if (data.solver.friction_anchor_stamp[n] < frame.step - 1) {
      // Caught by this iteration: it sticks where it was put out.
      data.solver.friction_anchor_tool_m[n] = p;
      data.solver.friction_anchor_stamp[n] = frame.step;
    }
    if (mu_static > 0.0) {
      // Coulomb at position level: the tangential move since the anchor that friction has not
      // already undone this step, against the cone of the node's normal impulse.
      const double normal_force_n = held_node_normal_force(model, frame, node, plane, plane.normal_tool.dot(p) - plane.offset_m);
      Eigen::Vector3d& correction = data.solver.friction_correction_tool_m[n];
      Eigen::Vector3d free_slip = p - data.solver.friction_anchor_tool_m[n] - correction;
      free_slip -= plane.normal_tool.dot(free_slip) * plane.normal_tool;
      const double free_slip_m = free_slip.norm();
      const double cone_m = normal_force_n * frame.dt_s * frame.dt_s * soft_node.m_im;  // F_n·h²/m
      Eigen::Vector3d wanted = Eigen::Vector3d::Zero();
      data.solver.friction_sliding[n] = 0;
      if (free_slip_m <= mu_static * cone_m) {
        wanted = -free_slip;
      } else if (free_slip_m > 0.0) {
        // Sliding: the kinetic cone, plus the implicit viscous share of the slip beyond it.
        const double kinetic_m = mu_kinetic * cone_m;
        const double beta = shear_damping * model.soft.node_rest_area_m2[n] * frame.dt_s * soft_node.m_im;  // b·h/m
        const double undone_m = kinetic_m + (beta / (1.0 + beta)) * (free_slip_m - kinetic_m);
        wanted = -free_slip * (undone_m / free_slip_m);
        data.solver.friction_sliding[n] = 1;
      }
      if (wanted != correction) {
        p += wanted - correction;
        correction = wanted;
        moved = true;
      }
    }
    data.solver.iterate_tool_m[n] = p;
    if (!moved) continue;
    write_tool_position(frame, p, soft_node.m_x);
    ++projected;
  }
  return projected;
}

double held_node_normal_force(const CollisionModel& model, const StepFrame& frame, int node, const ToolPlane& plane, double gap_m) {
  const HuntCrossleyParams& hc = model.params.hunt_crossley;
  const auto v = static_cast<std::size_t>(node);
  const Eigen::Vector3d normal_world = frame.r_cur * plane.normal_tool;
  const double x_m = plane.offset_m + normal_world.dot(frame.t_cur - model.soft.rest_node_world_m[v]);
  if (!(x_m > 0.0)) return 0.0;
  const double nodal_weight = hc.per_unit_area
                                  ? model.soft.node_rest_area_m2[v]
                                  : (model.soft.faces_of_node_begin[v + 1] - model.soft.faces_of_node_begin[v]) / 3.0;
  return release_share(gap_m, model.params.release_distance_m) * nodal_weight * hc.k * std::pow(x_m, hc.n);
}

void friction_force_on_tool(const CollisionModel& model, const StepFrame& frame, const btSoftBody& soft, const CollisionData& data,
                            CollisionStepResult& out) {
  if (!(model.params.friction_static_ratio > 0.0)) return;
  Eigen::Vector3d force_tool = Eigen::Vector3d::Zero();
  const double inverse_h2 = 1.0 / (frame.dt_s * frame.dt_s);
  for (const int node : data.broad.candidate_nodes) {
    const auto n = static_cast<std::size_t>(node);
    const double im = soft.m_nodes[node].m_im;
    if (im == 0.0) continue;
    const Eigen::Vector3d& correction = data.solver.friction_correction_tool_m[n];
    if (correction.isZero(0.0)) continue;
    // The correction moved the node by −(its tangential pull); the tool takes the reaction.
    force_tool -= correction * (inverse_h2 / im);
    (data.solver.friction_sliding[n] != 0 ? out.sliding_nodes : out.sticking_nodes) += 1;
  }
  const Eigen::Vector3d force_world = frame.r_cur * force_tool;
  out.friction_force_on_tool_world_n += force_world;
  out.force_on_tool_world_n += force_world;
}

void take_solved_shares(const CollisionModel& model, const StepFrame& frame, const btSoftBody& soft, CollisionData& data) {
  const auto& planes = model.tool.planes();
  const double release_m = model.params.release_distance_m;
  data.displacement.moved_nodes.clear();
  for (const int node : data.broad.candidate_nodes) {
    const auto n = static_cast<std::size_t>(node);
    const bool held = data.displacement.hold_stamp[n] == frame.step || data.displacement.hold_stamp[n] == frame.step - 1;
    if (!held || soft.m_nodes[node].m_im == 0) {
      if (data.displacement.moved_stamp[n] == frame.step) data.displacement.moved_stamp[n] = frame.step - 1;
      continue;
    }
    const Eigen::Vector3d p = to_tool(frame, soft.m_nodes[node].m_x);
    data.broad.end_tool_m[n] = p;
    const ToolPlane& plane = planes[static_cast<std::size_t>(data.displacement.hold_plane[n])];
    const double gap_m = plane.normal_tool.dot(p) - plane.offset_m;
    if (gap_m > release_m || gap_m < -kInsideTolerance_m) {
      // Lifted off beyond the release band, or left behind the plane beside the tool: released.
      if (data.displacement.hold_stamp[n] == frame.step) data.displacement.hold_stamp[n] = frame.step - 2;
      if (data.displacement.moved_stamp[n] == frame.step) data.displacement.moved_stamp[n] = frame.step - 1;
      continue;
    }
    data.displacement.node_share[n] = release_share(gap_m, release_m);
    data.solver.friction_anchor_tool_m[n] = p;
    data.solver.friction_anchor_stamp[n] = frame.step;
    data.displacement.hold_stamp[n] = frame.step;
    data.displacement.moved_stamp[n] = frame.step;
    data.displacement.moved_nodes.push_back(node);
  }
}


int guard_swept_paths(const CollisionModel& model, const StepFrame& frame, btSoftBody& soft, CollisionData& data, SoftNodeBounds* bounds) {
  const auto& planes = model.tool.planes();
  const double skin_m = model.params.skin_m;
  // Bullet's own velocity update (v = (x − q)·(1 − kDP)/h), for the nodes moved after it.
  const btScalar velocity_scale = soft.m_sst.isdt * (1 - soft.m_cfg.kDP);
  int moved = 0;
  for (const int node : data.broad.candidate_nodes) {
    btSoftBody::Node& soft_node = soft.m_nodes[node];
    if (soft_node.m_im == 0) continue;
    const auto n = static_cast<std::size_t>(node);
    const Eigen::Vector3d& start = data.broad.start_tool_m[n];
    Eigen::Vector3d end = to_tool(frame, soft_node.m_x);
    if (segment_clears_tool(planes, start, end)) continue;
    // The face the path enters by: the path passes through the tool, so it crosses one.
    const int enter_plane = cross_tool_planes(planes, start, end).entered;
    if (enter_plane < 0) continue;  // it started inside the tool: the projections have put it out
    const ToolPlane& plane = planes[static_cast<std::size_t>(enter_plane)];
    // On that face's plane (+ skin) the whole path lies in front of it, and the tool behind it.
    end += (plane.offset_m + skin_m - plane.normal_tool.dot(end)) * plane.normal_tool;
    write_tool_position(frame, end, soft_node.m_x);
    soft_node.m_v = (soft_node.m_x - soft_node.m_q) * velocity_scale;
    data.displacement.hold_stamp[n] = frame.step;
    data.displacement.hold_plane[n] = enter_plane;
    if (bounds != nullptr) bounds->extend(node, soft_node.m_x);
    ++moved;
  }
  return moved;
}

}  // namespace fissure::host::thin_body
