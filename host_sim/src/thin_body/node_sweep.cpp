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
// The footprint: a triangle visits only the tool nodes binned under a box that holds every node
// the test above can accept for it, derived from the test itself (footprint_for_crossing,
// footprint_for_touching), not from the triangle's swept bounds padded by the contact distance and
// the memory depth: a node touching A at the start may end far behind B when a step carries the
// soft surface through the tool, and project on B from far outside B's bounds along a tilted
// normal — such a padded box loses it (1 to 21 tool nodes in about a third of such random steps;
// no soft node crosses, but a tool node can pierce a triangle interior). For a triangle that only
// translates relative to the tool the box is tighter than the padded one (its swept bounds + d_c,
// and B's bounds pushed along n_B by how far a node can start
// behind A); turning and deforming triangles get a margin that grows with how far their normal
// can turn within the step.
//
// Cost: a triangle visits the tool nodes binned under its footprint. Before that, each tool
// plane is tested as a whole against the two conditions above, on the box of its nodes in the
// visited cells (the extreme of a plane equation over a box is at a corner): a plane whose nodes all
// end in front of the triangle, or all start behind it (with none in contact last step, or all
// beyond the memory depth), is skipped. For a plate pressed face-first into a soft body that skips
// the far face and the rims — half or more of the nodes under a large triangle. The nodes are binned
// per plane, so a skipped plane's nodes are not even read, and within an open plane each row of
// cells is cut to the interval where the triangle's end plane can come within contact_distance of
// a node (the same bound per cell, linear along the row). None of this changes a contact (tests/
// host_sim/node_sweep_test.cpp compares with the node test applied to every tool node).
// On a plate held in a coarse ball most of its nodes lie under a skipped plane or outside a row's
// interval, so the stage runs several times fewer node tests than a plain footprint visit
// (figures in docs/decisions.md, "Node sweep").
#include "collision_state.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cmath>
#include <limits>
#include <utility>

