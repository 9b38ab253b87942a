// Load-time part of the thin-body collision: soft-surface topology and rest state, tool-node bins,
// and the preallocation of every per-step buffer (the step itself never allocates).
#include "collision_state.hpp"

#include <BulletSoftBody/btSoftBody.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <tuple>

namespace fissure::host::thin_body {
namespace {

Eigen::Vector3d to_eigen(const btVector3& v) { return {v.x(), v.y(), v.z()}; }

ToolNodeBins build_bins(const ToolNodes& tool) {
  ToolNodeBins bins;
  const int w = tool.thin_axis();
  bins.axis_u = w == 0 ? 1 : 0;
  bins.axis_v = w == 2 ? 1 : 2;
  const auto& positions = tool.positions_tool_m();
  const int count = tool.node_count();
  const Eigen::AlignedBox3d& bounds = tool.bounds_tool_m();
  const double extent_u = std::max(bounds.sizes()[bins.axis_u], 1e-9);
  const double extent_v = std::max(bounds.sizes()[bins.axis_v], 1e-9);
  // About one node per face per cell: cell size from the node density over the footprint.
  const double per_face = std::max(1.0, 0.5 * count);
  bins.cell_m = std::max(std::sqrt(extent_u * extent_v / per_face), 1e-6);
  bins.cells_u = std::clamp(static_cast<int>(std::ceil(extent_u / bins.cell_m)) + 1, 1, 256);
  bins.cells_v = std::clamp(static_cast<int>(std::ceil(extent_v / bins.cell_m)) + 1, 1, 256);
  bins.origin_u = bounds.min()[bins.axis_u] - 0.5 * bins.cell_m;
  bins.origin_v = bounds.min()[bins.axis_v] - 0.5 * bins.cell_m;
  const auto cell_of = [&](const Eigen::Vector3d& p) {
    const int cu = std::clamp(static_cast<int>((p[bins.axis_u] - bins.origin_u) / bins.cell_m), 0, bins.cells_u - 1);
    const int cv = std::clamp(static_cast<int>((p[bins.axis_v] - bins.origin_v) / bins.cell_m), 0, bins.cells_v - 1);
    return cu * bins.cells_v + cv;
  };
  const std::size_t cells = static_cast<std::size_t>(bins.cells_u * bins.cells_v);
  bins.begin.assign(cells + 1, 0);
  for (const auto& p : positions) ++bins.begin[static_cast<std::size_t>(cell_of(p) + 1)];
  for (std::size_t c = 0; c < cells; ++c) bins.begin[c + 1] += bins.begin[c];
  bins.nodes.assign(static_cast<std::size_t>(count), -1);
  std::vector<int> fill(bins.begin.begin(), bins.begin.end() - 1);
  for (int i = 0; i < count; ++i)
    bins.nodes[static_cast<std::size_t>(fill[static_cast<std::size_t>(cell_of(positions[static_cast<std::size_t>(i)]))]++)] = i;
  return bins;
}

}  // namespace

void take_rest_state(const btSoftBody& soft, SoftSurfaceModel& model) {
  model.rest_node_world_m.resize(static_cast<std::size_t>(model.node_count));
  model.rest_bounds_world_m.setEmpty();
  for (int i = 0; i < model.node_count; ++i) {
    model.rest_node_world_m[static_cast<std::size_t>(i)] = to_eigen(soft.m_nodes[i].m_x);
    model.rest_bounds_world_m.extend(model.rest_node_world_m[static_cast<std::size_t>(i)]);
  }
  model.rest_centroid_world_m.resize(static_cast<std::size_t>(model.face_count));
  model.rest_area_m2.resize(static_cast<std::size_t>(model.face_count));
  model.node_rest_area_m2.assign(static_cast<std::size_t>(model.node_count), 0.0);
  double volume6 = 0.0;
  double area_sum = 0.0;
  model.max_rest_edge_m = 0.0;
  Eigen::Vector3d reference = to_eigen(soft.m_nodes[0].m_x);
  for (int f = 0; f < model.face_count; ++f) {
    const auto& nodes = model.face_nodes[static_cast<std::size_t>(f)];
    const Eigen::Vector3d a = to_eigen(soft.m_nodes[nodes[0]].m_x);
    const Eigen::Vector3d b = to_eigen(soft.m_nodes[nodes[1]].m_x);
    const Eigen::Vector3d c = to_eigen(soft.m_nodes[nodes[2]].m_x);
    model.rest_centroid_world_m[static_cast<std::size_t>(f)] = (a + b + c) / 3.0;
    const double area = 0.5 * (b - a).cross(c - a).norm();
    model.rest_area_m2[static_cast<std::size_t>(f)] = area;
    for (const int node : nodes) model.node_rest_area_m2[static_cast<std::size_t>(node)] += area / 3.0;
    area_sum += area;
    volume6 += (a - reference).dot((b - reference).cross(c - reference));
    model.max_rest_edge_m = std::max({model.max_rest_edge_m, (b - a).norm(), (c - b).norm(), (a - c).norm()});
  }
  // A closed surface has a volume comparable to area^(3/2); an open sheet has ~0 and keeps
  // Bullet's winding as its outward side.
  const double closed_threshold = 1e-3 * std::pow(area_sum, 1.5);
  model.outward_sign = (std::abs(volume6) / 6.0 > closed_threshold && volume6 < 0.0) ? -1.0 : 1.0;
}

CollisionModel build_collision_model(const ToolNodes& tool, const btSoftBody& soft,
                                     const ThinBodyCollisionParams& params, bool paired) {
  if (soft.m_faces.size() == 0 || soft.m_nodes.size() == 0)
    throw std::invalid_argument("thin-body collision: the soft body has no triangle faces");
  if (!(params.skin_m > 0.0) || !(params.contact_distance_m >= params.skin_m))
    throw std::invalid_argument("thin-body collision: need skin_m > 0 and contact_distance_m >= skin_m");
  if (!(params.release_distance_m >= 0.0))
    throw std::invalid_argument("thin-body collision: release_distance_m must be >= 0");
  if (!(params.velocity_filter_cutoff_hz > 0.0))
    throw std::invalid_argument("thin-body collision: velocity_filter_cutoff_hz must be > 0");
  if (!(params.contact_onset_ramp_s >= 0.0) || !std::isfinite(params.contact_onset_ramp_s))
    throw std::invalid_argument("thin-body collision: contact_onset_ramp_s must be >= 0 (finite)");
  if (!(params.solver_reach_m >= 0.0) || !std::isfinite(params.solver_reach_m))
    throw std::invalid_argument("thin-body collision: solver_reach_m must be >= 0 (finite)");
  const auto& hc = params.hunt_crossley;
  if (!(hc.k >= 0.0) || !(hc.lambda >= 0.0) || !(hc.n > 0.0) || !std::isfinite(hc.k) || !std::isfinite(hc.lambda) ||
      !std::isfinite(hc.n))
    throw std::invalid_argument("thin-body collision: Hunt-Crossley k, lambda >= 0 and n > 0 (finite)");
  CollisionModel model{tool, build_bins(tool), SoftSurfaceModel{}, params, paired, 0.0, Eigen::Vector3d::Zero(), 0.0, {}, 0.0, {}, {}};
  prepare_node_sweep(model.tool, model.bins);
  SoftSurfaceModel& surface = model.soft;
  surface.node_count = soft.m_nodes.size();
  surface.face_count = soft.m_faces.size();
  const btSoftBody::Node* first = &soft.m_nodes[0];
  surface.face_nodes.resize(static_cast<std::size_t>(surface.face_count));
  surface.faces_of_node_begin.assign(static_cast<std::size_t>(surface.node_count + 1), 0);
  for (int f = 0; f < surface.face_count; ++f) {
    for (int k = 0; k < 3; ++k) {
      const int index = static_cast<int>(soft.m_faces[f].m_n[k] - first);
      surface.face_nodes[static_cast<std::size_t>(f)][static_cast<std::size_t>(k)] = index;
      ++surface.faces_of_node_begin[static_cast<std::size_t>(index + 1)];
    }
  }
  for (int i = 0; i < surface.node_count; ++i) {
    const auto n = static_cast<std::size_t>(i);
    surface.has_faceless_nodes = surface.has_faceless_nodes || surface.faces_of_node_begin[n + 1] == 0;  // counts, before the sum
    surface.faces_of_node_begin[n + 1] += surface.faces_of_node_begin[n];
  }
  surface.faces_of_node.assign(static_cast<std::size_t>(surface.faces_of_node_begin.back()), -1);
  std::vector<int> fill(surface.faces_of_node_begin.begin(), surface.faces_of_node_begin.end() - 1);
  for (int f = 0; f < surface.face_count; ++f)
    for (const int index : surface.face_nodes[static_cast<std::size_t>(f)])
      surface.faces_of_node[static_cast<std::size_t>(fill[static_cast<std::size_t>(index)]++)] = f;
  take_rest_state(soft, surface);
  // A node already in contact may start a step this far behind its triangle (the soft solver
  // pushing a held node back a little) and still be in contact; further behind is another surface.
  model.memory_depth_m = std::max(tool.thickness_m(), 10.0 * params.contact_distance_m);
  model.near_pad_m = params.contact_distance_m + params.skin_m +
                     (params.response == ContactResponse::kInSolver ? params.solver_reach_m : 0.0);
  const double near_pad_m = model.near_pad_m;
  model.near_sphere_centre_tool_m = tool.bounds_tool_m().center();
  model.near_sphere_radius_m = 0.5 * (tool.bounds_tool_m().sizes() + Eigen::Vector3d::Constant(2.0 * near_pad_m)).norm();
  model.rim_plane.assign(tool.planes().size(), 0);
  for (int i = 0; i < tool.node_count(); ++i)
    if (tool.edge_node_flags()[static_cast<std::size_t>(i)] != 0)
      model.rim_plane[static_cast<std::size_t>(tool.plane_of_node()[static_cast<std::size_t>(i)])] = 1;
  // Sorted and deduplicated (n log n: a fine convex mesh has 10⁴–10⁵ feature edges).
  for (const auto& edge : tool.feature_edges_tool_m())
    for (const Eigen::Vector3d& end : edge) model.tool_corners_tool_m.push_back(end);
  const auto lexicographic = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return std::tie(a.x(), a.y(), a.z()) < std::tie(b.x(), b.y(), b.z());
  };
  std::sort(model.tool_corners_tool_m.begin(), model.tool_corners_tool_m.end(), lexicographic);
  model.tool_corners_tool_m.erase(std::unique(model.tool_corners_tool_m.begin(), model.tool_corners_tool_m.end()), model.tool_corners_tool_m.end());
  model.rim_plane_back_m.assign(tool.planes().size(), -std::numeric_limits<double>::infinity());
  for (std::size_t q = 0; q < tool.planes().size(); ++q)
    if (model.rim_plane[q] != 0) model.rim_plane_back_m[q] = tool_height_range(model, Eigen::Vector3d::Zero(), tool.planes()[q].normal_tool).lowest_m;
  return model;
}

