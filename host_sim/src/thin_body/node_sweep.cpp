// Stage 2: swept detection of tool-node / soft-triangle contacts, with no speed limit
// (BRIEF §3 item 2).
//
// Everything is done in the TOOL frame, where the tool nodes are fixed and the soft triangle
// moves from its start-of-step shape A (Bullet's m_q seen from the previous tool pose) to its
// end shape B (m_x seen from the current pose). That single relative motion contains both the
// tool's motion (any number of thicknesses per step) and the soft nodes' own motion within the
// step. A tool node p is in contact with triangle f when
//   * at the end it is behind or within contact_distance in front of B's plane (s_end ≤ d_c), and
//   * it came from the front: at the start it was in front of / touching A (s_start ≥ −d_c) —
//     or it was already in contact last step (side memory) and starts at most memory_depth
//     behind; a node that starts deep behind a triangle is on the far side of another surface;
//   * at the moment the linearly interpolated signed distance reaches d_c (τ ∈ [0, 1]) the node
//     projects inside the interpolated triangle A + τ(B − A). Nodes already touching use τ = 1
//     (the triangle under them now, so a sliding contact moves from triangle to triangle).
// The earliest crossing wins when several triangles qualify.
//
// Cost: a triangle visits the tool nodes binned under its swept footprint. Before that, each tool
// plane is tested as a whole against the two conditions above, on the box of its nodes in the
// visited cells (the extreme of a plane equation over a box is at a corner): a plane whose nodes all
// end in front of the triangle, or all start behind it (with none in contact last step, or all
// beyond the memory depth), is skipped. For a plate pressed face-first into a soft body that skips
// the far face and the rims — half or more of the nodes under a large triangle.
#include "collision_state.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fissure::host::thin_body {
namespace {

// Barycentric tolerance so that a node exactly on a shared edge is caught by both triangles.
constexpr double kBarycentricTolerance = 1e-7;
// The plane-level test evaluates the same signed distances as the node test in another order:
// this much slack (far below any contact distance, far above double rounding at tool sizes)
// keeps it from skipping a plane whose node the node test would just keep.
constexpr double kPlaneSkipSlack_m = 1e-12;

struct Triangle {
  Eigen::Vector3d a, b, c, normal;
  // Barycentric basis (edge vectors and their Gram determinant), precomputed once per triangle.
  Eigen::Vector3d e0, e1;
  double d00, d01, d11, inverse_denominator;
  bool valid;
};

Triangle make_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, double sign) {
  Triangle t;
  t.a = a;
  t.b = b;
  t.c = c;
  t.e0 = b - a;
  t.e1 = c - a;
  const Eigen::Vector3d n = t.e0.cross(t.e1);
  const double length = n.norm();
  t.d00 = t.e0.dot(t.e0);
  t.d01 = t.e0.dot(t.e1);
  t.d11 = t.e1.dot(t.e1);
  const double denominator = t.d00 * t.d11 - t.d01 * t.d01;
  t.valid = length > 1e-18 && denominator > 0.0;
  t.normal = t.valid ? Eigen::Vector3d(sign * n / length) : Eigen::Vector3d::Zero();
  t.inverse_denominator = t.valid ? 1.0 / denominator : 0.0;
  return t;
}

bool projects_inside(const Triangle& t, const Eigen::Vector3d& p) {
  const Eigen::Vector3d v2 = p - t.a;
  const double d20 = v2.dot(t.e0);
  const double d21 = v2.dot(t.e1);
  const double v = (t.d11 * d20 - t.d01 * d21) * t.inverse_denominator;
  const double w = (t.d00 * d21 - t.d01 * d20) * t.inverse_denominator;
  return v >= -kBarycentricTolerance && w >= -kBarycentricTolerance && v + w <= 1.0 + kBarycentricTolerance;
}

// Smallest and largest of n·x − d over a box: the extremes of a linear function are at corners.
double min_over_box(const Eigen::Vector3d& n, double d, const Eigen::AlignedBox3d& box) {
  return n.dot(box.center()) - d - n.cwiseAbs().dot(0.5 * box.sizes());
}
double max_over_box(const Eigen::Vector3d& n, double d, const Eigen::AlignedBox3d& box) {
  return n.dot(box.center()) - d + n.cwiseAbs().dot(0.5 * box.sizes());
}

}  // namespace

