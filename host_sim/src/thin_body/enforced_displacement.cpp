// Stage 4: enforced displacement (BRIEF §3 item 4; Fukuhara et al.: the soft nodes are moved, not
// pushed by a penalty spring). Works on the tool-frame end positions from the broad phase and
// writes btSoftBody::Node::m_x / m_v for every node it moves. Nodes of mass 0 (m_im == 0, fixed)
// are never moved.
//
// paired:
//  a. every vertex of a contacted triangle that is behind the leading node's tool plane is put
//     on that plane (+ skin) — but only if it came from that plane's side: at the start of the
//     step it was in front of the plane, or it was held on a plane facing the same way last step
//     (soft-node side memory). So no vertex is ever moved THROUGH the tool. On a RIM plane (one
//     carrying edge nodes: a side face of a blade) every free vertex whose straight move onto
//     the plane does not pass through the tool is placed too — also one beside the blade and
//     behind its rim: a coarse triangle straddling an edge-first blade is wrapped in front of the
//     edge instead of being sliced (a rim has no opposite face to give a side memory);
//  b. guard: every soft node near the tool whose relative path over the step (start → end, tool
//     frame) enters the tool volume is put back on the plane it entered through (Cyrus–Beck
//     clipping against the tool's convex planes); a node that starts inside (the soft solver
//     pushed a held node in) goes back to the plane it was held on, else to the nearest one.
//     This covers the tool's area between nodes and its rim.
// Colliding soft nodes = nodes moved this step, plus nodes held last step that are still within
// release_distance in front of their plane (hysteresis against contact-set chatter; their force
// share ramps smoothly from 1 on the face to 0 at release_distance, DisplacementData::node_share). Every
// triangle around a colliding node is in the force set (paper: "at least one of the nodes
// belonging to the triangle is in a colliding state"), pushing along its node's plane.
// ray (the paper's Fig. 3 right): every tool node in contact, excluded or not, puts its triangle's
// vertices on ITS OWN plane when behind it, in node order — with both faces in contact the last
// one wins, so vertices get pushed to the far face: the instability the pairing removes.
// Every moved node gets the tool's velocity at its position.
#include "collision_state.hpp"

#include <BulletSoftBody/btSoftBody.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace fissure::host::thin_body {
namespace {

// Two tool planes "face the same way" (a node held on one may be moved to the other) above this cosine.
constexpr double kSameSideCosine = 0.5;
// A rim node "leads into" a soft triangle when it meets it within 60° of head-on (tool normal ·
// soft normal < −0.5); below that it is grazing it.
constexpr double kRimHeadOnCosine = 0.5;

struct Writer {
  const CollisionModel& model;
  const StepFrame& frame;
  btSoftBody& soft;
  CollisionData& data;
  DisplacementCounts counts;

  bool fixed(int node) const { return soft.m_nodes[node].m_im == 0; }

  // Where a node goes on `plane` (+ skin): straight along the plane's normal (the tool face is
  // frictionless: a held node slides freely along it; friction measures worse, see
  // ThinBodyCollisionParams).
  Eigen::Vector3d target_on_plane(int node, int plane_index) const {
    const ToolPlane& plane = model.tool.planes()[static_cast<std::size_t>(plane_index)];
    const double target = plane.offset_m + model.params.skin_m;
    const Eigen::Vector3d& end = data.broad.end_tool_m[static_cast<std::size_t>(node)];
    return end + (target - plane.normal_tool.dot(end)) * plane.normal_tool;
  }

  // Moves the node's end position onto `plane` (+ skin) if it is behind it.
  bool place_on_plane(int node, int plane_index) {
    const ToolPlane& plane = model.tool.planes()[static_cast<std::size_t>(plane_index)];
    Eigen::Vector3d& p = data.broad.end_tool_m[static_cast<std::size_t>(node)];
    const double target = plane.offset_m + model.params.skin_m;
    if (plane.normal_tool.dot(p) >= target) return false;
    p = target_on_plane(node, plane_index);
    write(node, plane_index);
    return true;
  }