ToolHeightRange tool_height_range(const CollisionModel& model, const Eigen::Vector3d& origin, const Eigen::Vector3d& normal) {
  ToolHeightRange range;
  for (const Eigen::Vector3d& corner : model.tool_corners_tool_m) {
    const double h = normal.dot(corner - origin);
    range.lowest_m = std::min(range.lowest_m, h);
    range.highest_m = std::max(range.highest_m, h);
  }
  return range;
}

void allocate_collision_data(const CollisionModel& model, CollisionData& data) {
  const auto tool_nodes = static_cast<std::size_t>(model.tool.node_count());
  const auto soft_nodes = static_cast<std::size_t>(model.soft.node_count);
  const auto soft_faces = static_cast<std::size_t>(model.soft.face_count);
  data.step = 0;
  data.sweep.node_face.assign(tool_nodes, -1);
  data.sweep.node_face_prev.assign(tool_nodes, -1);
  data.sweep.node_age.assign(tool_nodes, 0);
  data.sweep.node_tau.assign(tool_nodes, 0.0);
  data.sweep.node_facing.assign(tool_nodes, 0.0);
  data.exclusion.node_excluded_stamp.assign(tool_nodes, -1);
  data.sweep.contact_nodes.clear();
  data.sweep.contact_nodes.reserve(tool_nodes);
  data.exclusion.vector.clear();
  data.exclusion.vector.reserve(tool_nodes);
  data.broad.soft_stamp.assign(soft_nodes, -1);
  data.broad.start_tool_m.assign(soft_nodes, Eigen::Vector3d::Zero());
  data.broad.end_tool_m.assign(soft_nodes, Eigen::Vector3d::Zero());
  data.displacement.moved_stamp.assign(soft_nodes, -1);
  data.displacement.moved_nodes.clear();
  data.displacement.moved_nodes.reserve(soft_nodes);
  data.displacement.hold_stamp.assign(soft_nodes, -1);
  data.displacement.hold_plane.assign(soft_nodes, -1);
  data.displacement.node_share.assign(soft_nodes, 0.0);
  data.solver.iterate_tool_m.assign(soft_nodes, Eigen::Vector3d::Zero());
  data.solver.friction_anchor_tool_m.assign(soft_nodes, Eigen::Vector3d::Zero());
  data.solver.friction_anchor_stamp.assign(soft_nodes, -1);
  data.solver.friction_correction_tool_m.assign(soft_nodes, Eigen::Vector3d::Zero());
  data.solver.friction_sliding.assign(soft_nodes, 0);
  data.solver.rim_correction_world_m.assign(soft_nodes, Eigen::Vector3d::Zero());
  data.solver.rim_correction_stamp.assign(soft_nodes, -1);
  data.broad.candidate_nodes.clear();
  data.broad.candidate_nodes.reserve(soft_nodes);
  data.sweep.plane_had_contact.assign(model.tool.planes().size(), 0);
  data.sweep.plane_open.assign(model.tool.planes().size(), 0);
  data.sweep.contact_words.assign((tool_nodes + 63) / 64, 0);
  data.broad.face_candidate_stamp.assign(soft_faces, -1);
  data.broad.candidate_faces.clear();
  data.broad.candidate_faces.reserve(soft_faces);
  data.exclusion.face_contact_stamp.assign(soft_faces, -1);
  data.force.face_force_stamp.assign(soft_faces, -1);
  data.exclusion.face_plane.assign(soft_faces, -1);
  data.exclusion.face_lead_node.assign(soft_faces, -1);
  data.exclusion.contacted_faces.clear();
  data.exclusion.contacted_faces.reserve(soft_faces);
  data.force.hc_stamp.assign(soft_faces, -1);
  data.force.hc_x_prev_m.assign(soft_faces, 0.0);
  data.force.hc_rate_filtered_m_s.assign(soft_faces, 0.0);
  data.force.hc_corner_stamp.assign(3 * soft_faces, -1);
  data.force.hc_corner_x_prev_m.assign(3 * soft_faces, 0.0);
  data.force.hc_corner_rate_filtered_m_s.assign(3 * soft_faces, 0.0);
  data.force.hc_corner_onset.assign(3 * soft_faces, 0.0);
}

StepFrame make_step_frame(const CollisionModel& model, std::int64_t step, const ToolPose& previous,
                          const ToolPose& current, double dt_s) {
  StepFrame frame;
  frame.step = step;
  frame.dt_s = dt_s;
  frame.r_prev = previous.orientation_world.normalized().toRotationMatrix();
  frame.t_prev = previous.position_world_m;
  frame.r_cur = current.orientation_world.normalized().toRotationMatrix();
  frame.t_cur = current.position_world_m;
  frame.velocity_world_m_s = (current.position_world_m - previous.position_world_m) / dt_s;
  const Eigen::AngleAxisd rotation(frame.r_cur * frame.r_prev.transpose());
  frame.angular_velocity_world = rotation.axis() * (rotation.angle() / dt_s);
  frame.swept_tool_world_m.setEmpty();
  const Eigen::AlignedBox3d& bounds = model.tool.bounds_tool_m();
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d p = bounds.corner(static_cast<Eigen::AlignedBox3d::CornerType>(corner));
    frame.swept_tool_world_m.extend(frame.r_prev * p + frame.t_prev);
    frame.swept_tool_world_m.extend(frame.r_cur * p + frame.t_cur);
  }
  return frame;
}

}  // namespace fissure::host::thin_body
