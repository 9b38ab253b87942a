// ToolNodes: node placement and pairing at load (BRIEF §3 item 1; paper "Extension of the
// algorithm to convex thin bodies").
#include <fissure/host_sim/thin_tool.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "fissure/host_sim/mesh_bvh.hpp"

namespace fissure::host {
namespace {

// Relative tolerance for "coplanar" when merging mesh triangles into tool planes and checking
// convexity: meshes come from float OBJ files, so 1e-6 of the tool size.
constexpr double kPlaneTolerance_relative = 1e-6;
// A mesh triangle whose normal is more than 60° off the thin axis is on the rim (an edge node):
// the flat faces are at 0°, the half-circle rim profile spreads from 0° to 90°.
constexpr double kEdgeNormalCosine = 0.5;

int other_axis_u(int thin_axis) { return thin_axis == 0 ? 1 : 0; }
int other_axis_v(int thin_axis) { return thin_axis == 2 ? 1 : 2; }

// 2-D convex hull (Andrew's monotone chain), counter-clockwise.
std::vector<Eigen::Vector2d> convex_hull_2d(std::vector<Eigen::Vector2d> points) {
  std::sort(points.begin(), points.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  if (points.size() < 3) return points;
  std::vector<Eigen::Vector2d> hull(2 * points.size());
  const auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  std::size_t k = 0;
  for (const auto& p : points) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], p) <= 0) --k;
    hull[k++] = p;
  }
  for (std::size_t i = points.size() - 1, t = k + 1; i > 0; --i) {
    const auto& p = points[i - 1];
    while (k >= t && cross(hull[k - 2], hull[k - 1], p) <= 0) --k;
    hull[k++] = p;
  }
  hull.resize(k - 1);
  return hull;
}

}  // namespace

ToolNodes ToolNodes::from_box(const BoxToolShape& shape) {
  if (shape.thin_axis < 0 || shape.thin_axis > 2)
    throw std::invalid_argument("box tool: thin_axis must be 0, 1 or 2, got " + std::to_string(shape.thin_axis));
  if (!(shape.half_extents_m.array() > 0.0).all() || !shape.half_extents_m.allFinite())
    throw std::invalid_argument("box tool: half_extents_m must be finite and > 0");
  if (shape.nodes_u < 1 || shape.nodes_v < 1)
    throw std::invalid_argument("box tool: nodes_u and nodes_v must be >= 1");
  ToolNodes tool;
  const int w = shape.thin_axis;
  const int u = other_axis_u(w);
  const int v = other_axis_v(w);
  const Eigen::Vector3d& h = shape.half_extents_m;
  for (int axis = 0; axis < 3; ++axis) {
    for (const double sign : {1.0, -1.0}) {
      ToolPlane plane;
      plane.normal_tool = sign * Eigen::Vector3d::Unit(axis);
      plane.offset_m = h[axis];
      tool.planes_.push_back(plane);
    }
  }
  const int per_face = shape.nodes_u * shape.nodes_v;
  // Grid including the face's edges, so that soft triangles straddling the rim are still swept by
  // a node (the face interior between nodes is covered by the soft-node guard of the response).
  const auto grid = [](int count, int index, double half) {
    return count == 1 ? 0.0 : -half + 2.0 * half * static_cast<double>(index) / static_cast<double>(count - 1);
  };
  for (const double sign : {1.0, -1.0}) {
    for (int iu = 0; iu < shape.nodes_u; ++iu) {
      for (int iv = 0; iv < shape.nodes_v; ++iv) {
        Eigen::Vector3d p = Eigen::Vector3d::Zero();
        p[w] = sign * h[w];
        p[u] = grid(shape.nodes_u, iu, h[u]);
        p[v] = grid(shape.nodes_v, iv, h[v]);
        tool.positions_tool_m_.push_back(p);
        tool.normals_tool_.push_back(sign * Eigen::Vector3d::Unit(w));
        tool.plane_of_node_.push_back(2 * w + (sign > 0 ? 0 : 1));
      }
    }
  }
  tool.pair_of_.resize(static_cast<std::size_t>(2 * per_face));
  for (int i = 0; i < per_face; ++i) {
    tool.pair_of_[static_cast<std::size_t>(i)] = i + per_face;
    tool.pair_of_[static_cast<std::size_t>(i + per_face)] = i;
  }
  tool.edge_node_.assign(static_cast<std::size_t>(2 * per_face), 0);
  if (shape.edge_nodes) {
    // Side faces: normal ±u (long direction v, nodes_v nodes) and ±v (long direction u, nodes_u),
    // one row in the middle of the thickness. A side face is thinner than the face-grid spacing of
    // any tool this is used for, so one row across it is enough to meet a soft triangle the rim
    // pushes into; a soft NODE meeting the rim between rows is the guard's job (as on the faces).
    // Unpaired: the node opposite an edge node along its normal is on the far rim, a tool length
    // away — pairing across the length is exactly the pairing across the edge that the paper's
    // limited ray forbids, and both rims can legitimately touch the soft body at once (a tool
    // buried in a fissure), so an exclusion between them would drop a real contact.
    for (const int side_axis : {u, v}) {
      const int along = side_axis == u ? v : u;
      const int count = side_axis == u ? shape.nodes_v : shape.nodes_u;
      for (const double sign : {1.0, -1.0}) {
        for (int k = 0; k < count; ++k) {
          Eigen::Vector3d p = Eigen::Vector3d::Zero();
          p[side_axis] = sign * h[side_axis];
          p[along] = grid(count, k, h[along]);
          tool.positions_tool_m_.push_back(p);
          tool.normals_tool_.push_back(sign * Eigen::Vector3d::Unit(side_axis));
          tool.plane_of_node_.push_back(2 * side_axis + (sign > 0 ? 0 : 1));
          tool.pair_of_.push_back(-1);
          tool.edge_node_.push_back(1);
        }
      }
    }
  }
  for (int corner = 0; corner < 8; ++corner) {
    tool.hull_vertices_tool_m_.emplace_back((corner & 1) ? h.x() : -h.x(), (corner & 2) ? h.y() : -h.y(),
                                            (corner & 4) ? h.z() : -h.z());
  }
  // The 12 box edges: corner pairs differing in one coordinate bit.
  for (int corner = 0; corner < 8; ++corner) {
    for (int bit = 1; bit < 8; bit <<= 1) {
      if ((corner & bit) != 0) continue;
      tool.feature_edges_tool_m_.push_back({tool.hull_vertices_tool_m_[static_cast<std::size_t>(corner)],
                                            tool.hull_vertices_tool_m_[static_cast<std::size_t>(corner | bit)]});
    }
  }
  tool.thin_axis_ = w;
  tool.thickness_m_ = 2.0 * h[w];
  tool.finish_pairing();
  tool.thin_ = true;  // a box tool is the paper's spatula: always paired
  return tool;
}

