// Crossed nodes and penetration, independent of the collision method (contact_metrics.hpp).
#include "fissure/host_sim/contact_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

namespace fissure::host {

namespace {

// 2-D convex hull (Andrew's monotone chain) of the x–z projection, counter-clockwise.
std::vector<Eigen::Vector2d> hull_2d(std::vector<Eigen::Vector2d> points) {
  std::sort(points.begin(), points.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a - o).x() * (b - o).y() - (a - o).y() * (b - o).x();
  };
  std::vector<Eigen::Vector2d> hull(2 * points.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (std::size_t i = points.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && cross(hull[k - 2], hull[k - 1], points[i - 1]) <= 0) --k;
    hull[k++] = points[i - 1];
  }
  hull.resize(k > 0 ? k - 1 : 0);
  return hull;
}

}  // namespace

ToolVolume ToolVolume::from_box(const Eigen::Vector3d& half_extents_m) {
  if (!(half_extents_m.minCoeff() > 0.0)) throw std::invalid_argument("ToolVolume::from_box: half extents must be > 0");
  ToolVolume v;
  for (int axis = 0; axis < 3; ++axis) {
    for (double sign : {1.0, -1.0}) {
      v.planes_.push_back({sign * Eigen::Vector3d::Unit(axis), half_extents_m[axis]});
    }
  }
  const double hx = half_extents_m.x(), hz = half_extents_m.z();
  v.footprint_ = {{{1, 0}, hx}, {{-1, 0}, hx}, {{0, 1}, hz}, {{0, -1}, hz}};
  v.half_thickness_m_ = half_extents_m.y();
  return v;
}

ToolVolume ToolVolume::from_convex_mesh(const std::vector<Eigen::Vector3d>& vertices_m, const std::vector<std::array<int, 3>>& triangles) {
  if (vertices_m.size() < 4 || triangles.size() < 4) throw std::invalid_argument("ToolVolume::from_convex_mesh: too few vertices/triangles");
  std::vector<std::pair<Eigen::Vector3d, double>> planes;
  for (const auto& t : triangles) {
    const Eigen::Vector3d& a = vertices_m.at(static_cast<std::size_t>(t[0]));
    const Eigen::Vector3d n = (vertices_m.at(static_cast<std::size_t>(t[1])) - a).cross(vertices_m.at(static_cast<std::size_t>(t[2])) - a);
    if (n.norm() <= 0.0) continue;
    const Eigen::Vector3d unit = n.normalized();
    planes.emplace_back(unit, unit.dot(a));
  }
  return from_planes(planes, vertices_m);
}

ToolVolume ToolVolume::from_planes(const std::vector<std::pair<Eigen::Vector3d, double>>& planes, const std::vector<Eigen::Vector3d>& vertices_m) {
  if (vertices_m.size() < 4 || planes.size() < 4) throw std::invalid_argument("ToolVolume::from_planes: too few vertices/planes");
  ToolVolume v;
  for (const auto& [normal, offset_m] : planes) v.planes_.push_back({normal, offset_m});
  std::vector<Eigen::Vector2d> projected;
  double y_lo = std::numeric_limits<double>::infinity(), y_hi = -y_lo;
  for (const Eigen::Vector3d& p : vertices_m) {
    projected.emplace_back(p.x(), p.z());
    y_lo = std::min(y_lo, p.y());
    y_hi = std::max(y_hi, p.y());
  }
  const std::vector<Eigen::Vector2d> hull = hull_2d(projected);
  for (std::size_t i = 0; i < hull.size(); ++i) {
    const Eigen::Vector2d e = hull[(i + 1) % hull.size()] - hull[i];
    const Eigen::Vector2d outward(e.y(), -e.x());  // CCW hull: right-hand normal points out
    v.footprint_.push_back({outward, outward.dot(hull[i])});
  }
  v.half_thickness_m_ = 0.5 * (y_hi - y_lo);
  return v;
}

double ToolVolume::signed_distance_m(const Eigen::Vector3d& p_tool) const noexcept {
  double d = -std::numeric_limits<double>::infinity();
  for (const Plane& plane : planes_) d = std::max(d, plane.normal.dot(p_tool) - plane.offset_m);
  return d;
}

bool ToolVolume::reaches_inside(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, double depth_tolerance_m,
                                std::vector<Eigen::Vector3d>& scratch) const {
  // The polygon left after each clip is kept in the first half of `scratch`, the next one is
  // built in the second half; a convex polygon clipped by a plane gains at most one vertex.
  const std::size_t capacity = 3 + planes_.size();
  scratch.resize(2 * capacity);
  std::size_t count = 3;
  scratch[0] = a;
  scratch[1] = b;
  scratch[2] = c;
  for (const Plane& plane : planes_) {
    const double offset = plane.offset_m - depth_tolerance_m;
    std::size_t next = 0;
    for (std::size_t k = 0; k < count; ++k) {
      const Eigen::Vector3d& p = scratch[k];
      const Eigen::Vector3d& q = scratch[(k + 1) % count];
      const double fp = plane.normal.dot(p) - offset;  // < 0: inside
      const double fq = plane.normal.dot(q) - offset;
      if (fp < 0.0) scratch[capacity + next++] = p;
      if ((fp < 0.0) != (fq < 0.0)) scratch[capacity + next++] = p + (fp / (fp - fq)) * (q - p);
    }
    if (next == 0) return false;
    for (std::size_t k = 0; k < next; ++k) scratch[k] = scratch[capacity + k];
    count = next;
  }
  return true;
}