void prepare_node_sweep(const ToolNodes& tool, ToolNodeBins& bins) {
  const auto& positions = tool.positions_tool_m();
  const auto& plane_of_node = tool.plane_of_node();
  bins.positions_m.resize(bins.nodes.size());
  bins.planes.resize(bins.nodes.size());
  for (std::size_t b = 0; b < bins.nodes.size(); ++b) {
    const auto node = static_cast<std::size_t>(bins.nodes[b]);
    bins.positions_m[b] = positions[node];
    bins.planes[b] = plane_of_node[node];
  }
  bins.plane_bounds_m.assign(tool.planes().size(), Eigen::AlignedBox3d());
  for (std::size_t i = 0; i < positions.size(); ++i)
    bins.plane_bounds_m[static_cast<std::size_t>(plane_of_node[i])].extend(positions[i]);
}

void sweep_tool_nodes(const CollisionModel& model, CollisionData& data) {
  // Which planes had a node in contact last step (before this step's lists are reset).
  std::fill(data.sweep_plane_had_contact.begin(), data.sweep_plane_had_contact.end(), 0);
  for (const int node : data.contact_nodes)
    if (data.node_face[static_cast<std::size_t>(node)] >= 0)
      data.sweep_plane_had_contact[static_cast<std::size_t>(model.tool.plane_of_node()[static_cast<std::size_t>(node)])] = 1;
  data.node_face.swap(data.node_face_prev);
  std::fill(data.node_face.begin(), data.node_face.end(), -1);
  data.contact_nodes.clear();
  const auto& normals = model.tool.normals_tool();
  const std::size_t plane_count = model.bins.plane_bounds_m.size();
  const ToolNodeBins& bins = model.bins;
  const double contact = model.params.contact_distance_m;
  const double sign = model.soft.outward_sign;

  for (const int face : data.candidate_faces) {
    const auto& v = model.soft.face_nodes[static_cast<std::size_t>(face)];
    const auto at_start = [&](int k) { return data.start_tool_m[static_cast<std::size_t>(v[static_cast<std::size_t>(k)])]; };
    const auto at_end = [&](int k) { return data.end_tool_m[static_cast<std::size_t>(v[static_cast<std::size_t>(k)])]; };
    const Triangle start = make_triangle(at_start(0), at_start(1), at_start(2), sign);
    const Triangle end = make_triangle(at_end(0), at_end(1), at_end(2), sign);
    if (!start.valid || !end.valid) continue;
    // Tool nodes under the triangle's swept footprint (both shapes), via the bins.
    Eigen::AlignedBox3d swept;
    swept.extend(start.a).extend(start.b).extend(start.c).extend(end.a).extend(end.b).extend(end.c);
    const double pad = contact + model.memory_depth_m;
    // Faces whose swept bounds miss the tool's bounds (mostly along the thin axis) touch no node.
    const Eigen::AlignedBox3d& tool_bounds = model.tool.bounds_tool_m();
    if ((swept.min().array() > tool_bounds.max().array() + pad).any() ||
        (swept.max().array() < tool_bounds.min().array() - pad).any())
      continue;
    const int u0 = std::clamp(static_cast<int>(std::floor((swept.min()[bins.axis_u] - pad - bins.origin_u) / bins.cell_m)), 0, bins.cells_u - 1);
    const int u1 = std::clamp(static_cast<int>(std::floor((swept.max()[bins.axis_u] + pad - bins.origin_u) / bins.cell_m)), 0, bins.cells_u - 1);
    const int v0 = std::clamp(static_cast<int>(std::floor((swept.min()[bins.axis_v] - pad - bins.origin_v) / bins.cell_m)), 0, bins.cells_v - 1);
    const int v1 = std::clamp(static_cast<int>(std::floor((swept.max()[bins.axis_v] + pad - bins.origin_v) / bins.cell_m)), 0, bins.cells_v - 1);
    if (swept.max()[bins.axis_u] + pad < bins.origin_u || swept.min()[bins.axis_u] - pad > bins.origin_u + bins.cells_u * bins.cell_m ||
        swept.max()[bins.axis_v] + pad < bins.origin_v || swept.min()[bins.axis_v] - pad > bins.origin_v + bins.cells_v * bins.cell_m)
      continue;
    // The planes that may touch this triangle: their nodes in the cells visited below neither all
    // end in front of it nor all start behind it. The cells' extent (edge cells also hold the
    // nodes clamped into them: unbounded there; a little slack for the binning's rounding) bounds
    // every node the loop reaches, so a skipped plane only drops nodes the node test would drop.
    constexpr double kInfinity = std::numeric_limits<double>::infinity();
    constexpr double kCellSlack_m = 1e-9;
    const double cells_u_lo = u0 == 0 ? -kInfinity : bins.origin_u + u0 * bins.cell_m - kCellSlack_m;
    const double cells_u_hi = u1 == bins.cells_u - 1 ? kInfinity : bins.origin_u + (u1 + 1) * bins.cell_m + kCellSlack_m;
    const double cells_v_lo = v0 == 0 ? -kInfinity : bins.origin_v + v0 * bins.cell_m - kCellSlack_m;
    const double cells_v_hi = v1 == bins.cells_v - 1 ? kInfinity : bins.origin_v + (v1 + 1) * bins.cell_m + kCellSlack_m;
    const double d_end = end.normal.dot(end.a);
    const double d_start = start.normal.dot(start.a);
    bool any_open = false;
    for (std::size_t plane = 0; plane < plane_count; ++plane) {
      Eigen::AlignedBox3d under = bins.plane_bounds_m[plane];
      under.min()[bins.axis_u] = std::max(under.min()[bins.axis_u], cells_u_lo);
      under.max()[bins.axis_u] = std::min(under.max()[bins.axis_u], cells_u_hi);
      under.min()[bins.axis_v] = std::max(under.min()[bins.axis_v], cells_v_lo);
      under.max()[bins.axis_v] = std::min(under.max()[bins.axis_v], cells_v_hi);
      bool open = !under.isEmpty();
      if (open && min_over_box(end.normal, d_end, under) > contact + kPlaneSkipSlack_m) open = false;
      if (open) {
        const double s_start_max = max_over_box(start.normal, d_start, under);
        const bool memory_may_hold = data.sweep_plane_had_contact[plane] != 0 && s_start_max >= -model.memory_depth_m - kPlaneSkipSlack_m;
        if (s_start_max < -contact - kPlaneSkipSlack_m && !memory_may_hold) open = false;
      }
      data.sweep_plane_open[plane] = open ? 1 : 0;
      any_open = any_open || open;
    }
    if (!any_open) continue;
    for (int cu = u0; cu <= u1; ++cu) {
      for (int cv = v0; cv <= v1; ++cv) {
        const int cell = cu * bins.cells_v + cv;
        for (int b = bins.begin[static_cast<std::size_t>(cell)]; b < bins.begin[static_cast<std::size_t>(cell + 1)]; ++b) {
          const auto bin = static_cast<std::size_t>(b);
          if (data.sweep_plane_open[static_cast<std::size_t>(bins.planes[bin])] == 0) continue;
          const Eigen::Vector3d& p = bins.positions_m[bin];
          const double s_end = end.normal.dot(p - end.a);
          if (s_end > contact) continue;
          const int node = bins.nodes[bin];
          const auto n = static_cast<std::size_t>(node);
          const double s_start = start.normal.dot(p - start.a);
          const bool was_in_contact = data.node_face_prev[n] >= 0;
          if (s_start < -contact && !(was_in_contact && s_start >= -model.memory_depth_m)) continue;
          const double tau = s_start > contact ? (s_start - contact) / (s_start - s_end) : 1.0;
          bool inside = false;
          Eigen::Vector3d normal_at_tau = end.normal;
          if (tau >= 1.0) {
            inside = projects_inside(end, p);
          } else {
            const Triangle at_tau = make_triangle(start.a + tau * (end.a - start.a), start.b + tau * (end.b - start.b),
                                                  start.c + tau * (end.c - start.c), sign);
            inside = at_tau.valid && projects_inside(at_tau, p);
            normal_at_tau = at_tau.normal;
          }
          if (!inside) continue;
          const bool first = data.node_face[n] < 0;
          if (first || tau < data.node_tau[n] - 1e-12) {
            if (first) data.contact_nodes.push_back(node);
            data.node_face[n] = face;
            data.node_tau[n] = tau;
            data.node_facing[n] = normals[n].dot(normal_at_tau);
          }
        }
      }
    }
  }
  std::sort(data.contact_nodes.begin(), data.contact_nodes.end());  // deterministic order
  // Side memory: how many consecutive steps each node has been in contact.
  for (std::size_t i = 0; i < data.node_face.size(); ++i)
    data.node_age[i] = data.node_face[i] >= 0 ? (data.node_face_prev[i] >= 0 ? data.node_age[i] + 1 : 1) : 0;
}

}  // namespace fissure::host::thin_body