  void write(int node, int plane_index) {
    const auto n = static_cast<std::size_t>(node);
    const Eigen::Vector3d p_world = frame.r_cur * data.broad.end_tool_m[n] + frame.t_cur;
    const Eigen::Vector3d v_world = frame.velocity_world_m_s + frame.angular_velocity_world.cross(p_world - frame.t_cur);
    btSoftBody::Node& soft_node = soft.m_nodes[node];
    soft_node.m_x.setValue(static_cast<btScalar>(p_world.x()), static_cast<btScalar>(p_world.y()),
                           static_cast<btScalar>(p_world.z()));
    soft_node.m_v.setValue(static_cast<btScalar>(v_world.x()), static_cast<btScalar>(v_world.y()),
                           static_cast<btScalar>(v_world.z()));
    data.displacement.node_share[n] = 1.0;  // on the face: the node's whole share of the force
    if (data.displacement.moved_stamp[n] != frame.step) {
      data.displacement.moved_stamp[n] = frame.step;
      data.displacement.moved_nodes.push_back(node);
      ++counts.displaced;
    }
    data.displacement.hold_stamp[n] = frame.step;
    data.displacement.hold_plane[n] = plane_index;
  }

  bool held_last_step_facing(int node, const Eigen::Vector3d& normal) const {
    const auto n = static_cast<std::size_t>(node);
    if (data.displacement.hold_stamp[n] != frame.step - 1) return false;
    return model.tool.planes()[static_cast<std::size_t>(data.displacement.hold_plane[n])].normal_tool.dot(normal) > kSameSideCosine;
  }

  // Whether moving the node's end position straight onto `plane` (+ skin) along its normal stays
  // outside the tool's interior (Cyrus–Beck clip of the move against every tool plane). A rim
  // plane has no opposite face and no pair to say which side the soft body is on; geometry does:
  // a vertex beside a blade (outside its slab), even behind the rim, is pulled onto the rim plane
  // without passing through the tool, so a coarse triangle straddling the blade is wrapped in
  // front of the edge instead of being sliced by it. A vertex beyond the tool's back along the
  // rim's normal is on the tool's far side (past a jaw's opposite side face): its straight move
  // onto this rim would carry it across the whole tool — over a large face, so it clears the
  // interior — and is no wrap.
  bool move_clears_tool(int node, int plane_index) const {
    const ToolPlane& target_plane = model.tool.planes()[static_cast<std::size_t>(plane_index)];
    const Eigen::Vector3d& a = data.broad.end_tool_m[static_cast<std::size_t>(node)];
    if (target_plane.normal_tool.dot(a) >= target_plane.offset_m + model.params.skin_m) return true;  // in front: nothing to move
    if (target_plane.normal_tool.dot(a) <= model.rim_plane_back_m[static_cast<std::size_t>(plane_index)]) return false;
    return segment_clears_tool(model.tool.planes(), a, target_on_plane(node, plane_index));
  }

  void paired_faces() {
    const double feasible_slack = model.params.contact_distance_m + model.params.skin_m;
    for (const int face : data.exclusion.contacted_faces) {
      const int plane_index = data.exclusion.face_plane[static_cast<std::size_t>(face)];
      const ToolPlane& plane = model.tool.planes()[static_cast<std::size_t>(plane_index)];
      // Wrapping applies when the rim LEADS into the triangle (its node meets it head-on, as an
      // edge-first blade does); a rim node grazing a triangle at the side of a plate moving
      // face-first must not drag the vertices under the plate sideways onto its rim plane.
      const int lead = data.exclusion.face_lead_node[static_cast<std::size_t>(face)];
      const bool rim_leads = model.rim_plane[static_cast<std::size_t>(plane_index)] != 0 && lead >= 0 &&
                             data.sweep.node_facing[static_cast<std::size_t>(lead)] < -kRimHeadOnCosine;
      for (const int node : model.soft.face_nodes[static_cast<std::size_t>(face)]) {
        if (fixed(node)) continue;
        const double start_height = plane.normal_tool.dot(data.broad.start_tool_m[static_cast<std::size_t>(node)]);
        const bool came_from_front = start_height >= plane.offset_m - feasible_slack;
        if (came_from_front || held_last_step_facing(node, plane.normal_tool) ||
            (rim_leads && move_clears_tool(node, plane_index)))
          place_on_plane(node, plane_index);
      }
    }
  }

