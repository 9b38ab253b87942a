#pragma once
// Internal model (const, built once) and data (mutable, preallocated) of the thin-body collision,
// and the pipeline stages (one file each) that read the model and update the data — MuJoCo style.
#include <fissure/host_sim/node_bounds_solver.hpp>
#include <fissure/host_sim/thin_body_collision.hpp>
#include <fissure/host_sim/thin_tool.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <vector>

class btSoftBody;

namespace fissure::host::thin_body {

// A node counts as inside the tool only beyond this depth (float noise of positions written at +skin).
inline constexpr double kInsideTolerance_m = 1e-7;

// A held node's share of its force at `gap_m` in front of its plane: smoothstep from 1 on the
// face to 0 at `release_m`, flat at both ends, so a node fades out as it separates.
inline double release_share(double gap_m, double release_m) {
  const double u = release_m > 0.0 ? std::max(0.0, gap_m) / release_m : 0.0;
  return 1.0 - u * u * (3.0 - 2.0 * u);
}

// Topology and rest state of the soft surface (paper: "during the object initialization, the
// original position of each triangle vertices is stored").
struct SoftSurfaceModel {
  int node_count = 0;
  int face_count = 0;
  std::vector<std::array<int, 3>> face_nodes;
  std::vector<int> faces_of_node_begin;  // CSR: faces around each node
  std::vector<int> faces_of_node;
  bool has_faceless_nodes = false;  // a volume's interior nodes (broad_phase.cpp: take_faceless)
  std::vector<Eigen::Vector3d> rest_node_world_m;      // rest positions (world, when the rest state was taken)
  std::vector<Eigen::Vector3d> rest_centroid_world_m;  // centroid_distance's rest centroids
  std::vector<double> rest_area_m2;
  std::vector<double> node_rest_area_m2;  // a third of the rest area of the faces round each node (its nodal quadrature weight)
  double outward_sign = 1.0;   // multiplies Bullet's winding normal to point out of the soft body
  double max_rest_edge_m = 0.0;
  Eigen::AlignedBox3d rest_bounds_world_m;  // bounds of rest_node_world_m (the broad phase's seed clip side)
};

// Uniform 2-D grid of the tool nodes over the two non-thin axes (tool frame), so a soft triangle
// only tests the tool nodes under its swept footprint: cost grows with the contact patch.
struct ToolNodeBins {
  int axis_u = 0;
  int axis_v = 2;
  double origin_u = 0.0;
  double origin_v = 0.0;
  double cell_m = 1.0;
  int cells_u = 1;
  int cells_v = 1;
  std::vector<int> begin;  // CSR over cells_u * cells_v cells
  std::vector<int> nodes;
  // The node sweep's tables (prepare_node_sweep): each tool plane's nodes binned alone, so that a
  // skipped plane's nodes are never read and a row of cells is one contiguous run of nodes.
  std::vector<int> plane_cell_begin;              // CSR over planes × cells (plane * cells_u * cells_v + cell)
  std::vector<int> plane_cell_nodes;              // tool node index
  std::vector<Eigen::Vector3d> plane_cell_positions_m;  // its tool-frame position
  // Per tool plane: the tool-frame bounds of its nodes (the sweep skips a whole plane for a
  // triangle when no node of it can touch the triangle).
  std::vector<Eigen::AlignedBox3d> plane_bounds_m;
};

struct CollisionModel {
  ToolNodes tool;
  ToolNodeBins bins;
  SoftSurfaceModel soft;
  ThinBodyCollisionParams params;
  bool paired = true;          // false: the ray-only variant
  double memory_depth_m = 0.0; // how far behind a triangle a node already in contact may start
  // The tool bounds padded by contact_distance + skin, as a sphere (tool frame): the broad
  // phase's first, out-of-contact test (broad_phase_out_of_reach) reads only these.
  Eigen::Vector3d near_sphere_centre_tool_m = Eigen::Vector3d::Zero();
  double near_sphere_radius_m = 0.0;
  // Per tool plane: 1 when edge (rim) nodes lie on it (ToolNodes::edge_node_flags). A soft
  // triangle placed on a rim plane takes ALL its free vertices onto that plane whenever the move
  // does not pass through the tool (enforced_displacement.cpp).
  std::vector<std::uint8_t> rim_plane;
  // How far from the tool's bounds a soft face is collected by the broad phase: contact_distance
  // + skin, plus solver_reach_m for the in-solver response (nodes Bullet's iterations may pull
  // into the tool after the detection ran on the predicted positions).
  double near_pad_m = 0.0;
  // The tool's corners (the feature edges' end points, each once, tool frame): a convex tool's
  // extent along any direction is reached at one of them, so the rim stages reject a soft
  // triangle whose plane the tool does not cross with a few dot products instead of the exact
  // prism clip over every feature edge.
  std::vector<Eigen::Vector3d> tool_corners_tool_m;
  // Per rim plane: the tool's lowest height along the plane's normal (its back, the far side of
  // the tool seen from that rim). A node below it is beyond the tool, not beside it, and is never
  // wrapped onto the rim (enforced_displacement.cpp). −∞ for the other planes.
  std::vector<double> rim_plane_back_m;
};

// The tool's lowest and highest height above a plane through `origin` with unit `normal` (tool
// frame): its support along ±normal, over the corners.
struct ToolHeightRange {
  double lowest_m = std::numeric_limits<double>::infinity();
  double highest_m = -std::numeric_limits<double>::infinity();
};
ToolHeightRange tool_height_range(const CollisionModel& model, const Eigen::Vector3d& origin, const Eigen::Vector3d& normal);

// Per-step frame quantities.
struct StepFrame {
  std::int64_t step = 0;
  double dt_s = 0.0;
  Eigen::Matrix3d r_prev = Eigen::Matrix3d::Identity();  // tool → world at the previous pose
  Eigen::Vector3d t_prev = Eigen::Vector3d::Zero();
  Eigen::Matrix3d r_cur = Eigen::Matrix3d::Identity();   // tool → world at the current pose
  Eigen::Vector3d t_cur = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_world_m_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity_world = Eigen::Vector3d::Zero();
  Eigen::AlignedBox3d swept_tool_world_m;
};

// The mutable state of one collision instance, one sub-struct per pipeline stage (the stage that
// writes it; later stages read it). "Carried" fields keep their meaning from one step to the next
// (side memories, filters, anchors: each valid at its stamp); the rest is the stage's scratch for
// the current step, and the counters say what the last call visited (tests and the bench read
// them instead of timing). Every vector is sized by allocate_collision_data: no step allocates.
struct BroadPhaseData {  // stage 1 (broad_phase.cpp)
  // Output, this step: the soft nodes and faces near the swept tool, and the nodes' positions in
  // the tool frame at the start (previous pose, m_q) and at the end (current pose, m_x).
  std::vector<int> candidate_nodes;
  std::vector<int> candidate_faces;
  std::vector<std::int64_t> face_candidate_stamp;
  std::vector<std::int64_t> soft_stamp;
  std::vector<Eigen::Vector3d> start_tool_m;
  std::vector<Eigen::Vector3d> end_tool_m;
  // Scratch (sized on the broad phase's first call).
  std::vector<std::int64_t> listed_stamp;      // soft node listed in candidate_nodes at this step
  std::vector<int> previous_candidates;        // carried: last step's candidate nodes (re-tested directly)
  std::vector<int> scan_hits;                  // nodes inside the scan's union box this step
  std::vector<int> faces_kept;                 // faces the world-bounds pre-filter passed to the exact test
  // Counters of the last call.
  int nodes_scanned = 0;        // soft nodes whose start/end positions the scan read (every node)
  int seed_nodes = 0;           // soft nodes whose own start/end box met the query
  int faces_tested = 0;         // soft faces reached and tested (pre-filter on their world bounds)
  int faces_transformed = 0;    // of those, faces the exact tool-frame test ran on (vertices transformed)
};

struct NodeSweepData {  // stage 2 (node_sweep.cpp): tool nodes against soft triangles over the step
  // Per tool node: the soft face in contact (-1: none) this step and, carried, the last one.
  std::vector<int> node_face;
  std::vector<int> node_face_prev;
  std::vector<int> node_age;         // carried: consecutive steps in contact (who led first)
  std::vector<double> node_tau;      // fraction of the step at which the contact began
  std::vector<double> node_facing;   // tool normal · soft normal (−1: head on)
  std::vector<int> contact_nodes;    // nodes in contact this step (before exclusion)
  // Per tool plane: a node of it was in contact last step (carried) / the current triangle may
  // touch a node of it (scratch).
  std::vector<std::uint8_t> plane_had_contact;
  std::vector<std::uint8_t> plane_open;
  std::vector<std::uint64_t> contact_words;  // bitset over the tool nodes (orders contact_nodes; all 0 between steps)
  int node_tests = 0;  // node tests the last sweep_tool_nodes call ran
};

struct PairExclusionData {  // stage 3 (pair_exclusion.cpp)
  std::vector<std::int64_t> node_excluded_stamp;
  std::vector<int> vector;  // the paper's exclusion vector (this step)
  // Per soft face hit this step by a tool node that survived the exclusion: the leading tool node
  // and its plane (stage 4 rewrites the plane a face's vertices were placed on).
  std::vector<std::int64_t> face_contact_stamp;
  std::vector<int> face_plane;
  std::vector<int> face_lead_node;
  std::vector<int> contacted_faces;  // stage 3: faces hit by a tool node; stage 4: faces with a colliding soft node
};

struct DisplacementData {  // stage 4 (enforced_displacement.cpp; in_solver: solver_projection.cpp)
  std::vector<std::int64_t> moved_stamp;   // displaced this step ...
  std::vector<int> moved_nodes;            // ... listed (their triangles have a colliding node)
  std::vector<std::int64_t> hold_stamp;    // carried: soft-node side memory: held on a tool plane ...
  std::vector<int> hold_plane;             // ... this one, at step hold_stamp
  std::vector<double> node_share;          // colliding node's share of its force (valid where moved_stamp == step):
                                           // 1 on the face, ramping to 0 over release_distance in front of it
};

struct SolverProjectionData {  // in_solver only (solver_projection.cpp, rim_projection.cpp)
  std::vector<Eigen::Vector3d> iterate_tool_m;  // each candidate's position after the last projection (tool frame, current pose)
  // Friction: where a held node sticks (carried; tool frame; the node's position at the end of the
  // step it was last held, or where it was first held this step), valid at friction_anchor_stamp,
  // and the tangential correction friction has applied to it so far this step (tool frame, m; the
  // position-level friction impulse × h / m) with whether it was the whole move (stick) or the cone's share (slide).
  std::vector<Eigen::Vector3d> friction_anchor_tool_m;
  std::vector<std::int64_t> friction_anchor_stamp;
  std::vector<Eigen::Vector3d> friction_correction_tool_m;
  std::vector<std::uint8_t> friction_sliding;
  // Rim constraint: the displacement its projections gave a node this step (world, m), valid at
  // rim_correction_stamp.
  std::vector<Eigen::Vector3d> rim_correction_world_m;
  std::vector<std::int64_t> rim_correction_stamp;
};

struct ForceData {  // stage 5 (hunt_crossley_force.cpp): the ẋ filters, carried
  std::vector<std::int64_t> face_force_stamp;
  std::vector<std::int64_t> hc_stamp;   // last step the face was in contact (filter state valid)
  std::vector<double> hc_x_prev_m;
  std::vector<double> hc_rate_filtered_m_s;
  // normal_displacement: the ẋ filter per triangle corner (index 3·face + corner).
  std::vector<std::int64_t> hc_corner_stamp;
  std::vector<double> hc_corner_x_prev_m;
  std::vector<double> hc_corner_rate_filtered_m_s;
  // normal_displacement: each corner's onset ramp (0 → 1 over contact_onset_ramp_s from the step
  // it joins the contact set, index 3·face + corner).
  std::vector<double> hc_corner_onset;
};

struct CollisionData {
  std::int64_t step = 0;
  BroadPhaseData broad;
  NodeSweepData sweep;
  PairExclusionData exclusion;
  DisplacementData displacement;
  SolverProjectionData solver;
  ForceData force;
};

// The step's frame quantities (rotations, translations, velocities, swept tool bounds) from the
// tool's pose at the start and at the end of the step.
StepFrame make_step_frame(const CollisionModel& model, std::int64_t step, const ToolPose& previous,
                          const ToolPose& current, double dt_s);
CollisionModel build_collision_model(const ToolNodes& tool, const btSoftBody& soft,
                                     const ThinBodyCollisionParams& params, bool paired);
void take_rest_state(const btSoftBody& soft, SoftSurfaceModel& model);
void allocate_collision_data(const CollisionModel& model, CollisionData& data);

// Stage 1 (broad_phase.cpp): swept tool bounds vs every soft node's start / end position; on a hit,
// collects candidate soft nodes / faces and their tool-frame start / end positions. false = out
// of contact. `node_bounds`: this step's node bounds from the solver (NodeBoundsSolver), which
// let it skip the nodes far from the tool; null (or not valid): every node is read.
bool broad_phase(const CollisionModel& model, const StepFrame& frame, const btSoftBody& soft, CollisionData& data,
                 const SoftNodeBounds* node_bounds = nullptr);
// Stage 1's first test, before the step's frame is even built (out of contact its code and data
// are all that is touched after Bullet's step): true when the tool, padded and swept, cannot meet
// the solver's whole-body bounds — the broad phase would find nothing. Only for a step after one
// with no candidate (so no side memory and no held node to re-test); false without valid bounds.
// On true it leaves `data` as broad_phase() would (no candidates, zero counts).
bool broad_phase_out_of_reach(const CollisionModel& model, const ToolPose& previous, const ToolPose& current,
                              const SoftNodeBounds* node_bounds, CollisionData& data);
// Stage 2 (node_sweep.cpp): every tool node against the candidate triangles, swept over the step.
void sweep_tool_nodes(const CollisionModel& model, CollisionData& data);
// Load time: the bin-ordered node tables and per-plane bounds the sweep reads (fills bins' tables).
void prepare_node_sweep(const ToolNodes& tool, ToolNodeBins& bins);
// Stage 3 (pair_exclusion.cpp): infeasible pairs → exclusion vector (paired only); assigns each
// contacted face the tool plane of its leading node. Returns the number of both-face contacts left.
int exclude_infeasible_pairs(const CollisionModel& model, CollisionData& data);
// Stage 4 (enforced_displacement.cpp): writes soft node positions / velocities.
struct DisplacementCounts {
  int displaced = 0;
  int guard_corrections = 0;
};
// `node_bounds` (may be null) takes in every position it writes, so that another tool part's
// broad phase later in the same step still reads conservative bounds.
DisplacementCounts enforce_displacement(const CollisionModel& model, const StepFrame& frame, btSoftBody& soft,
                                        CollisionData& data, SoftNodeBounds* node_bounds = nullptr);
// Whether the straight segment a → b (tool frame) stays outside the tool's interior (Cyrus–Beck
// clip against every tool plane; the interior shrunk by the inside tolerance, so touching a face
// or an edge is not "through").
bool segment_clears_tool(const std::vector<ToolPlane>& planes, const Eigen::Vector3d& a, const Eigen::Vector3d& b);
// After the in-solver solve and Bullet's velocity update: a candidate node whose straight path
// over the step (start at the previous pose, end at the current one, both in the tool frame)
// passes through the tool goes onto the face that path enters by, held there, its velocity
// following. Why: each position iteration's move clears the tool, but a node carried round a
// corner by several iterations (the rim projections of a fan of cut triangles throw a node on a
// jaw's corner edge 2–8 mm per iteration) ends the step on a path through it, and Bullet's
// velocity (x − q)/h is that path. Returns how many nodes were moved.
int guard_swept_paths(const CollisionModel& model, const StepFrame& frame, btSoftBody& soft, CollisionData& data, SoftNodeBounds* bounds);
// enforce_displacement's three parts: place the contacted nodes (and guard), keep last step's held
// nodes within release_distance colliding (after_step's hysteresis), and collect the force set
// (every face around a colliding node) into contacted_faces.
DisplacementCounts place_contact_nodes(const CollisionModel& model, const StepFrame& frame, btSoftBody& soft, CollisionData& data,
                                       SoftNodeBounds* node_bounds);
void hold_near_nodes(const CollisionModel& model, const StepFrame& frame, CollisionData& data);
void collect_force_faces(const CollisionModel& model, const StepFrame& frame, CollisionData& data);
// The in-solver response (solver_projection.cpp): after each of Bullet's position iterations, the
// held nodes behind their plane and the free candidate nodes inside the tool back out on a face
// (returns how many were moved); after the solve, every held node's share of the force from its
// final gap, the colliding nodes listed in moved_nodes.
int project_contacts(const CollisionModel& model, const StepFrame& frame, btSoftBody& soft, CollisionData& data);
// Before the first project_contacts of a step: every candidate's position after the placement,
// from which the first iteration's moves are judged.
void start_iterates(const CollisionModel& model, const StepFrame& frame, const btSoftBody& soft, CollisionData& data);
// The rim constraint (rim_projection.cpp), before the node projection in each iteration: every
// candidate soft triangle the tool cuts (in front of and behind its plane inside its prism, at
// most a tool thickness + solver_reach deep) moved back until the deepest tool point lies on it.
// Returns how many triangles were moved.
// A world position in the tool frame at the step's current pose, and back.
inline Eigen::Vector3d to_tool(const StepFrame& frame, const btVector3& x_world) {
  return frame.r_cur.transpose() * (Eigen::Vector3d(x_world.x(), x_world.y(), x_world.z()) - frame.t_cur);
}
inline void write_tool_position(const StepFrame& frame, const Eigen::Vector3d& p_tool, btVector3& x_world) {
  const Eigen::Vector3d p_world = frame.r_cur * p_tool + frame.t_cur;
  x_world.setValue(static_cast<btScalar>(p_world.x()), static_cast<btScalar>(p_world.y()), static_cast<btScalar>(p_world.z()));
}

// A soft triangle in the tool frame (current positions): its corners, unit outward normal and
// twice its area. false for a degenerate (zero-area) triangle.
struct SoftTriangleInTool {
  std::array<Eigen::Vector3d, 3> x;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  double twice_area = 0.0;
};
bool soft_triangle_in_tool(const CollisionModel& model, const StepFrame& frame, const btSoftBody& soft, int face, SoftTriangleInTool& out);
// Barycentric coordinates (clamped ≥ 0) of the foot of `point` on the triangle's plane.
std::array<double, 3> barycentric_of_foot(const SoftTriangleInTool& triangle, const Eigen::Vector3d& point);

// Over the intersection of the tool with a soft triangle's prism (x: its corners, normal: its unit
// outward normal, tool frame): the lowest and highest height above the triangle's plane and the
// lowest point (rim_projection.cpp says why these vertices are exact for a convex tool), over the
// tool edges within reach_m of the triangle's box (callers look no further than that).
struct TriangleToolExtent {
  bool meets = false;
  double lowest_m = std::numeric_limits<double>::infinity();
  double highest_m = -std::numeric_limits<double>::infinity();
  Eigen::Vector3d deepest_tool_m = Eigen::Vector3d::Zero();
};
TriangleToolExtent triangle_tool_extent(const ToolNodes& tool, const std::array<Eigen::Vector3d, 3>& x, const Eigen::Vector3d& normal,
                                        double reach_m);
int project_rim_contacts(const CollisionModel& model, const StepFrame& frame, btSoftBody& soft, CollisionData& data);
// After the solve's velocity update: a corner the rim constraint pushed this step leaves it no
// faster along that push than the tool moves there (the contact is inelastic).
void inelastic_rim_velocities(const StepFrame& frame, btSoftBody& soft, const CollisionData& data);
void take_solved_shares(const CollisionModel& model, const StepFrame& frame, const btSoftBody& soft, CollisionData& data);
// After the solve, with friction: the friction force on the tool, the reaction to every candidate's
// friction impulse this step (m·correction/h²), and how many held nodes stuck and slid.
void friction_force_on_tool(const CollisionModel& model, const StepFrame& frame, const btSoftBody& soft, const CollisionData& data,
                            CollisionStepResult& out);
// The elastic Hunt-Crossley normal force a node held on `plane` carries at the current pose and
// `gap_m` in front of the plane (share · nodal weight · k·xⁿ): what the force stage gives it, and
// the normal force its friction cone is taken from.
double held_node_normal_force(const CollisionModel& model, const StepFrame& frame, int node, const ToolPlane& plane, double gap_m);
// Stage 5 (hunt_crossley_force.cpp): HC per contacted triangle, summed; fills out.contacts.
void hunt_crossley_force(const CollisionModel& model, const StepFrame& frame, const btSoftBody& soft,
                         CollisionData& data, CollisionStepResult& out);

}  // namespace fissure::host::thin_body
