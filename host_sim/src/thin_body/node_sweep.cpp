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
#include "collision_state.hpp"

#include <algorithm>
#include <cmath>

namespace fissure::host::thin_body {
namespace {

// Barycentric tolerance so that a node exactly on a shared edge is caught by both triangles.
constexpr double kBarycentricTolerance = 1e-7;

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

}  // namespace

void sweep_tool_nodes(const CollisionModel& model, CollisionData& data) {
  data.node_face.swap(data.node_face_prev);
  std::fill(data.node_face.begin(), data.node_face.end(), -1);
  data.contact_nodes.clear();
  const auto& positions = model.tool.positions_tool_m();
  const auto& normals = model.tool.normals_tool();
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
    for (int cu = u0; cu <= u1; ++cu) {
      for (int cv = v0; cv <= v1; ++cv) {
        const int cell = cu * bins.cells_v + cv;
        for (int b = bins.begin[static_cast<std::size_t>(cell)]; b < bins.begin[static_cast<std::size_t>(cell + 1)]; ++b) {
          const int node = bins.nodes[static_cast<std::size_t>(b)];
          const auto n = static_cast<std::size_t>(node);
          const Eigen::Vector3d& p = positions[n];
          const double s_end = end.normal.dot(p - end.a);
          if (s_end > contact) continue;
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