  void guard() {
    const auto& planes = model.tool.planes();
    const std::size_t plane_count = planes.size();
    for (const int node : data.broad.candidate_nodes) {
      if (fixed(node)) continue;
      const auto n = static_cast<std::size_t>(node);
      const Eigen::Vector3d& a = data.broad.start_tool_m[n];
      const Eigen::Vector3d& b = data.broad.end_tool_m[n];
      double t_enter = 0.0;
      double t_exit = 1.0;
      int enter_plane = -1;
      int nearest_plane = 0;
      double nearest_height = -std::numeric_limits<double>::infinity();
      bool misses = false;
      for (std::size_t q = 0; q < plane_count; ++q) {
        const double fa = planes[q].normal_tool.dot(a) - planes[q].offset_m + kInsideTolerance_m;
        const double fb = planes[q].normal_tool.dot(b) - planes[q].offset_m + kInsideTolerance_m;
        if (fa > nearest_height) {
          nearest_height = fa;
          nearest_plane = static_cast<int>(q);
        }
        if (fa > 0.0 && fb > 0.0) {
          misses = true;
          break;
        }
        if (fa > 0.0) {
          const double t = fa / (fa - fb);
          if (t > t_enter) {
            t_enter = t;
            enter_plane = static_cast<int>(q);
          }
        } else if (fb > 0.0) {
          const double t = fa / (fa - fb);
          if (t < t_exit) t_exit = t;
        }
      }
      if (misses || t_enter > t_exit) continue;
      int plane_index = enter_plane;
      if (plane_index < 0) {
        if (data.displacement.hold_stamp[n] >= frame.step - 1 && data.displacement.hold_plane[n] >= 0) {
          plane_index = data.displacement.hold_plane[n];
        } else {
          plane_index = nearest_plane;  // started inside with no memory: the shallowest way out
        }
      }
      if (place_on_plane(node, plane_index)) ++counts.guard_corrections;
    }
  }

  void ray_only() {
    const auto& plane_of_node = model.tool.plane_of_node();
    for (const int i : data.sweep.contact_nodes) {
      const int face = data.sweep.node_face[static_cast<std::size_t>(i)];
      if (face < 0) continue;
      const int plane_index = plane_of_node[static_cast<std::size_t>(i)];
      for (const int node : model.soft.face_nodes[static_cast<std::size_t>(face)])
        if (!fixed(node)) place_on_plane(node, plane_index);
      data.exclusion.face_plane[static_cast<std::size_t>(face)] = plane_index;  // last writer, as placed
    }
  }
};

}  // namespace

bool segment_clears_tool(const std::vector<ToolPlane>& planes, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  double t_enter = 0.0;
  double t_exit = 1.0;
  for (const ToolPlane& plane : planes) {
    const double fa = plane.normal_tool.dot(a) - plane.offset_m + kInsideTolerance_m;
    const double fb = plane.normal_tool.dot(b) - plane.offset_m + kInsideTolerance_m;
    if (fa >= 0.0 && fb >= 0.0) return true;  // the whole segment is outside this plane
    if (fa >= 0.0) {
      t_enter = std::max(t_enter, fa / (fa - fb));
    } else if (fb >= 0.0) {
      t_exit = std::min(t_exit, fa / (fa - fb));
    }
    if (t_enter >= t_exit) return true;
  }
  return false;
}