int triangles_cut_by_volume(const ToolVolume& volume, const std::vector<Eigen::Vector3d>& soft_nodes_world_m,
                            const std::vector<std::array<int, 3>>& faces, const Eigen::Isometry3d& tool_to_world,
                            double depth_tolerance_m) {
  const Eigen::Isometry3d world_to_tool = tool_to_world.inverse();
  std::vector<Eigen::Vector3d> scratch;
  int cut = 0;
  for (const std::array<int, 3>& face : faces) {
    const auto corner = [&](std::size_t k) { return Eigen::Vector3d(world_to_tool * soft_nodes_world_m[static_cast<std::size_t>(face[k])]); };
    if (volume.reaches_inside(corner(0), corner(1), corner(2), depth_tolerance_m, scratch)) ++cut;
  }
  return cut;
}

bool ToolVolume::in_footprint(const Eigen::Vector3d& p_tool) const noexcept {
  const Eigen::Vector2d q(p_tool.x(), p_tool.z());
  for (const Edge2d& e : footprint_) {
    if (e.a.dot(q) > e.b) return false;
  }
  return true;
}

CrossingTracker::CrossingTracker(ToolVolume volume, int soft_node_count)
    : volume_(std::move(volume)),
      side_(static_cast<std::size_t>(soft_node_count), 0),
      endpoint_side_(static_cast<std::size_t>(soft_node_count), 0),
      previous_tool_m_(static_cast<std::size_t>(soft_node_count), Eigen::Vector3d::Zero()) {}

void CrossingTracker::reset(const std::vector<Eigen::Vector3d>& soft_nodes_world_m, const Eigen::Isometry3d& tool_to_world) noexcept {
  const Eigen::Isometry3d world_to_tool = tool_to_world.inverse();
  const std::size_t n = std::min(side_.size(), soft_nodes_world_m.size());
  for (std::size_t i = 0; i < n; ++i) {
    previous_tool_m_[i] = world_to_tool * soft_nodes_world_m[i];
    const double y = previous_tool_m_[i].y();
    side_[i] = y > 0.0 ? 1 : (y < 0.0 ? -1 : 0);
    endpoint_side_[i] = side_[i];
  }
}

namespace {

enum class MidPlanePass : std::uint8_t { kNone, kRoundTheRim, kThroughTheTool };

// Where the straight relative path a → b (tool frame) crosses the mid-plane y = 0: outside the
// tool (round the rim; on a side face counts as outside, as for a node held there) or inside it.
MidPlanePass mid_plane_pass(const ToolVolume& volume, const Eigen::Vector3d& a, const Eigen::Vector3d& b) noexcept {
  if (!(a.y() * b.y() < 0.0)) return MidPlanePass::kNone;
  const double s = a.y() / (a.y() - b.y());
  const Eigen::Vector3d c = a + s * (b - a);
  return volume.signed_distance_m(c) < -kInsideToleranceM ? MidPlanePass::kThroughTheTool : MidPlanePass::kRoundTheRim;
}

// The end-point side memory: inside the footprint it is frozen and a node on the other side
// of the mid-plane went through (returns true); outside it follows the node (it may go round
// the rim). A node first seen exactly on the mid-plane takes the side it is next seen on.
bool follow_side(std::int8_t& memory, std::int8_t side_now, bool in_footprint) noexcept {
  if (!in_footprint) {
    if (side_now != 0) memory = side_now;
    return false;
  }
  if (memory == 0) memory = side_now;
  return side_now != 0 && side_now != memory;
}

}  // namespace

CrossingSnapshot CrossingTracker::update(const std::vector<Eigen::Vector3d>& soft_nodes_world_m, const Eigen::Isometry3d& tool_to_world) noexcept {
  CrossingSnapshot snap;
  const Eigen::Isometry3d world_to_tool = tool_to_world.inverse();
  const std::size_t n = std::min(side_.size(), soft_nodes_world_m.size());
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d p = world_to_tool * soft_nodes_world_m[i];
    const std::int8_t side_now = p.y() > 0.0 ? 1 : (p.y() < 0.0 ? -1 : 0);
    const double penetration_m = std::max(0.0, -volume_.signed_distance_m(p));
    snap.max_penetration_m = std::max(snap.max_penetration_m, penetration_m);
    const bool inside = penetration_m > kInsideToleranceM;
    // Beside the rim: outside the tool but within its thickness band. The footprint's edge and
    // the tool's side face are the same line, so a node held on a side face (the paired method
    // leaves it skin_m outside) projects onto the footprint's edge within rounding and may
    // slide past the mid-plane along the face — that is going round the rim, not through.
    const bool beside_rim = !inside && penetration_m == 0.0 && std::abs(p.y()) < volume_.half_thickness_m();
    const bool in_footprint = volume_.in_footprint(p) && !beside_rim;
    // The end-point-only rule, kept as a comparison figure.
    const bool endpoint_wrong_side = follow_side(endpoint_side_[i], side_now, in_footprint);
    snap.endpoint_crossed_nodes += (endpoint_wrong_side || inside) ? 1 : 0;
    // The path since the last update: round the rim → the memory follows to the new side;
    // through the tool → crossed, even if the node ended beyond the rim.
    const MidPlanePass pass = mid_plane_pass(volume_, previous_tool_m_[i], p);
    previous_tool_m_[i] = p;
    const bool through = pass == MidPlanePass::kThroughTheTool;
    if (pass == MidPlanePass::kRoundTheRim && side_now != side_[i]) {
      side_[i] = side_now;
      ++snap.rim_passes;
    }
    const bool wrong_side = follow_side(side_[i], side_now, in_footprint);
    snap.wrong_side_nodes += wrong_side ? 1 : 0;
    snap.through_nodes += through ? 1 : 0;
    snap.inside_nodes += inside ? 1 : 0;
    snap.crossed_nodes += (wrong_side || through || inside) ? 1 : 0;
  }
  return snap;
}

}  // namespace fissure::host
