#pragma once
// Method-independent contact metrics (BRIEF §9): crossed nodes and penetration into the
// tool, measured from the soft nodes' positions and the tool's own geometry (built here
// from the scene, NOT from the collision method's node model), so that every method is
// judged by the same ruler.
//
// Definitions (tool frame; the thin axis is local y, the mid-plane is y = 0):
// * footprint: the tool's silhouette seen along the thin axis (convex polygon in x–z).
// * side memory: each soft node remembers the side of the mid-plane it is on (sign of
//   y_tool). The memory follows the node freely while it is OUTSIDE the footprint (it may
//   go around the rim); inside the footprint it is frozen — except beside the rim (outside
//   the tool, |y_tool| < half thickness: a node on a side face), where it also follows.
//   The memory also follows the PATH between two updates: the node's straight relative path
//   (tool frame, from where it was at the last update to where it is now — the relative motion
//   the collision methods sweep) that crosses the mid-plane outside the tool went round the
//   rim, whatever the end point. Without this, a node the tool's rim passes within one update
//   (a tool teleport after dropped device replies: the spatula jumped 24 mm sideways in one
//   1 ms step; a node's relative path crossed the mid-plane 5.1 mm beside its rim) was read as crossed when it ended under
//   the footprint; and a node that went through the tool and out beyond its rim within one
//   update was missed.
// * wrong side: the node is inside the footprint and on the other side of the mid-plane
//   than it remembers — it went through the tool.
// * through: the node's relative path since the last update crossed the mid-plane inside the
//   tool (deeper than kInsideToleranceM) — it went through the tool, wherever it ended.
// * inside: the node lies inside the tool volume deeper than kInsideToleranceM.
// * crossed = wrong side OR through OR inside (a node counts once). Target: 0 (issue 5).
// * endpoint_crossed (kept for comparison): the same count with an end-point-only
//   side memory (no path test), which misreads a rim pass within one update as crossed.
// * penetration: max(0, −signed distance to the tool volume); the max over nodes.
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace fissure::host {

/// A node deeper than this inside the tool counts as crossed. 0.1 mm is issue 5's target
/// for the maximum penetration, so a node beyond it has failed the target outright.
inline constexpr double kInsideToleranceM = 1e-4;

/// The tool's convex volume for measurement, tool frame. Thin axis = local y.
class ToolVolume {
 public:
  /// A box centred on the origin with these half extents (y the thinnest).
  static ToolVolume from_box(const Eigen::Vector3d& half_extents_m);
  /// A closed convex mesh (outward winding); planes are its triangles' planes.
  static ToolVolume from_convex_mesh(const std::vector<Eigen::Vector3d>& vertices_m, const std::vector<std::array<int, 3>>& triangles);
  /// A convex tool given by its face planes (outward unit normal, offset: n·p ≤ offset inside) and
  /// its vertices (for the silhouette and the thickness), e.g. a ToolNodes' planes and hull.
  static ToolVolume from_planes(const std::vector<std::pair<Eigen::Vector3d, double>>& planes, const std::vector<Eigen::Vector3d>& vertices_m);

  /// max over planes of (n·p − d): exact depth (negative) inside, a lower bound outside.
  [[nodiscard]] double signed_distance_m(const Eigen::Vector3d& p_tool) const noexcept;
  /// Whether some point of the triangle a, b, c (tool frame) lies deeper than depth_tolerance_m
  /// inside (signed_distance_m < −tolerance): exact, by clipping the triangle against every plane
  /// moved inward by the tolerance (Sutherland–Hodgman) — sampling would miss a 1 mm blade
  /// between the samples of a 21 mm triangle. `scratch` is reused between calls.
  [[nodiscard]] bool reaches_inside(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c, double depth_tolerance_m,
                                    std::vector<Eigen::Vector3d>& scratch) const;
  /// Whether p_tool's projection along y falls inside the tool's silhouette.
  [[nodiscard]] bool in_footprint(const Eigen::Vector3d& p_tool) const noexcept;
  [[nodiscard]] double half_thickness_m() const noexcept { return half_thickness_m_; }

 private:
  struct Plane {
    Eigen::Vector3d normal;
    double offset_m;
  };
  struct Edge2d {  // a·(x, z) ≤ b inside
    Eigen::Vector2d a;
    double b;
  };
  std::vector<Plane> planes_;
  std::vector<Edge2d> footprint_;
  double half_thickness_m_ = 0.0;
};

/// How many soft triangles (world node positions, index triples) reach deeper than
/// depth_tolerance_m into the tool (ToolVolume::reaches_inside). A thin tool that slices a coarse
/// triangle between its nodes leaves every node outside and the triangle's interior inside: the
/// node-based crossed count cannot see that, this can. A diagnostic (faces × planes² work and a
/// scratch allocation), not a per-step metric.
[[nodiscard]] int triangles_cut_by_volume(const ToolVolume& volume, const std::vector<Eigen::Vector3d>& soft_nodes_world_m,
                                          const std::vector<std::array<int, 3>>& faces, const Eigen::Isometry3d& tool_to_world,
                                          double depth_tolerance_m);

/// What the metrics saw after one step, for one tool part (a jaw, or the whole spatula).
struct CrossingSnapshot {
  int crossed_nodes = 0;       ///< wrong side ∪ inside (see above)
  int wrong_side_nodes = 0;
  int inside_nodes = 0;
  int through_nodes = 0;            ///< relative path crossed the mid-plane inside the tool since the last update
  int rim_passes = 0;               ///< changed side by passing the rim (outside the tool) within one update
  int endpoint_crossed_nodes = 0;   ///< the end-point-only rule's crossed count (comparison only)
  double max_penetration_m = 0.0;
};

/// Mutable per-node side memory for one rigid tool part; preallocated for the soft body's
/// node count, then update() each step (no allocation).
class CrossingTracker {
 public:
  CrossingTracker(ToolVolume volume, int soft_node_count);

  /// Sets every node's side from its current position (call once before the tool moves in).
  void reset(const std::vector<Eigen::Vector3d>& soft_nodes_world_m, const Eigen::Isometry3d& tool_to_world) noexcept;
  /// Measures the nodes against the tool's current pose and updates the side memory.
  CrossingSnapshot update(const std::vector<Eigen::Vector3d>& soft_nodes_world_m, const Eigen::Isometry3d& tool_to_world) noexcept;

  [[nodiscard]] const ToolVolume& volume() const noexcept { return volume_; }
  /// Per node: +1 / −1 remembered side, 0 not yet known (exactly on the mid-plane).
  [[nodiscard]] const std::vector<std::int8_t>& sides() const noexcept { return side_; }

 private:
  ToolVolume volume_;
  std::vector<std::int8_t> side_;
  std::vector<std::int8_t> endpoint_side_;          // the end-point-only rule's memory (comparison only)
  std::vector<Eigen::Vector3d> previous_tool_m_;    // each node at the last update, tool frame
};

}  // namespace fissure::host
