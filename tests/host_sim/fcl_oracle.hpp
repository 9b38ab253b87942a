#pragma once
// An independent oracle for the contact metrics' "cut triangle" and "node inside the tool"
// (host_sim/contact_metrics.hpp), as MuJoCo tests its special colliders against a general one:
// the same questions answered by general-purpose libraries, not by the project's own clip.
//
// The project's definition (ToolVolume::reaches_inside): a soft triangle is cut when some point
// of it lies deeper than the tolerance t inside the tool, depth = min over the tool's planes of
// (offset − n·p) — for a point inside a convex polytope that is exactly its distance to the
// boundary. "Some point deeper than t" is "the triangle meets the tool shrunk by t" (every face
// moved inward by t), so the oracle asks exactly that:
//   * the shrunk tool: the convex hull of the tool's own vertices (Bullet's btConvexHullComputer)
//     with every face moved t inward, its vertices solved in double precision from the planes
//     that meet at each (found through the dual hull) — the tool's volume from its vertices, not
//     from the project's plane list;
//   * the test: FCL's mesh–convex collision (fcl::collide of a BVHModel<AABB> of the soft
//     triangles against an fcl::Convex of the shrunk hull, boolean, every colliding triangle
//     reported; libccd's MPR for each triangle–convex pair); a node is inside when an
//     fcl::Sphere of kNodeRadiusM at it collides with the shrunk hull.
// Why not FCL's penetration depth against the unshrunk tool (collide with enable_contact, or
// signed distance): that depth is the minimum translation that separates the triangle from the
// tool. It is ≥ the project's depth (a shorter shift leaves the deepest point inside) and can be
// much larger: a triangle slicing through a 1 mm blade reaches 0.5 mm deep at most, but must move
// by about its own size to get clear; across a box edge the ratio is √2. It answers another question.
//
// Agreement is exact up to the precision of the two tools' definitions and of FCL: the hull of a
// mesh's vertices and the intersection of its triangles' planes differ by up to 0.21 µm on the
// rounded spatula (Bullet merges near-coplanar faces); MPR stops at kMprToleranceM. A triangle
// whose deepest point lies within a fraction of a micrometre of t may fall either way, so every comparison carries a depth
// margin (kAgreementMarginM): the oracle is also asked at t − margin and t + margin, and a
// project answer is accepted when it lies between the two:
//   cut by the oracle at t + margin  ⇒  cut by the project at t  ⇒  cut by the oracle at t − margin.
// Test-only (tests/host_sim); nothing of the product links it.
#include <array>
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace fissure::host::test_oracle {

/// The depth margin of an accepted disagreement [m]: 1 % of the 0.1 mm tolerance, about five
/// times the two definitions' difference (see above), far below the cuts that matter (0.1–2 mm).
inline constexpr double kAgreementMarginM = 1e-6;
/// MPR termination tolerance handed to FCL [m] (FCL's 1e-6 default is in model units, here
/// metres: it would equal the margin).
inline constexpr double kMprToleranceM = 1e-10;
/// Radius of the sphere that stands for a soft node [m]: far below the margin.
inline constexpr double kNodeRadiusM = 1e-9;

/// The oracle's answer for one pose: which triangles are cut (deeper than t), which nodes lie
/// inside (deeper than t), each also at t ∓ margin.
struct OracleCounts {
  std::vector<char> cut;         ///< per triangle, at t
  std::vector<char> cut_loose;   ///< per triangle, at t − margin (a superset of cut)
  std::vector<char> cut_strict;  ///< per triangle, at t + margin (a subset of cut)
  std::vector<char> inside, inside_loose, inside_strict;  ///< per node, likewise
  [[nodiscard]] static int count(const std::vector<char>& flags);
};

/// How the project's per-triangle (or per-node) answers compare with the oracle's.
struct Agreement {
  int project = 0;        ///< the project's count
  int oracle = 0;         ///< the oracle's count at t
  int differ = 0;         ///< items where the two answers differ at t
  int beyond_margin = 0;  ///< differing items the margin does not explain (must be 0)
};
[[nodiscard]] Agreement compare(const std::vector<char>& project, const std::vector<char>& oracle, const std::vector<char>& oracle_loose,
                                const std::vector<char>& oracle_strict);

/// Agreement over the steps of a run: the cut-triangle and inside-node figures of both sides.
struct RunTally {
  int steps = 0;
  int project_max_cut = 0, oracle_max_cut = 0;                ///< most triangles cut on one step
  int project_steps_with_cut = 0, oracle_steps_with_cut = 0;  ///< steps with any
  int project_max_inside = 0, oracle_max_inside = 0;          ///< most nodes inside on one step
  long triangles_differ = 0, triangles_beyond_margin = 0;     ///< summed over the steps
  long nodes_differ = 0, nodes_beyond_margin = 0;
  void add(const Agreement& triangles, const Agreement& nodes);
};

/// The tool (a rigid convex body given by its vertices, tool frame) shrunk by t and t ∓ margin.
class FclToolOracle {
 public:
  FclToolOracle(const std::vector<Eigen::Vector3d>& tool_vertices_tool_m, double depth_tolerance_m);
  /// A box centred on the tool origin.
  static FclToolOracle from_box(const Eigen::Vector3d& half_extents_m, double depth_tolerance_m);
  ~FclToolOracle();
  FclToolOracle(FclToolOracle&&) noexcept;
  FclToolOracle& operator=(FclToolOracle&&) noexcept;
  FclToolOracle(const FclToolOracle&) = delete;
  FclToolOracle& operator=(const FclToolOracle&) = delete;

  /// Soft triangles (world node positions, index triples) and nodes against the tool at
  /// `tool_to_world`. Without margins only the answers at t are filled (the ∓ margin lists stay
  /// empty, and compare() refuses them): a third of the work, for the steps where the project
  /// agrees with the oracle at t anyway; ask again with margins where it does not.
  [[nodiscard]] OracleCounts check(const std::vector<Eigen::Vector3d>& soft_nodes_world_m, const std::vector<std::array<int, 3>>& faces,
                                   const Eigen::Isometry3d& tool_to_world, bool with_margins = true) const;
  /// One triangle (tool frame) at t.
  [[nodiscard]] bool triangle_cut(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) const;
  /// The vertices of the tool shrunk by t (tool frame), for inspection.
  [[nodiscard]] const std::vector<Eigen::Vector3d>& shrunk_vertices_tool_m() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fissure::host::test_oracle