ToolNodes ToolNodes::from_convex_mesh(const ConvexMeshToolShape& shape) {
  const auto& verts = shape.vertices_tool_m;
  if (verts.size() < 4 || shape.triangles.size() < 4)
    throw std::invalid_argument("convex tool mesh: needs at least 4 vertices and 4 triangles");
  for (const auto& p : verts)
    if (!p.allFinite()) throw std::invalid_argument("convex tool mesh: non-finite vertex");
  if (!std::isfinite(shape.pairing_ray_limit_m))
    throw std::invalid_argument("convex tool mesh: pairing_ray_limit_m must be finite");
  ToolNodes tool;
  for (const auto& p : verts) tool.bounds_tool_m_.extend(p);
  const double size_m = tool.bounds_tool_m_.diagonal().norm();
  const double tol_m = kPlaneTolerance_relative * size_m;

  // Signed volume decides the winding (outward normals wanted).
  double volume6 = 0.0;
  for (const auto& t : shape.triangles) {
    for (const int index : t)
      if (index < 0 || index >= static_cast<int>(verts.size()))
        throw std::invalid_argument("convex tool mesh: triangle index " + std::to_string(index) + " out of range");
    volume6 += verts[static_cast<std::size_t>(t[0])].dot(
        verts[static_cast<std::size_t>(t[1])].cross(verts[static_cast<std::size_t>(t[2])]));
  }
  if (std::abs(volume6) <= 1e-12 * size_m * size_m * size_m)
    throw std::invalid_argument("convex tool mesh: zero volume (open or flat mesh)");
  const double winding = volume6 > 0.0 ? 1.0 : -1.0;

  std::vector<Eigen::Vector3d> tri_normal;
  std::vector<Eigen::Vector3d> tri_a, tri_b, tri_c;
  for (const auto& t : shape.triangles) {
    const Eigen::Vector3d& a = verts[static_cast<std::size_t>(t[0])];
    const Eigen::Vector3d& b = verts[static_cast<std::size_t>(t[1])];
    const Eigen::Vector3d& c = verts[static_cast<std::size_t>(t[2])];
    const Eigen::Vector3d n = winding * (b - a).cross(c - a);
    if (n.norm() <= 1e-12 * size_m * size_m)
      throw std::invalid_argument("convex tool mesh: degenerate (zero-area) triangle");
    tri_normal.push_back(n.normalized());
    tri_a.push_back(a);
    tri_b.push_back(b);
    tri_c.push_back(c);
  }
  // Convexity: no vertex beyond any triangle's plane by more than tol_m (a box tree over the
  // vertices answers each triangle in ~log n instead of a scan of every vertex).
  const VertexTree vertex_tree(verts);
  for (std::size_t f = 0; f < tri_normal.size(); ++f) {
    const double offset = tri_normal[f].dot(tri_a[f]);
    const Eigen::Vector3d& n = tri_normal[f];
    if (vertex_tree.find_beyond(n, offset + tol_m, [&](const Eigen::Vector3d& p) { return n.dot(p) - offset > tol_m; }) >= 0)
      throw std::invalid_argument("convex tool mesh: not convex (a vertex lies outside triangle " + std::to_string(f) + "'s plane)");
  }
  // Planes: merge coplanar triangles (a flat face is one plane) — each triangle takes the FIRST
  // plane (in creation order) whose normal is within 1 − 1e-9 in cosine and whose offset is
  // within tol_m. Planes are hashed on a grid of (normal, offset) cells at least as wide as
  // those tolerances, so every plane that can match lies in the 3^4 cells around the triangle's.
  struct CellHash {
    std::size_t operator()(const std::array<std::int64_t, 4>& k) const noexcept {
      std::size_t h = 0;
      for (const std::int64_t c : k) h = h * 0x9E3779B97F4A7C15ULL ^ static_cast<std::size_t>(c);
      return h;
    }
  };
  // |n − m| < 4.5e-5 when n·m > 1 − 1e-9 (unit normals): a 5e-5 cell per normal component.
  constexpr double kNormalCell = 5e-5;
  const double offset_cell = std::max(tol_m, std::numeric_limits<double>::min());
  const auto cell_of = [&](const Eigen::Vector3d& n, double offset) {
    return std::array<std::int64_t, 4>{static_cast<std::int64_t>(std::floor(n.x() / kNormalCell)), static_cast<std::int64_t>(std::floor(n.y() / kNormalCell)),
                                       static_cast<std::int64_t>(std::floor(n.z() / kNormalCell)), static_cast<std::int64_t>(std::floor(offset / offset_cell))};
  };
  std::unordered_map<std::array<std::int64_t, 4>, std::vector<int>, CellHash> plane_cells;
  for (std::size_t f = 0; f < tri_normal.size(); ++f) {
    const double offset = tri_normal[f].dot(tri_a[f]);
    const std::array<std::int64_t, 4> cell = cell_of(tri_normal[f], offset);
    int plane_index = -1;
    for (int d = 0; d < 81; ++d) {
      std::array<std::int64_t, 4> near = cell;
      for (int k = 0, code = d; k < 4; ++k, code /= 3) near[static_cast<std::size_t>(k)] += code % 3 - 1;
      const auto it = plane_cells.find(near);
      if (it == plane_cells.end()) continue;
      for (const int q : it->second) {
        if ((plane_index < 0 || q < plane_index) && tool.planes_[static_cast<std::size_t>(q)].normal_tool.dot(tri_normal[f]) > 1.0 - 1e-9 &&
            std::abs(tool.planes_[static_cast<std::size_t>(q)].offset_m - offset) <= tol_m)
          plane_index = q;
      }
    }
    if (plane_index < 0) {
      plane_index = static_cast<int>(tool.planes_.size());
      tool.planes_.push_back(ToolPlane{tri_normal[f], offset});
      plane_cells[cell].push_back(plane_index);
    }
    tool.positions_tool_m_.push_back((tri_a[f] + tri_b[f] + tri_c[f]) / 3.0);
    tool.normals_tool_.push_back(tri_normal[f]);
    tool.plane_of_node_.push_back(plane_index);
  }
  // Pairing: a ray from each centroid opposite to its normal, limited to pairing_ray_limit_m;
  // the nearest other triangle hit gives the pair (paper Fig. 2: the limit stops rim nodes
  // pairing across the edge). A box tree over the triangles visits only those near the ray.
  const std::size_t count = tri_normal.size();
  tool.pair_of_.assign(count, -1);
  if (shape.pairing_ray_limit_m > 0.0) {
    const double t_min = tol_m;  // skip the node's own plane (and coplanar neighbours)
    const TriangleTree triangle_tree(tri_a, tri_b, tri_c);
    for (std::size_t i = 0; i < count; ++i) {
      tool.pair_of_[i] = triangle_tree.first_hit(tool.positions_tool_m_[i], -tri_normal[i], t_min, shape.pairing_ray_limit_m, static_cast<int>(i));
    }
  }
  tool.hull_vertices_tool_m_ = verts;
  // Feature edges: a triangle edge whose two triangles lie on different planes (one hash lookup
  // per triangle edge: linear in the mesh).
  {
    struct EdgeHash {
      std::size_t operator()(std::uint64_t key) const noexcept { return std::hash<std::uint64_t>{}(key * 0x9E3779B97F4A7C15ULL); }
    };
    std::unordered_map<std::uint64_t, int, EdgeHash> first_plane_of_edge;
    first_plane_of_edge.reserve(3 * shape.triangles.size());
    for (std::size_t f = 0; f < shape.triangles.size(); ++f) {
      for (int k = 0; k < 3; ++k) {
        const auto a = static_cast<std::uint32_t>(shape.triangles[f][static_cast<std::size_t>(k)]);
        const auto b = static_cast<std::uint32_t>(shape.triangles[f][static_cast<std::size_t>((k + 1) % 3)]);
        const std::uint64_t key = (static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b);
        const auto [it, inserted] = first_plane_of_edge.emplace(key, tool.plane_of_node_[f]);
        if (!inserted && it->second != tool.plane_of_node_[f]) tool.feature_edges_tool_m_.push_back({verts[a], verts[b]});
      }
    }
  }
  const Eigen::Vector3d extent = tool.bounds_tool_m_.sizes();
  extent.minCoeff(&tool.thin_axis_);
  tool.thickness_m_ = extent[tool.thin_axis_];
  // Rim triangles: normal more than 60° off the thin axis (|n_thin| < cos 60°).
  tool.edge_node_.assign(count, 0);
  for (std::size_t i = 0; i < count; ++i)
    tool.edge_node_[i] = std::abs(tri_normal[i][tool.thin_axis_]) < kEdgeNormalCosine ? 1 : 0;
  tool.finish_pairing();
  tool.thin_ = shape.pairing_ray_limit_m > 0.0 && tool.report_.mutual + tool.report_.one_way > 0;
  return tool;
}