DisplacementCounts place_contact_nodes(const CollisionModel& model, const StepFrame& frame, btSoftBody& soft, CollisionData& data,
                                       SoftNodeBounds* node_bounds) {
  Writer writer{model, frame, soft, data, DisplacementCounts{}};
  data.displacement.moved_nodes.clear();
  if (model.paired) {
    writer.paired_faces();
    writer.guard();
  } else {
    writer.ray_only();
  }
  // Every node written above is listed in moved_nodes (Writer::write).
  if (node_bounds != nullptr)
    for (const int node : data.displacement.moved_nodes) node_bounds->extend(node, soft.m_nodes[node].m_x);
  return writer.counts;
}

void hold_near_nodes(const CollisionModel& model, const StepFrame& frame, CollisionData& data) {
  // Hysteresis: a node held last step and still within release_distance in front of its plane
  // stays colliding (not moved), with a share of its force that ramps (smoothstep) from 1 on the
  // face to 0 at release_distance (normal_displacement, hunt_crossley_force.cpp): the node's force
  // fades out as it separates instead of dropping by a whole node's worth at the release. The
  // ramp is wide (2 mm) so that the dither of a held tool (tens of µm) changes a hovering node's
  // share by a few % only — the share's slope adds to the contact stiffness.
  const auto& planes = model.tool.planes();
  const double release_m = model.params.release_distance_m;
  for (const int node : data.broad.candidate_nodes) {
    const auto n = static_cast<std::size_t>(node);
    if (data.displacement.hold_stamp[n] != frame.step - 1 || data.displacement.moved_stamp[n] == frame.step) continue;
    const int plane_index = data.displacement.hold_plane[n];
    const ToolPlane& plane = planes[static_cast<std::size_t>(plane_index)];
    const double gap = plane.normal_tool.dot(data.broad.end_tool_m[n]) - plane.offset_m;
    if (gap > release_m) continue;  // separated: released
    if (gap < 0.0) continue;  // pushed behind its plane with no tool node hitting it: released
    data.displacement.node_share[n] = release_share(gap, release_m);
    data.displacement.hold_stamp[n] = frame.step;  // lifted off the face it moves freely (only its side is remembered)
    data.displacement.moved_stamp[n] = frame.step;
    data.displacement.moved_nodes.push_back(node);
  }
}

namespace {

// A face with a colliding soft node enters the force set on the plane that node is held on (the
// first colliding node found decides). A tool node that hit the face this step is kept as its
// leading node only if it lies on that same plane.
void add_force_face(const StepFrame& frame, CollisionData& data, int face, int plane_index) {
  const auto f = static_cast<std::size_t>(face);
  if (data.force.face_force_stamp[f] == frame.step) return;
  data.force.face_force_stamp[f] = frame.step;
  const bool hit_on_same_plane = data.exclusion.face_contact_stamp[f] == frame.step && data.exclusion.face_plane[f] == plane_index;
  if (!hit_on_same_plane) data.exclusion.face_lead_node[f] = -1;
  data.exclusion.face_plane[f] = plane_index;
  data.exclusion.contacted_faces.push_back(face);
}

}  // namespace

void collect_force_faces(const CollisionModel& model, const StepFrame& frame, CollisionData& data) {
  // Paper: "the calculation of x is executed if and only if at least one of the nodes belonging to
  // the triangle is in a colliding state" — the force set is every triangle around a colliding
  // soft node (displaced this step, or held within the release distance).
  data.exclusion.contacted_faces.clear();
  for (const int node : data.displacement.moved_nodes) {
    const auto n = static_cast<std::size_t>(node);
    for (int k = model.soft.faces_of_node_begin[n]; k < model.soft.faces_of_node_begin[n + 1]; ++k)
      add_force_face(frame, data, model.soft.faces_of_node[static_cast<std::size_t>(k)], data.displacement.hold_plane[n]);
  }
}

DisplacementCounts enforce_displacement(const CollisionModel& model, const StepFrame& frame, btSoftBody& soft,
                                        CollisionData& data, SoftNodeBounds* node_bounds) {
  const DisplacementCounts counts = place_contact_nodes(model, frame, soft, data, node_bounds);
  hold_near_nodes(model, frame, data);
  collect_force_faces(model, frame, data);
  return counts;
}

}  // namespace fissure::host::thin_body
