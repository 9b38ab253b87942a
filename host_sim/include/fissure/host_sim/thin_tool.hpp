#pragma once
// Thin rigid tools for the paired-node collision (paper: Fazioli et al., "Implementation of a
// soft-rigid collision algorithm...", extending Fukuhara et al. 2014; BRIEF §3).
//
// A ToolNodes is the const *model* of a tool: built ONCE at load from a shape, it holds the
// collision nodes (position + outward normal in the tool frame), the pair of each node across
// the thickness, the report of how the pairing went, and the tool's convex volume as planes
// (used to keep soft nodes out of it and to measure penetration). Nothing here changes per step.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <vector>

namespace fissure::host {

// Pose of the tool frame in the world frame (p_world = orientation_world * p_tool + position_world_m).
struct ToolPose {
  Eigen::Vector3d position_world_m = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation_world = Eigen::Quaterniond::Identity();

  [[nodiscard]] Eigen::Vector3d to_world(const Eigen::Vector3d& p_tool) const {
    return orientation_world * p_tool + position_world_m;
  }
  [[nodiscard]] Eigen::Vector3d to_tool(const Eigen::Vector3d& p_world) const {
    return orientation_world.conjugate() * (p_world - position_world_m);
  }
};

// A box tool (the paper's / Fukuhara's spatula): centred on the tool origin. The two large faces
// are the ones normal to thin_axis; each carries a nodes_u × nodes_v grid of collision nodes
// (u, v = the two other axes in increasing order). Node i on one face pairs with the node at the
// same (u, v) on the other face (always mutual).
struct BoxToolShape {
  Eigen::Vector3d half_extents_m = Eigen::Vector3d(0.02, 0.002, 0.02);
  int thin_axis = 1;  // 0, 1, 2 in the tool frame
  int nodes_u = 9;    // grid resolution per large face along the first non-thin axis (≥ 1)
  int nodes_v = 9;    // ... along the second non-thin axis (≥ 1)
  // Edge (rim) nodes on the four thin side faces, one row along the middle of the thickness at
  // the large-face grid's positions along each side's long direction (nodes_v nodes on the two
  // sides normal to u, nodes_u on the two normal to v). They are UNPAIRED and appended after the
  // 2·nodes_u·nodes_v face nodes (which keep their indices). Without them a blade moving
  // edge-first slips between the soft nodes of a coarse mesh and slices it without any force.
  bool edge_nodes = true;
};

// A convex thin tool given as a closed triangle mesh in the tool frame (outward winding, i.e.
// counter-clockwise seen from outside; the loader fixes the winding if the volume comes out negative).
// One node at each triangle's centroid, paired with the triangle hit by a ray cast from it
// opposite to its normal — the ray LIMITED to pairing_ray_limit_m so that nodes on the rounded rim
// do not pair across the edge (paper Fig. 2). A ray that hits nothing within the limit leaves
// the node unpaired.
struct ConvexMeshToolShape {
  std::vector<Eigen::Vector3d> vertices_tool_m;
  std::vector<std::array<int, 3>> triangles;
  double pairing_ray_limit_m = 0.0;  // scene parameter; ≤ 0 means "no pairing" (a tool that is not thin)
};

struct PairingReport {
  int mutual = 0;    // nodes whose pair points back at them
  int one_way = 0;   // nodes paired with a node that is paired with someone else
  int unpaired = 0;  // nodes whose ray found nothing within the limit
};

// A plane of the tool's convex volume in the tool frame: outward normal · p = offset_m on the
// plane, < offset_m inside the tool.
struct ToolPlane {
  Eigen::Vector3d normal_tool = Eigen::Vector3d::UnitY();
  double offset_m = 0.0;
};

class ToolNodes {
 public:
  // Throws std::invalid_argument naming the bad field (non-positive extent, bad axis, grid < 1,
  // empty/degenerate/non-convex mesh, triangle index out of range).
  static ToolNodes from_box(const BoxToolShape& shape);
  static ToolNodes from_convex_mesh(const ConvexMeshToolShape& shape);