namespace fissure::host::thin_body {
namespace {

// Barycentric tolerance so that a node exactly on a shared edge is caught by both triangles.
constexpr double kBarycentricTolerance = 1e-7;
// The plane-level test evaluates the same signed distances as the node test in another order:
// this much slack (far below any contact distance, far above double rounding at tool sizes)
// keeps it from skipping a plane whose node the node test would just keep.
constexpr double kPlaneSkipSlack_m = 1e-12;
// The footprint's slack against rounding: absolute, and relative to the triangle's swept size (the
// node test's barycentric tolerance, 1e-7 of an edge, with a margin).
constexpr double kFootprintSlack_m = 1e-9;
constexpr double kFootprintRelativeSlack = 1e-6;

struct Triangle {
  Eigen::Vector3d a, b, c, normal;
  // Barycentric basis (edge vectors and their Gram determinant), precomputed once per triangle.
  Eigen::Vector3d e0, e1;
  double d00, d01, d11, inverse_denominator;
  bool valid;
  // e0 × e1 and its length (make_triangle only: the sweep's footprint reads them).
  Eigen::Vector3d area_normal;
  double area_normal_length;
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
  t.area_normal = n;
  t.area_normal_length = length;
  t.d00 = t.e0.dot(t.e0);
  t.d01 = t.e0.dot(t.e1);
  t.d11 = t.e1.dot(t.e1);
  const double denominator = t.d00 * t.d11 - t.d01 * t.d01;
  t.valid = length > 1e-18 && denominator > 0.0;
  t.normal = t.valid ? Eigen::Vector3d(sign * n / length) : Eigen::Vector3d::Zero();
  t.inverse_denominator = t.valid ? 1.0 / denominator : 0.0;
  return t;
}

// make_triangle in two halves, for the per-node triangle at τ: the barycentric basis (false: a
// degenerate Gram determinant), then the unit normal (false: a degenerate cross product). Both
// true ⇔ make_triangle's `valid`, with the same values.
bool barycentric_basis(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, Triangle& t) {
  t.a = a;
  t.b = b;
  t.c = c;
  t.e0 = b - a;
  t.e1 = c - a;
  t.d00 = t.e0.dot(t.e0);
  t.d01 = t.e0.dot(t.e1);
  t.d11 = t.e1.dot(t.e1);
  const double denominator = t.d00 * t.d11 - t.d01 * t.d01;
  t.valid = denominator > 0.0;
  t.inverse_denominator = t.valid ? 1.0 / denominator : 0.0;
  return t.valid;
}
bool unit_normal(Triangle& t, double sign) {
  const Eigen::Vector3d n = t.e0.cross(t.e1);
  const double length = n.norm();
  t.valid = t.valid && length > 1e-18;
  t.normal = t.valid ? Eigen::Vector3d(sign * n / length) : Eigen::Vector3d::Zero();
  return t.valid;
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

// Range of c0 + c1·τ + c2·τ² over τ ∈ [0, 1] (the ends and the vertex when it lies inside).
std::pair<double, double> quadratic_range(double c0, double c1, double c2) {
  double lo = std::min(c0, c0 + c1 + c2);
  double hi = std::max(c0, c0 + c1 + c2);
  if (c2 != 0.0) {
    const double vertex = -c1 / (2.0 * c2);
    if (vertex > 0.0 && vertex < 1.0) {
      const double at_vertex = c0 + vertex * (c1 + c2 * vertex);
      lo = std::min(lo, at_vertex);
      hi = std::max(hi, at_vertex);
    }
  }
  return {lo, hi};
}

// Where the node test's CROSSING branch (s_start > d_c, τ < 1) can accept a tool node p: p
// projects inside the interpolated triangle T(τ) = A + τ(B − A) at a point q, p = q + σ·n(τ), and
// q lies in the swept bounds of A and B. Two bounds on the offset p − q, per axis k; both hold,
// the smaller is used:
// (1) along the thin axis w, p_w − q_w = σ·n_w(τ) is at most D (the tool's thickness and the
//     triangle's swept extent along w), so |p_k − q_k| ≤ D·|N_k(τ)|/|N_w(τ)|, with the
//     unnormalised normal N(τ) = e0(τ) × e1(τ) = N_A + τ·N1 + τ²·N2 (N1 = e0_A × Δe1 + Δe0 × e1_A,
//     N2 = Δe0 × Δe1) bounded component by component over τ ∈ [0, 1]. Tight for a triangle facing
//     the tool's face; none when N_w(τ) may vanish (a triangle edge-on to the tool).
// (2) |p_k − q_k| ≤ |σ|·|n_k(τ)|. With p − a(τ) = (1 − τ)(p − a_A) + τ(p − a_B) and
//     d_c = (1 − τ)·s_start + τ·s_end (the τ the test solves for):
//       σ − d_c = (1 − τ)(n(τ) − n_A)·(p − a_A) + τ(n(τ) − n_B)·(p − a_B),
//     and p − a_A = σ·n(τ) + (q − a(τ)) + τ(a_B − a_A) (the same from B), where
//     (n(τ) − n_A)·n(τ) = |n(τ) − n_A|²/2. So |σ|·(1 − turn²/2) ≤ d_c + turn·(L + |a_B − a_A|),
//     with L the triangle's longest edge (start or end: an edge's length is convex in τ) and
//     turn a bound on how far the unit normal turns within the step: |N(τ) − N_A| and
//     |N(τ) − N_B| are both ≤ |N1| + |N2| =: c_N, so |N(τ)| ≥ |N_A| − c_N, and for vectors
//     |u/|u| − v/|v|| ≤ |u − v|/√(|u||v|) (as |u − v|² ≥ |u||v|·|û − v̂|²). Per
//     axis |n_k(τ)| ≤ |n_A,k| + turn_A (and the same from B). A translating triangle has turn 0:
//     the swept bounds + d_c, whatever its orientation.
Eigen::AlignedBox3d footprint_for_crossing(const Triangle& start, const Triangle& end, const Eigen::AlignedBox3d& swept,
                                           const Eigen::AlignedBox3d& tool_bounds, double contact, int axis_w) {
  const Eigen::Vector3d d0 = end.e0 - start.e0;
  const Eigen::Vector3d d1 = end.e1 - start.e1;
  const Eigen::Vector3d& n_start = start.area_normal;
  const Eigen::Vector3d n_2 = d0.cross(d1);
  const Eigen::Vector3d n_1 = end.area_normal - n_start - n_2;  // = e0_A × Δe1 + Δe0 × e1_A
  const double change = n_1.norm() + n_2.norm();
  const auto turn_from = [change](double length) {
    const double least = length - change;  // |N(τ)| ≥ |N_ref| − change
    return least > 0.0 ? std::min(2.0, change / std::sqrt(length * least)) : 2.0;
  };
  const double turn_start = turn_from(start.area_normal_length);
  const double turn_end = turn_from(end.area_normal_length);
  const double turn = std::max(turn_start, turn_end);
  const double shrink = 1.0 - 0.5 * turn * turn;
  // Per axis, |p_k − q_k| is also at most how far apart a tool point and a point of the swept
  // bounds can be (all there is when turn ≥ √2).
  Eigen::Vector3d reach = (tool_bounds.max() - swept.min()).cwiseAbs().cwiseMax((swept.max() - tool_bounds.min()).cwiseAbs());
  if (shrink > 1e-3) {
    const double edge_squared = std::max({start.d00, start.d11, (start.e1 - start.e0).squaredNorm(), end.d00, end.d11,
                                          (end.e1 - end.e0).squaredNorm()});
    const double sigma_max = (contact + turn * (std::sqrt(edge_squared) + (end.a - start.a).norm())) / shrink * (1.0 + 1e-9);
    for (int k = 0; k < 3; ++k)
      reach[k] = std::min(reach[k], sigma_max * std::min({1.0, std::abs(start.normal[k]) + turn_start, std::abs(end.normal[k]) + turn_end}));
  }
  // (1): N_w(τ) keeps its sign over the step (with a relative margin against rounding).
  const auto [w_lo, w_hi] = quadratic_range(n_start[axis_w], n_1[axis_w], n_2[axis_w]);
  const double n_scale = n_start.cwiseAbs().sum() + n_1.cwiseAbs().sum() + n_2.cwiseAbs().sum();
  const double n_w_min = (w_lo > 0.0 ? w_lo : (w_hi < 0.0 ? -w_hi : 0.0)) - 1e-9 * n_scale;
  if (n_w_min > 0.0) {
    // (q may lie a barycentric tolerance outside the swept bounds: the same slack as the caller's.)
    const double depth_w = std::max(tool_bounds.max()[axis_w] - swept.min()[axis_w], swept.max()[axis_w] - tool_bounds.min()[axis_w]) +
                           kFootprintSlack_m + kFootprintRelativeSlack * swept.diagonal().norm();
    for (int k = 0; k < 3; ++k) {
      if (k == axis_w) continue;
      const auto [k_lo, k_hi] = quadratic_range(n_start[k], n_1[k], n_2[k]);
      const double n_k_max = std::max(std::abs(k_lo), std::abs(k_hi)) + 1e-9 * n_scale;
      reach[k] = std::min(reach[k], depth_w * n_k_max / n_w_min * (1.0 + 1e-9));
    }
  }
  return Eigen::AlignedBox3d(swept.min() - reach, swept.max() + reach);
}

// Where the node test's TOUCHING branch (−start_depth ≤ s_start ≤ d_c, τ = 1) can accept a tool
// node p: p projects inside the END triangle B at q, p = q + s·n_B with s = s_end ≤ d_c. Nothing
// in the test bounds s from below but the start: s_start = n_A·(q − a_A) + s·(n_A·n_B) ≥
// −start_depth, so when n_A·n_B > 0, s ≥ (−start_depth − max over B's corners of n_A·(q − a_A)) /
// n_A·n_B (exact: linear in q). When a step carries the soft surface through the tool that is the
// distance carried, and p can end far behind B, far outside B's own bounds along a tilted normal —
// the node a footprint of the swept bounds + d_c + memory depth loses. Otherwise (a normal
// turned by more than 90°) s_start − s comes from its extreme over the tool's bounds. Per axis,
// p_k ∈ the tool's bounds and q_k ∈ B's bounds also bound s (through the thin axis mostly).
Eigen::AlignedBox3d footprint_for_touching(const Triangle& start, const Triangle& end, const Eigen::AlignedBox3d& tool_bounds, double contact,
                                           double start_depth, double slack_m) {
  Eigen::AlignedBox3d end_bounds;
  end_bounds.extend(end.a).extend(end.b).extend(end.c);
  const double alignment = start.normal.dot(end.normal);
  double s_lo = 0.0;
  if (alignment > 1e-3) {
    const double ahead = std::max({start.normal.dot(end.a - start.a), start.normal.dot(end.b - start.a), start.normal.dot(end.c - start.a)});
    s_lo = (-start_depth - ahead - slack_m) / alignment;
    s_lo -= 1e-9 * std::abs(s_lo);
  } else {
    const double delta_max = max_over_box(start.normal - end.normal, start.normal.dot(start.a) - end.normal.dot(end.a), tool_bounds);
    s_lo = -start_depth - delta_max - slack_m;
  }
  double s_hi = contact;
  for (int k = 0; k < 3; ++k) {
    const double n_k = end.normal[k];
    if (std::abs(n_k) < 1e-6) continue;  // no useful bound (and none lost: it only narrows)
    const double a = (tool_bounds.min()[k] - end_bounds.max()[k]) / n_k;
    const double b = (tool_bounds.max()[k] - end_bounds.min()[k]) / n_k;
    // Widened against the division's rounding and by the caller's slack (q may lie a rounding
    // tolerance outside B).
    const double widen = 1e-9 * (std::abs(a) + std::abs(b)) + slack_m / std::abs(n_k);
    s_lo = std::max(s_lo, std::min(a, b) - widen);
    s_hi = std::min(s_hi, std::max(a, b) + widen);
  }
  if (s_lo > s_hi) return Eigen::AlignedBox3d();  // empty: no node can touch B
  const Eigen::Vector3d along_lo = s_lo * end.normal;
  const Eigen::Vector3d along_hi = s_hi * end.normal;
  return Eigen::AlignedBox3d(end_bounds.min() + along_lo.cwiseMin(along_hi), end_bounds.max() + along_lo.cwiseMax(along_hi));
}

}  // namespace

void prepare_node_sweep(const ToolNodes& tool, ToolNodeBins& bins) {
  const auto& positions = tool.positions_tool_m();
  const auto& plane_of_node = tool.plane_of_node();
  const std::size_t plane_count = tool.planes().size();
  const auto cells = static_cast<std::size_t>(bins.cells_u * bins.cells_v);
  // Each node stays in the cell bins.begin / bins.nodes put it in (edge cells included).
  std::vector<std::size_t> cell_of_node(positions.size(), 0);
  for (std::size_t c = 0; c < cells; ++c)
    for (int b = bins.begin[c]; b < bins.begin[c + 1]; ++b) cell_of_node[static_cast<std::size_t>(bins.nodes[static_cast<std::size_t>(b)])] = c;
  bins.plane_cell_begin.assign(plane_count * cells + 1, 0);
  for (std::size_t i = 0; i < positions.size(); ++i)
    ++bins.plane_cell_begin[static_cast<std::size_t>(plane_of_node[i]) * cells + cell_of_node[i] + 1];
  for (std::size_t k = 0; k < plane_count * cells; ++k) bins.plane_cell_begin[k + 1] += bins.plane_cell_begin[k];
  bins.plane_cell_nodes.assign(positions.size(), -1);
  bins.plane_cell_positions_m.assign(positions.size(), Eigen::Vector3d::Zero());
  std::vector<int> fill(bins.plane_cell_begin.begin(), bins.plane_cell_begin.end() - 1);
  for (const int node : bins.nodes) {  // cell order, and the cell's own order inside it
    const auto i = static_cast<std::size_t>(node);
    const auto slot = static_cast<std::size_t>(fill[static_cast<std::size_t>(plane_of_node[i]) * cells + cell_of_node[i]]++);
    bins.plane_cell_nodes[slot] = node;
    bins.plane_cell_positions_m[slot] = positions[i];
  }
  bins.plane_bounds_m.assign(plane_count, Eigen::AlignedBox3d());
  for (std::size_t i = 0; i < positions.size(); ++i)
    bins.plane_bounds_m[static_cast<std::size_t>(plane_of_node[i])].extend(positions[i]);
}

void sweep_tool_nodes(const CollisionModel& model, CollisionData& data) {
  // Which planes had a node in contact last step (before this step's lists are reset).
  std::fill(data.sweep.plane_had_contact.begin(), data.sweep.plane_had_contact.end(), 0);
  for (const int node : data.sweep.contact_nodes)
    if (data.sweep.node_face[static_cast<std::size_t>(node)] >= 0)
      data.sweep.plane_had_contact[static_cast<std::size_t>(model.tool.plane_of_node()[static_cast<std::size_t>(node)])] = 1;
  data.sweep.node_face.swap(data.sweep.node_face_prev);
  std::fill(data.sweep.node_face.begin(), data.sweep.node_face.end(), -1);
  data.sweep.contact_nodes.clear();
  const auto& normals = model.tool.normals_tool();
  const std::size_t plane_count = model.bins.plane_bounds_m.size();
  const ToolNodeBins& bins = model.bins;
  const double contact = model.params.contact_distance_m;
  const double sign = model.soft.outward_sign;
  // How far behind a triangle a node may start and still be accepted (the node test's start
  // condition): the memory depth once any node was in contact last step.
  const bool any_had_contact =
      std::any_of(data.sweep.plane_had_contact.begin(), data.sweep.plane_had_contact.end(), [](std::uint8_t had) { return had != 0; });
  const double start_depth = any_had_contact ? std::max(contact, model.memory_depth_m) : contact;
  data.sweep.node_tests = 0;
  const int axis_w = 3 - bins.axis_u - bins.axis_v;  // the tool's thin axis

  for (const int face : data.broad.candidate_faces) {
    const auto& v = model.soft.face_nodes[static_cast<std::size_t>(face)];
    const auto at_start = [&](int k) { return data.broad.start_tool_m[static_cast<std::size_t>(v[static_cast<std::size_t>(k)])]; };
    const auto at_end = [&](int k) { return data.broad.end_tool_m[static_cast<std::size_t>(v[static_cast<std::size_t>(k)])]; };
    const Triangle start = make_triangle(at_start(0), at_start(1), at_start(2), sign);
    const Triangle end = make_triangle(at_end(0), at_end(1), at_end(2), sign);
    if (!start.valid || !end.valid) continue;
    // No tool node can pass the node test when the whole tool ends in front of the triangle or
    // starts deeper behind it than the start condition allows (the plane test below, on the
    // tool's bounds: a cheap cut before the footprint's bounds are worked out).
    const Eigen::AlignedBox3d& tool_bounds = model.tool.bounds_tool_m();
    const double d_end = end.normal.dot(end.a);
    const double d_start = start.normal.dot(start.a);
    if (min_over_box(end.normal, d_end, tool_bounds) > contact + kPlaneSkipSlack_m ||
        max_over_box(start.normal, d_start, tool_bounds) < -start_depth - kPlaneSkipSlack_m)
      continue;
    // The footprint (see footprint_for_crossing / footprint_for_touching): every tool node the
    // node test can accept for this triangle lies in it, so only the bins' cells under it are read.
    Eigen::AlignedBox3d swept;
    swept.extend(start.a).extend(start.b).extend(start.c).extend(end.a).extend(end.b).extend(end.c);
    // Rounding: the node test's barycentric tolerance lets a projection lie up to ~1e-7 of the
    // triangle's size outside it; the bounds are evaluated in another order than the test.
    const double footprint_slack = kFootprintSlack_m + kFootprintRelativeSlack * swept.diagonal().norm();
    Eigen::AlignedBox3d footprint = footprint_for_crossing(start, end, swept, tool_bounds, contact, axis_w);
    footprint.extend(footprint_for_touching(start, end, tool_bounds, contact, start_depth, footprint_slack));
    footprint.min().array() -= footprint_slack;
    footprint.max().array() += footprint_slack;
    // A footprint that misses the tool's bounds (mostly along the thin axis) holds no node. (The
    // bins need no such test of their own: their edge cells hold every node beyond them.)
    if ((footprint.min().array() > tool_bounds.max().array()).any() || (footprint.max().array() < tool_bounds.min().array()).any())
      continue;
    const auto cell_of = [&](double x, double origin, int cells) {
      return static_cast<int>(std::clamp(std::floor((x - origin) / bins.cell_m), 0.0, static_cast<double>(cells - 1)));
    };
    const int u0 = cell_of(footprint.min()[bins.axis_u], bins.origin_u, bins.cells_u);
    const int u1 = cell_of(footprint.max()[bins.axis_u], bins.origin_u, bins.cells_u);
    const int v0 = cell_of(footprint.min()[bins.axis_v], bins.origin_v, bins.cells_v);
    const int v1 = cell_of(footprint.max()[bins.axis_v], bins.origin_v, bins.cells_v);
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
        const bool memory_may_hold = data.sweep.plane_had_contact[plane] != 0 && s_start_max >= -model.memory_depth_m - kPlaneSkipSlack_m;
        if (s_start_max < -contact - kPlaneSkipSlack_m && !memory_may_hold) open = false;
      }
      data.sweep.plane_open[plane] = open ? 1 : 0;
      any_open = any_open || open;
    }
    if (!any_open) continue;
    // Within an open plane, a row of cells (fixed u) is visited only over the cells whose nodes
    // may end within contact_distance of the triangle's plane (the s_end test below): the lowest
    // s_end over a cell's node box is linear in the cell's v index, so the cells it keeps are
    // one interval, solved per row and widened by one cell against the division's rounding (the
    // box is the cell's extent + kCellSlack_m, the plane's node bounds across u / the thin axis;
    // edge cells, which also hold the nodes clamped into them, are unbounded outwards). A skipped
    // cell only holds nodes with s_end > contact + kPlaneSkipSlack_m, which the node test drops:
    // the contacts are the same, only fewer nodes are read — a triangle tilted against the tool
    // does not read the nodes under the part of its box that its plane passes far above.
    const double n_u = end.normal[bins.axis_u];
    const double n_v = end.normal[bins.axis_v];
    const double n_w = end.normal[axis_w];
    const double s_end_limit = d_end + contact + kPlaneSkipSlack_m;  // keep a cell while min n·p ≤ this
    const auto cells_in_plane = static_cast<std::size_t>(bins.cells_u * bins.cells_v);
    // cv at which n_v·(the cell edge that is lowest along n_v) reaches a budget b: (b − v_offset)·v_scale
    // (low edge origin_v + cv·cell − slack for n_v > 0, high edge origin_v + (cv + 1)·cell + slack for n_v < 0).
    const double v_scale = n_v != 0.0 ? 1.0 / (n_v * bins.cell_m) : 0.0;
    const double v_offset = n_v > 0.0 ? n_v * (bins.origin_v - kCellSlack_m) : n_v * (bins.origin_v + bins.cell_m + kCellSlack_m);
    const double memory_depth = model.memory_depth_m;
    // The node test (see the header comment) for the node in plane-major slot b.
    const auto test_node = [&](int b) {
      const auto slot = static_cast<std::size_t>(b);
      const Eigen::Vector3d& p = bins.plane_cell_positions_m[slot];
      ++data.sweep.node_tests;
      const double s_end = end.normal.dot(p - end.a);
      if (s_end > contact) return;
      const int node = bins.plane_cell_nodes[slot];
      const auto n = static_cast<std::size_t>(node);
      const double s_start = start.normal.dot(p - start.a);
      const bool was_in_contact = data.sweep.node_face_prev[n] >= 0;
      if (s_start < -contact && !(was_in_contact && s_start >= -memory_depth)) return;
      const double tau = s_start > contact ? (s_start - contact) / (s_start - s_end) : 1.0;
      bool inside = false;
      Eigen::Vector3d normal_at_tau = end.normal;
      if (tau >= 1.0) {
        inside = projects_inside(end, p);
      } else {
        // The triangle at τ; its normal (a square root and a division) only once the node is inside.
        Triangle at_tau;
        if (barycentric_basis(start.a + tau * (end.a - start.a), start.b + tau * (end.b - start.b),
                              start.c + tau * (end.c - start.c), at_tau) &&
            projects_inside(at_tau, p) && unit_normal(at_tau, sign)) {
          inside = true;
          normal_at_tau = at_tau.normal;
        }
      }
      if (!inside) return;
      const bool first = data.sweep.node_face[n] < 0;
      if (first || tau < data.sweep.node_tau[n] - 1e-12) {
        if (first) data.sweep.contact_nodes.push_back(node);
        data.sweep.node_face[n] = face;
        data.sweep.node_tau[n] = tau;
        data.sweep.node_facing[n] = normals[n].dot(normal_at_tau);
      }
    };
    for (std::size_t plane = 0; plane < plane_count; ++plane) {
      if (data.sweep.plane_open[plane] == 0) continue;
      const Eigen::AlignedBox3d& plane_box = bins.plane_bounds_m[plane];
      const int* cell_begin = &bins.plane_cell_begin[plane * cells_in_plane];
      const double w_term = n_w > 0.0 ? n_w * plane_box.min()[axis_w] : n_w * plane_box.max()[axis_w];
      for (int cu = u0; cu <= u1; ++cu) {
        const int row = cu * bins.cells_v;
        if (cell_begin[row + v0] == cell_begin[row + v1 + 1]) continue;  // no node of this plane under the row
        double row_lo = std::max(plane_box.min()[bins.axis_u], cu == 0 ? -kInfinity : bins.origin_u + cu * bins.cell_m - kCellSlack_m);
        double row_hi = std::min(plane_box.max()[bins.axis_u], cu == bins.cells_u - 1 ? kInfinity : bins.origin_u + (cu + 1) * bins.cell_m + kCellSlack_m);
        if (row_lo > row_hi) {  // rounding at the plane's edge: take the plane's whole extent
          row_lo = plane_box.min()[bins.axis_u];
          row_hi = plane_box.max()[bins.axis_u];
        }
        const double u_term = n_u > 0.0 ? n_u * row_lo : n_u * row_hi;
        // Keep cell cv while u_term + w_term + (lowest n_v·v over the cell) ≤ s_end_limit.
        const double v_budget = s_end_limit - u_term - w_term;
        int first = v0;
        int last = v1;
        int edge_cell = -1;  // an edge cell outside first..last that must still be visited
        if (n_v > 0.0) {
          // Lowest n_v·v at the cell's low edge origin_v + cv·cell − slack: keep cv ≤ cv_max (+1 cell;
          // truncation is the floor here: cv_max ≥ v0 ≥ 0).
          const double cv_max = (v_budget - v_offset) * v_scale + 1.0;
          if (cv_max < static_cast<double>(v1)) last = cv_max < static_cast<double>(v0) ? v0 - 1 : static_cast<int>(cv_max);
          // Cell 0 also holds the nodes clamped into it from below (unbounded): always kept.
          if (v0 == 0 && last < 0) edge_cell = 0;
        } else if (n_v < 0.0) {
          // Lowest n_v·v at the cell's high edge origin_v + (cv + 1)·cell + slack: keep cv ≥ cv_min (−1 cell;
          // truncation is at most the ceiling: one more cell at worst).
          const double cv_min = (v_budget - v_offset) * v_scale - 1.0;
          if (cv_min > static_cast<double>(v0)) first = cv_min > static_cast<double>(v1) ? v1 + 1 : static_cast<int>(cv_min);
          // The last cell also holds the nodes clamped into it from above (unbounded): always kept.
          if (v1 == bins.cells_v - 1 && first > v1) edge_cell = v1;
        } else if (v_budget < 0.0) {
          continue;  // the plane's lowest s_end over the whole row is above the contact distance
        }
        if (edge_cell >= 0) first = last = edge_cell;
        // Cells first..last of a row: one contiguous run of this plane's nodes.
        for (int b = cell_begin[row + first]; b < cell_begin[row + last + 1]; ++b) test_node(b);
      }
    }
  }
  // Deterministic order: node index order, through a bitset of the tool nodes (linear in the tool
  // nodes / 64 plus the contacts, where sorting a deep press's hundreds of contact nodes cost ~6 %).
  for (const int node : data.sweep.contact_nodes)
    data.sweep.contact_words[static_cast<std::size_t>(node) >> 6U] |= std::uint64_t{1} << (static_cast<unsigned>(node) & 63U);
  data.sweep.contact_nodes.clear();
  for (std::size_t word = 0; word < data.sweep.contact_words.size(); ++word) {
    for (std::uint64_t bits = data.sweep.contact_words[word]; bits != 0; bits &= bits - 1)
      data.sweep.contact_nodes.push_back(static_cast<int>(64 * word) + std::countr_zero(bits));
    data.sweep.contact_words[word] = 0;
  }
  // Side memory: how many consecutive steps each node has been in contact. Kept for the nodes in
  // contact only (the pair rule reads the age of nodes in contact, and a node's count restarts at
  // 1 when it was not in contact last step), not over every tool node each step.
  for (const int node : data.sweep.contact_nodes) {
    const auto i = static_cast<std::size_t>(node);
    data.sweep.node_age[i] = data.sweep.node_face_prev[i] >= 0 ? data.sweep.node_age[i] + 1 : 1;
  }
}

}  // namespace fissure::host::thin_body