namespace {

// Median split along the longest side of the midpoints' box, leaves of up to kLeafEdges edges:
// balanced, so the depth is log2(edges / kLeafEdges) + 1.
constexpr int kLeafEdges = 4;

void build_ball(const std::vector<Eigen::Vector3d>& midpoints, const std::vector<double>& half_lengths, std::vector<int>& order,
                std::vector<ToolNodes::FeatureEdgeBall>& balls, std::size_t ball, int begin, int end, int depth) {
  if (depth > ToolNodes::kFeatureEdgeBallDepth) throw std::invalid_argument("tool mesh: too many feature edges for the rim's ball tree");
  Eigen::AlignedBox3d box;
  for (int i = begin; i < end; ++i) box.extend(midpoints[static_cast<std::size_t>(order[static_cast<std::size_t>(i)])]);
  const Eigen::Vector3d centre = box.center();
  double radius_m = 0.0;
  for (int i = begin; i < end; ++i) {
    const auto e = static_cast<std::size_t>(order[static_cast<std::size_t>(i)]);
    radius_m = std::max(radius_m, (midpoints[e] - centre).norm() + half_lengths[e]);
  }
  balls[ball] = ToolNodes::FeatureEdgeBall{centre, radius_m, -1, begin, end};
  if (end - begin <= kLeafEdges) return;
  int axis = 0;
  box.sizes().maxCoeff(&axis);
  const int middle = begin + (end - begin) / 2;
  std::nth_element(order.begin() + begin, order.begin() + middle, order.begin() + end, [&](int a, int b) {
    return midpoints[static_cast<std::size_t>(a)][axis] < midpoints[static_cast<std::size_t>(b)][axis];
  });
  const std::size_t child = balls.size();
  balls.resize(child + 2);
  balls[ball].first_child = static_cast<int>(child);
  build_ball(midpoints, half_lengths, order, balls, child, begin, middle, depth + 1);
  build_ball(midpoints, half_lengths, order, balls, child + 1, middle, end, depth + 1);
}

void build_feature_edge_balls(const std::vector<Eigen::Vector3d>& midpoints, const std::vector<double>& half_lengths, std::vector<int>& order,
                              std::vector<ToolNodes::FeatureEdgeBall>& balls) {
  order.resize(midpoints.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  balls.clear();
  if (order.empty()) return;
  balls.resize(1);
  build_ball(midpoints, half_lengths, order, balls, 0, 0, static_cast<int>(order.size()), 1);
}

}  // namespace

void ToolNodes::finish_pairing() {
  feature_edge_midpoints_tool_m_.clear();
  feature_edge_half_lengths_m_.clear();
  for (const auto& edge : feature_edges_tool_m_) {
    feature_edge_midpoints_tool_m_.push_back(0.5 * (edge[0] + edge[1]));
    feature_edge_half_lengths_m_.push_back(0.5 * (edge[1] - edge[0]).norm());
  }
  build_feature_edge_balls(feature_edge_midpoints_tool_m_, feature_edge_half_lengths_m_, feature_edge_ball_order_, feature_edge_balls_);
  const int count = node_count();
  paired_by_begin_.assign(static_cast<std::size_t>(count + 1), 0);
  for (const int pair : pair_of_)
    if (pair >= 0) ++paired_by_begin_[static_cast<std::size_t>(pair + 1)];
  for (int i = 0; i < count; ++i)
    paired_by_begin_[static_cast<std::size_t>(i + 1)] += paired_by_begin_[static_cast<std::size_t>(i)];
  paired_by_nodes_.assign(static_cast<std::size_t>(paired_by_begin_.back()), -1);
  std::vector<int> fill(paired_by_begin_.begin(), paired_by_begin_.end() - 1);
  for (int i = 0; i < count; ++i) {
    const int pair = pair_of_[static_cast<std::size_t>(i)];
    if (pair >= 0) paired_by_nodes_[static_cast<std::size_t>(fill[static_cast<std::size_t>(pair)]++)] = i;
  }
  report_ = PairingReport{};
  for (int i = 0; i < count; ++i) {
    const int pair = pair_of_[static_cast<std::size_t>(i)];
    if (pair < 0) {
      ++report_.unpaired;
    } else if (pair_of_[static_cast<std::size_t>(pair)] == i) {
      ++report_.mutual;
    } else {
      ++report_.one_way;
    }
  }
  bounds_tool_m_.setEmpty();
  for (const auto& p : hull_vertices_tool_m_) bounds_tool_m_.extend(p);
  // Footprint seen along the thin axis.
  const int u = other_axis_u(thin_axis_);
  const int v = other_axis_v(thin_axis_);
  std::vector<Eigen::Vector2d> projected;
  for (const auto& p : hull_vertices_tool_m_) projected.emplace_back(p[u], p[v]);
  const auto hull = convex_hull_2d(projected);
  footprint_halfplanes_.clear();
  for (std::size_t i = 0; i < hull.size(); ++i) {
    const Eigen::Vector2d& a = hull[i];
    const Eigen::Vector2d& b = hull[(i + 1) % hull.size()];
    const Eigen::Vector2d edge = b - a;
    const Eigen::Vector2d outward(edge.y(), -edge.x());  // CCW hull: right-hand normal points out
    const Eigen::Vector2d n = outward.normalized();
    footprint_halfplanes_.emplace_back(n.x(), n.y(), n.dot(a));
  }
}

int ToolNodes::edge_node_count() const {
  return static_cast<int>(std::count(edge_node_.begin(), edge_node_.end(), std::uint8_t{1}));
}

double ToolNodes::signed_distance_m(const Eigen::Vector3d& p_tool) const {
  double distance = -std::numeric_limits<double>::infinity();
  for (const auto& plane : planes_) distance = std::max(distance, plane.normal_tool.dot(p_tool) - plane.offset_m);
  return distance;
}

bool ToolNodes::in_footprint(const Eigen::Vector3d& p_tool) const {
  const double pu = p_tool[other_axis_u(thin_axis_)];
  const double pv = p_tool[other_axis_v(thin_axis_)];
  for (const auto& h : footprint_halfplanes_)
    if (h.x() * pu + h.y() * pv > h.z()) return false;
  return !footprint_halfplanes_.empty();
}

}  // namespace fissure::host