  [[nodiscard]] int node_count() const { return static_cast<int>(positions_tool_m_.size()); }
  [[nodiscard]] const std::vector<Eigen::Vector3d>& positions_tool_m() const { return positions_tool_m_; }
  [[nodiscard]] const std::vector<Eigen::Vector3d>& normals_tool() const { return normals_tool_; }
  // Pair of each node across the thickness, -1 = unpaired.
  [[nodiscard]] const std::vector<int>& pair_of() const { return pair_of_; }
  // Nodes whose pair is this node (reverse of pair_of; needed for the exclusion cross-check of
  // one-way pairs): paired_by(i) = [paired_by_begin[i], paired_by_begin[i+1]) in paired_by_nodes.
  [[nodiscard]] const std::vector<int>& paired_by_begin() const { return paired_by_begin_; }
  [[nodiscard]] const std::vector<int>& paired_by_nodes() const { return paired_by_nodes_; }
  // The tool face (plane index into planes()) each node lies on; the soft body is placed on this
  // plane when the node leads a contact.
  [[nodiscard]] const std::vector<int>& plane_of_node() const { return plane_of_node_; }
  [[nodiscard]] const std::vector<ToolPlane>& planes() const { return planes_; }
  [[nodiscard]] const PairingReport& pairing_report() const { return report_; }
  // 1 for an edge (rim) node: a node on a side face, not on one of the two large faces (box: the
  // appended side-face rows; mesh: centroids of triangles whose normal is more than 60° off the
  // thin axis). Edge nodes are never paired on a box. When an edge node and a node on another
  // tool plane hit the same soft triangle, the one meeting it more head-on places it (see
  // pair_exclusion.cpp).
  [[nodiscard]] const std::vector<std::uint8_t>& edge_node_flags() const { return edge_node_; }
  [[nodiscard]] int edge_node_count() const;
  // Whether pairing (and so the infeasible-pair exclusion) applies: box tools always, meshes
  // when pairing_ray_limit_m > 0 and at least one pair was found.
  [[nodiscard]] bool is_thin() const { return thin_; }
  // Axis of smallest extent (box: the given thin axis; mesh: from its bounds) and the extent.
  [[nodiscard]] int thin_axis() const { return thin_axis_; }
  [[nodiscard]] double thickness_m() const { return thickness_m_; }
  [[nodiscard]] const Eigen::AlignedBox3d& bounds_tool_m() const { return bounds_tool_m_; }
  // Vertices of the tool volume (box: 8 corners; mesh: its vertices) for swept bounds.
  [[nodiscard]] const std::vector<Eigen::Vector3d>& hull_vertices_tool_m() const { return hull_vertices_tool_m_; }
  // The edges where two faces of the tool's volume meet at an angle (box: its 12 edges; mesh: the
  // triangle edges between two different planes), as end points in the tool frame: the rim a soft
  // triangle can be draped over, and must not be cut by.
  [[nodiscard]] const std::vector<std::array<Eigen::Vector3d, 2>>& feature_edges_tool_m() const { return feature_edges_tool_m_; }
  // Per feature edge: its midpoint and half its length (the ball round it), for a cheap first test.
  [[nodiscard]] const std::vector<Eigen::Vector3d>& feature_edge_midpoints_tool_m() const { return feature_edge_midpoints_tool_m_; }
  [[nodiscard]] const std::vector<double>& feature_edge_half_lengths_m() const { return feature_edge_half_lengths_m_; }
  // A ball tree over the feature edges (each ball holds its edges whole), so that a query along a
  // line visits the edges near the line rather than all of them (the rounded spatula has ~10³).
  // A ball with first_child < 0 is a leaf holding feature_edge_ball_order()[begin, end); else its
  // children are first_child and first_child + 1. Depth ≤ kFeatureEdgeBallDepth.
  struct FeatureEdgeBall {
    Eigen::Vector3d centre_tool_m = Eigen::Vector3d::Zero();
    double radius_m = 0.0;
    int first_child = -1;
    int begin = 0;
    int end = 0;
  };
  static constexpr int kFeatureEdgeBallDepth = 48;
  [[nodiscard]] const std::vector<FeatureEdgeBall>& feature_edge_balls() const { return feature_edge_balls_; }
  [[nodiscard]] const std::vector<int>& feature_edge_ball_order() const { return feature_edge_ball_order_; }

  // Signed distance to the tool's convex volume from a point in the tool frame: max over planes
  // of (n·p − offset). Exact inside (−depth to the nearest face), a lower bound outside.
  // Penetration of a soft node into the tool = max(0, −signed_distance).
  [[nodiscard]] double signed_distance_m(const Eigen::Vector3d& p_tool) const;
  // Whether p_tool lies in the tool's footprint seen along the thin axis (its projection falls
  // inside the projection of the tool's volume) — used for the "crossed node" metric.
  [[nodiscard]] bool in_footprint(const Eigen::Vector3d& p_tool) const;

 private:
  ToolNodes() = default;
  void finish_pairing();  // fills paired_by_*, report_, thin_

  std::vector<Eigen::Vector3d> positions_tool_m_;
  std::vector<Eigen::Vector3d> normals_tool_;
  std::vector<int> pair_of_;
  std::vector<int> paired_by_begin_;
  std::vector<int> paired_by_nodes_;
  std::vector<int> plane_of_node_;
  std::vector<std::uint8_t> edge_node_;
  std::vector<ToolPlane> planes_;
  std::vector<Eigen::Vector3d> hull_vertices_tool_m_;
  std::vector<std::array<Eigen::Vector3d, 2>> feature_edges_tool_m_;
  std::vector<Eigen::Vector3d> feature_edge_midpoints_tool_m_;
  std::vector<double> feature_edge_half_lengths_m_;
  std::vector<FeatureEdgeBall> feature_edge_balls_;
  std::vector<int> feature_edge_ball_order_;
  // Footprint along the thin axis as 2-D half-planes (a·(u,v) ≤ b) of the projected hull.
  std::vector<Eigen::Vector3d> footprint_halfplanes_;
  PairingReport report_;
  bool thin_ = false;
  int thin_axis_ = 1;
  double thickness_m_ = 0.0;
  Eigen::AlignedBox3d bounds_tool_m_;
};

// A convex spatula with rounded rims (paper Fig. 1 middle, Fig. 2): a rounded rectangle
// (length × width, corner radius) in the tool's x–z plane, thickness along y, whose rim is a
// half-circle profile sampled with rim_segments segments — so rim triangles are very close to one
// another (the case the limited pairing ray is for). Outward-wound, closed, convex.
struct RoundedSpatulaParams {
  double length_m = 0.04;        // along x
  double width_m = 0.04;         // along z
  double thickness_m = 0.002;    // along y (the thin axis)
  double corner_radius_m = 0.008;
  int corner_segments = 6;       // per 90° of each rounded corner
  int rim_segments = 7;          // half-circle profile of the rim (≥ 2); odd → a band with horizontal normals (Fig. 2)
  int face_divisions = 8;        // grid subdivision of the flat faces (node density)
};
ConvexMeshToolShape make_rounded_spatula_mesh(const RoundedSpatulaParams& params, double pairing_ray_limit_m);

}  // namespace fissure::host
