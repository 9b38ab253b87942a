// Stage 1: broad phase (BRIEF §3 item 6: "broad phase on the swept tool bounds first, nothing when
// out of contact"). It is exact with respect to the positions the later stages use. No structure
// kept from before Bullet's step can be (see 1. below), so it reads node bounds taken inside
// Bullet's solve itself (NodeBoundsSolver), or, without them, every node once.
//
// What the later stages need, and so what this stage must return (all in the TOOL frame, where the
// node sweep and the response work — start = Bullet's m_q seen from the previous tool pose, end =
// m_x seen from the current pose):
//   * every soft face whose start/end bounds come within `near_pad` (contact_distance + skin) of
//     the tool's bounds — a tool node within contact_distance of it (node sweep), a vertex whose
//     relative path enters the tool (guard);
//   * every face around a soft node held on the tool LAST step that is still within
//     release_distance of the tool's bounds (the response's hysteresis keeps such a node
//     colliding). Only those nodes get the release band: a plate held on a sphere does not
//     collect every face within release_distance under its whole face;
//   * every soft face within `memory_pad` (memory_depth + contact) of the tool nodes that were in
//     contact LAST step: only those may keep a contact while starting behind their triangle
//     (node_sweep.cpp's side memory). Bounding those nodes, not the whole tool, keeps a held
//     plate from collecting every face a tool thickness under its whole face;
//   * every vertex of those faces (candidate nodes, with their tool-frame start/end positions).
// The test is exact on that criterion (tests/host_sim/broad_phase_test.cpp compares it with brute
// force). Faces are reached through seed nodes, soft nodes whose own start/end box (m_q, m_x) meets
// a seed box: each query's swept world box grown by the longest stretched edge (a large triangle
// can cross the tool with all three vertices outside it) and cut back to the swept box on the
// side the soft body lies (seed_box() says why that loses no face):
//   0. With the solver's node bounds (node_bounds_solver.hpp: per 32 nodes, every node's m_q and
//      m_x after the solve, fused into Bullet's own last pass over the nodes; extended by the
//      collision's own writes): the whole body's box is tested against the query WITHOUT the
//      seed reach — every face lies inside the bounds of all nodes — and out of contact that is
//      all that runs. In contact only the nodes of blocks whose box meets the union box are read
//      (bench collision, 20 480 faces, same contact: 704 of 10 242 nodes). Without them:
//   1. EVERY soft node is tested, from the very positions the narrow phase uses. Bullet's node tree
//      (btSoftBody::m_ndbvt) is not used: Bullet fits each leaf around the node's PREDICTED
//      position, then pose matching and the constraint solver move the node — 15-25 mm after a
//      released dent under strong pose matching (tests/host_sim/broad_phase_test.cpp), 10-17 mm in
//      bench collision's 128-face sweep — further than any fixed margin. No structure built before
//      Bullet's step can be exact without a bound on how far Bullet moves a node after it, and
//      Bullet gives none. The scan reads each node's two positions once, in memory order (one cache
//      line per node, software-prefetched), against one union box; only nodes in it get the exact
//      tests. Its price (bench collision, 10 242 nodes, after Bullet's step has evicted the cache):
//      ~60 µs a step in or out of contact; in contact that is less than a walk of Bullet's node
//      tree costs (~2000 cold tree nodes for a fixed contact on the 20 480-face sphere).
//      (A separate bounds pass after Bullet's solve costs +38-48 µs a step on 10 242 nodes — the
//      nodes are cold again by then; fused into the solve's own last node loop, as
//      NodeBoundsSolver does, it costs ~5 instructions a node: 0. above.)
//   2. The faces around last step's candidate nodes are re-tested directly: a node held on the tool
//      last step keeps its faces for the release band even where the seed query does not reach.
//   3. Most faces reached through the seeds lie in the seed band only and are rejected (bench
//      collision's 20 480-face same_contact hold: 45 seeds reach 116 faces for 24 candidates).
//      Each reached face is first tested from its vertices' WORLD bounds (m_q box, m_x box, in
//      Bullet's float with SIMD), carried into the tool frame whole (Arvo's box transform, see
//      ToolFrameBounds): every tool-frame start/end position of a vertex lies in those carried
//      boxes, so a face they keep away from every query is one the exact test would reject — the
//      candidate set is unchanged (tests/host_sim/broad_phase_test.cpp: brute force, every reached
//      face decided as the exact test decides, and rotated / stretched / held / memory cases at
//      the pre-filter's edge). Only the faces it keeps get their vertices transformed into the
//      tool frame and stamped. That saves only a few µs: the band's cost is memory latency (a few
//      lines per face and vertex, cold after Bullet's step), not arithmetic.
// Out of contact: the whole-body test fails (or, without bounds, the scan finds no seed); nothing
// else runs.
#include "collision_state.hpp"

#include <BulletSoftBody/btSoftBody.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace fissure::host::thin_body {
namespace {

// How many nodes ahead the scan prefetches (microbenchmark of the scan over 10 242 Bullet nodes on
// the 2-core VM: 0 → 10.1, 8 → 8.4, 16 → 5.8, 64 → 5.9 ns per node).
constexpr int kScanPrefetchAhead = 16;

Eigen::Vector3d to_eigen(const btVector3& v) { return {v.x(), v.y(), v.z()}; }

// A double bound rounded outwards to Bullet's float, so that a float position on the boundary is
// never lost to rounding.
float float_below(double v) { return std::nextafter(static_cast<float>(v), -std::numeric_limits<float>::infinity()); }
float float_above(double v) { return std::nextafter(static_cast<float>(v), std::numeric_limits<float>::infinity()); }

// The solver's whole-body bounds meet a world box.
bool body_meets(const SoftNodeBounds& bounds, const Eigen::AlignedBox3d& box_world) {
  return bounds.all_lo.x() <= float_above(box_world.max().x()) && bounds.all_hi.x() >= float_below(box_world.min().x()) &&
         bounds.all_lo.y() <= float_above(box_world.max().y()) && bounds.all_hi.y() >= float_below(box_world.min().y()) &&
         bounds.all_lo.z() <= float_above(box_world.max().z()) && bounds.all_hi.z() >= float_below(box_world.min().z());
}

Eigen::AlignedBox3d grown(const Eigen::AlignedBox3d& box, double by_m) {
  return {box.min() - Eigen::Vector3d::Constant(by_m), box.max() + Eigen::Vector3d::Constant(by_m)};
}

// World bounds of a tool-frame box at the previous and the current pose.
Eigen::AlignedBox3d swept_world(const StepFrame& frame, const Eigen::AlignedBox3d& box_tool) {
  Eigen::AlignedBox3d out;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d p = box_tool.corner(static_cast<Eigen::AlignedBox3d::CornerType>(corner));
    out.extend(frame.r_prev * p + frame.t_prev);
    out.extend(frame.r_cur * p + frame.t_cur);
  }
  return out;
}

// The queries of one step (see the header comment).
struct Query {
  Eigen::AlignedBox3d near_tool;      // tool frame: tool bounds + near_pad
  Eigen::AlignedBox3d release_tool;   // tool frame: tool bounds + release pad (nodes held last step)
  Eigen::AlignedBox3d memory_tool;    // tool frame: last step's contact nodes + memory_pad (may be empty)
  // World: the swept near / memory boxes (their union). A needed face's own start/end world box
  // meets it, and every face lies inside the bounds of all the nodes: a body whose node bounds
  // miss this box has no face to collect (the whole-body test of the solver's bounds).
  Eigen::AlignedBox3d faces_world;
  // World: the seed boxes of the near and of the memory query — each swept box grown by the
  // longest (stretched) edge and cut back to the swept box on the side the soft body lies (see
  // seed_box()) — and their union (the scan's first test). Kept apart: a plate held on a ball
  // has a memory query a few mm round its contact patch, and the union's box would take the
  // memory query's depth under the whole plate.
  Eigen::AlignedBox3d near_seed_world;
  Eigen::AlignedBox3d memory_seed_world;  // may be empty
  Eigen::AlignedBox3d any_seed_world;

  bool face_needed(const Eigen::AlignedBox3d& face_tool) const {
    return face_tool.intersects(near_tool) || (!memory_tool.isEmpty() && face_tool.intersects(memory_tool));
  }
  bool seed(const Eigen::AlignedBox3d& node_world) const {
    return node_world.intersects(near_seed_world) || (!memory_seed_world.isEmpty() && node_world.intersects(memory_seed_world));
  }
};

// A soft triangle can cross the padded region with every vertex outside it, so faces are reached
// through seeds further out: every vertex of a triangle lies within its longest edge of every
// other point of it, and an edge is allowed to stretch to kStretchAllowance times its rest
// length (for a face's start and its end triangle alike, so a face's start/end box lies within
// that much of each of its vertices' own start/end boxes).
constexpr double kStretchAllowance = 2.0;
double seed_reach_m(const CollisionModel& model) { return kStretchAllowance * model.soft.max_rest_edge_m; }

double near_pad_m(const CollisionModel& model) { return model.near_pad_m; }
double release_pad_m(const CollisionModel& model) { return std::max(model.params.contact_distance_m, model.params.release_distance_m) + model.params.skin_m; }
double memory_pad_m(const CollisionModel& model) { return model.memory_depth_m + model.params.contact_distance_m; }

// Tool-frame straight lines are not straight in the world when the tool turns within the step: a
// point of the relative path lies within ¼·θ·|relative move| of the world segment (θ = the step's
// rotation angle); the relative move is bounded by the translation plus the query's size (+ reach).
double rotation_slack_m(const CollisionModel& model, const StepFrame& frame, double query_size_m) {
  const double angle = frame.angular_velocity_world.norm() * frame.dt_s;
  return 0.25 * angle * ((frame.t_cur - frame.t_prev).norm() + query_size_m + 2.0 * seed_reach_m(model));
}

// The seed box of a query. A needed face F meets the query's swept box Q, so on every axis k F's highest vertex box
// reaches Q.min_k and its lowest reaches down to Q.max_k — and each vertex box lies within the
// reach of F. So the seeds may be cut on ANY one side without losing a needed face: on the side
// the soft body lies, the band of nodes under a plate pressed into it (most of the reach band:
// bench collision's 20 480-face same contact, 247 seeds for 24 candidate faces) is not read.
// Which side: the one the body's rest bounds extend furthest beyond Q (any choice is exact; this
// one is the same on every path, whatever the current positions).
Eigen::AlignedBox3d seed_box(const CollisionModel& model, const Eigen::AlignedBox3d& query_world, const Eigen::AlignedBox3d& grown_world) {
  Eigen::AlignedBox3d seed = grown_world;
  const Eigen::AlignedBox3d& body = model.soft.rest_bounds_world_m;
  if (body.isEmpty()) return seed;
  int best_axis = -1;
  bool best_below = false;
  double best_m = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double below_m = query_world.min()[k] - body.min()[k];
    const double above_m = body.max()[k] - query_world.max()[k];
    if (below_m > best_m) best_m = below_m, best_axis = k, best_below = true;
    if (above_m > best_m) best_m = above_m, best_axis = k, best_below = false;
  }
  if (best_axis < 0) return seed;
  if (best_below) {
    seed.min()[best_axis] = std::min(seed.max()[best_axis], query_world.min()[best_axis]);
  } else {
    seed.max()[best_axis] = std::max(seed.min()[best_axis], query_world.max()[best_axis]);
  }
  return seed;
}

Query make_query(const CollisionModel& model, const StepFrame& frame, const CollisionData& data) {
  const double near_pad = near_pad_m(model);
  const double memory_pad = memory_pad_m(model);
  const double reach = seed_reach_m(model);

  Query q;
  const auto& positions = model.tool.positions_tool_m();
  q.near_tool = grown(model.tool.bounds_tool_m(), near_pad);
  q.release_tool = grown(model.tool.bounds_tool_m(), release_pad_m(model));
  for (const int node : data.sweep.contact_nodes)
    if (data.sweep.node_face[static_cast<std::size_t>(node)] >= 0) q.memory_tool.extend(positions[static_cast<std::size_t>(node)]);
  if (!q.memory_tool.isEmpty()) q.memory_tool = grown(q.memory_tool, memory_pad);
  // The padded tool-frame boxes are transformed corner by corner, so their world bounds hold the
  // pads whatever the orientation.
  const auto world_of = [&](const Eigen::AlignedBox3d& box_tool, double reach_m) {
    const Eigen::AlignedBox3d world = swept_world(frame, box_tool);
    return grown(world, reach_m + rotation_slack_m(model, frame, world.sizes().norm()));
  };
  q.faces_world = world_of(q.near_tool, 0.0);
  q.near_seed_world = seed_box(model, q.faces_world, world_of(q.near_tool, reach));
  q.any_seed_world = q.near_seed_world;
  if (!q.memory_tool.isEmpty()) {
    const Eigen::AlignedBox3d memory_world = world_of(q.memory_tool, 0.0);
    q.faces_world.extend(memory_world);
    q.memory_seed_world = seed_box(model, memory_world, world_of(q.memory_tool, reach));
    q.any_seed_world.extend(q.memory_seed_world);
  }
  return q;
}

// A world box carried into the tool frame at the previous / current pose (Arvo, "Transforming
// axis-aligned bounding boxes", Graphics Gems 1990): the centre by Rᵀ, the half-sizes by |Rᵀ|.
// Every point of the world box lands inside the result; for a tool whose axes are the world's (or
// a signed permutation of them) the result is the bounds of the transformed box. In Bullet's
// single precision with SIMD btVector3 (the pre-filter runs on every face of the band): each
// result is grown by kFloatSlack times the magnitudes involved, which bounds the float rounding
// (≤ ~20 ε ≈ 1.2e-6 of them, ε = 2⁻²⁴), so the box still holds every double-precision position
// the exact test computes.
class ToolFrameBounds {
 public:
  explicit ToolFrameBounds(const StepFrame& frame)
      : prev_(frame.r_prev, frame.t_prev), cur_(frame.r_cur, frame.t_cur) {}

  struct Box {
    btVector3 lo, hi;
  };
  Box start(const btVector3& lo, const btVector3& hi) const { return prev_.carried(lo, hi); }
  Box end(const btVector3& lo, const btVector3& hi) const { return cur_.carried(lo, hi); }

 private:
  static constexpr btScalar kFloatSlack = 1e-5f;

  struct Pose {
    btVector3 rt_col[3], abs_rt_col[3], t;  // columns of Rᵀ and |Rᵀ|; the origin
    btScalar t_magnitude;
    Pose(const Eigen::Matrix3d& r, const Eigen::Vector3d& origin) {
      for (int c = 0; c < 3; ++c) {
        // Column c of Rᵀ is row c of R.
        rt_col[c] = btVector3(static_cast<btScalar>(r(c, 0)), static_cast<btScalar>(r(c, 1)), static_cast<btScalar>(r(c, 2)));
        abs_rt_col[c] = rt_col[c].absolute();
      }
      t = btVector3(static_cast<btScalar>(origin.x()), static_cast<btScalar>(origin.y()), static_cast<btScalar>(origin.z()));
      t_magnitude = static_cast<btScalar>(origin.cwiseAbs().maxCoeff());
    }
    Box carried(const btVector3& lo, const btVector3& hi) const {
      const btVector3 centre = (lo + hi) * btScalar(0.5) - t;
      const btVector3 half = (hi - lo) * btScalar(0.5);
      const btVector3 c = rt_col[0] * centre.x() + rt_col[1] * centre.y() + rt_col[2] * centre.z();
      const btVector3 magnitude_lo = lo.absolute(), magnitude_hi = hi.absolute();
      const btScalar magnitude = std::max(magnitude_lo[magnitude_lo.maxAxis()], magnitude_hi[magnitude_hi.maxAxis()]) + t_magnitude;
      const btScalar slack = kFloatSlack * magnitude;
      const btVector3 h = abs_rt_col[0] * half.x() + abs_rt_col[1] * half.y() + abs_rt_col[2] * half.z() + btVector3(slack, slack, slack);
      return {c - h, c + h};
    }
  };
  Pose prev_, cur_;
};

// A tool-frame query box in float, rounded outwards (the pre-filter compares float boxes).
struct FloatBox {
  btVector3 lo, hi;
  bool empty = true;
  static FloatBox of(const Eigen::AlignedBox3d& box) {
    FloatBox out;
    if (box.isEmpty()) return out;
    out.lo = btVector3(float_below(box.min().x()), float_below(box.min().y()), float_below(box.min().z()));
    out.hi = btVector3(float_above(box.max().x()), float_above(box.max().y()), float_above(box.max().z()));
    out.empty = false;
    return out;
  }
  bool meets(const btVector3& lo_other, const btVector3& hi_other) const {
    return !empty && lo_other.x() <= hi.x() && lo_other.y() <= hi.y() && lo_other.z() <= hi.z() && hi_other.x() >= lo.x() &&
           hi_other.y() >= lo.y() && hi_other.z() >= lo.z();
  }
};

class Collector {
 public:
  Collector(const CollisionModel& model, const StepFrame& frame, const btSoftBody& soft, const Query& query, CollisionData& data)
      : model_(model), frame_(frame), soft_(soft), query_(query), data_(data), bounds_(frame),
        near_(FloatBox::of(query.near_tool)), memory_(FloatBox::of(query.memory_tool)), release_(FloatBox::of(query.release_tool)) {}

  // A seed: a node whose own start/end box meets a seed box (every face around it is reached).
  bool is_seed(int node) const {
    const btSoftBody::Node& n = soft_.m_nodes[node];
    Eigen::AlignedBox3d box(to_eigen(n.m_x));
    box.extend(to_eigen(n.m_q));
    return query_.seed(box);
  }

  // A node of no face (a volume's interior: an FEM body's nodes inside its boundary triangles) is
  // reached by no face, so it is a candidate on its own when its start/end box meets the face
  // query: the response then keeps it out of the tool as it keeps a surface node (a tool that
  // crosses a whole cell in one step passes the interior node the surface contact does not hold).
  void take_faceless(int node) {
    const auto n = static_cast<std::size_t>(node);
    if (model_.soft.faces_of_node_begin[n] != model_.soft.faces_of_node_begin[n + 1]) return;
    if (data_.broad.listed_stamp[n] == frame_.step) return;
    transform(node);
    Eigen::AlignedBox3d box_tool(data_.broad.start_tool_m[n]);
    box_tool.extend(data_.broad.end_tool_m[n]);
    if (!query_.face_needed(box_tool)) return;
    data_.broad.listed_stamp[n] = frame_.step;
    data_.broad.candidate_nodes.push_back(node);
  }

  // Every face around a seed or around last step's candidate (whatever its leaf says), once a step.
  void reach_faces_around(int node) {
    const auto n = static_cast<std::size_t>(node);
    for (int k = model_.soft.faces_of_node_begin[n]; k < model_.soft.faces_of_node_begin[n + 1]; ++k)
      prefilter_face(model_.soft.faces_of_node[static_cast<std::size_t>(k)]);
  }

  // The exact test of every face the pre-filter kept, in the order they were reached.
  void test_kept_faces() {
    for (const int face : data_.broad.faces_kept) test_face(face);
  }

 private:

  // Each face once a step: kept for the exact test unless its vertices' world bounds, carried
  // into the tool frame, keep it away from every query (header comment, 3.). It reads only
  // Bullet's node positions: no transform, no stamp.
  void prefilter_face(int face) {
    const auto f = static_cast<std::size_t>(face);
    if (data_.broad.face_candidate_stamp[f] == frame_.step) return;
    data_.broad.face_candidate_stamp[f] = frame_.step;
    ++data_.broad.faces_tested;
    const std::array<int, 3>& v = model_.soft.face_nodes[f];
    const btSoftBody::Node& a = soft_.m_nodes[v[0]];
    const btSoftBody::Node& b = soft_.m_nodes[v[1]];
    const btSoftBody::Node& c = soft_.m_nodes[v[2]];
    btVector3 q_lo = a.m_q, q_hi = a.m_q, x_lo = a.m_x, x_hi = a.m_x;
    q_lo.setMin(b.m_q), q_lo.setMin(c.m_q), q_hi.setMax(b.m_q), q_hi.setMax(c.m_q);
    x_lo.setMin(b.m_x), x_lo.setMin(c.m_x), x_hi.setMax(b.m_x), x_hi.setMax(c.m_x);
    const ToolFrameBounds::Box end_tool = bounds_.end(x_lo, x_hi);
    ToolFrameBounds::Box box_tool = bounds_.start(q_lo, q_hi);
    box_tool.lo.setMin(end_tool.lo);
    box_tool.hi.setMax(end_tool.hi);
    // The held-vertex band: its end position lies in end_tool, so a vertex inside release_tool
    // needs end_tool to meet it; the hold stamps are read only then.
    if (near_.meets(box_tool.lo, box_tool.hi) || memory_.meets(box_tool.lo, box_tool.hi) ||
        (release_.meets(end_tool.lo, end_tool.hi) && has_vertex_held_last_step(f)))
      data_.broad.faces_kept.push_back(face);
  }

  bool has_vertex_held_last_step(std::size_t face) const {
    for (const int vertex : model_.soft.face_nodes[face])
      if (data_.displacement.hold_stamp[static_cast<std::size_t>(vertex)] == frame_.step - 1) return true;
    return false;
  }

  void transform(int node) {
    const auto i = static_cast<std::size_t>(node);
    if (data_.broad.soft_stamp[i] == frame_.step) return;
    data_.broad.soft_stamp[i] = frame_.step;
    const btSoftBody::Node& n = soft_.m_nodes[node];
    data_.broad.start_tool_m[i] = frame_.r_prev.transpose() * (to_eigen(n.m_q) - frame_.t_prev);
    data_.broad.end_tool_m[i] = frame_.r_cur.transpose() * (to_eigen(n.m_x) - frame_.t_cur);
  }

  // A vertex held on a tool face last step and still within the release pad of the tool.
  bool has_held_vertex_in_reach(std::size_t face) const {
    for (const int vertex : model_.soft.face_nodes[face]) {
      const auto v = static_cast<std::size_t>(vertex);
      if (data_.displacement.hold_stamp[v] == frame_.step - 1 && query_.release_tool.contains(data_.broad.end_tool_m[v])) return true;
    }
    return false;
  }

  // The exact test: the face's tool-frame start/end bounds against the queries.
  void test_face(int face) {
    const auto f = static_cast<std::size_t>(face);
    ++data_.broad.faces_transformed;
    Eigen::AlignedBox3d box_tool;
    for (const int vertex : model_.soft.face_nodes[f]) {
      transform(vertex);
      box_tool.extend(data_.broad.start_tool_m[static_cast<std::size_t>(vertex)]);
      box_tool.extend(data_.broad.end_tool_m[static_cast<std::size_t>(vertex)]);
    }
    if (!query_.face_needed(box_tool) && !has_held_vertex_in_reach(f)) return;
    data_.broad.candidate_faces.push_back(face);
    for (const int vertex : model_.soft.face_nodes[f]) {
      const auto v = static_cast<std::size_t>(vertex);
      if (data_.broad.listed_stamp[v] == frame_.step) continue;
      data_.broad.listed_stamp[v] = frame_.step;
      data_.broad.candidate_nodes.push_back(vertex);
    }
  }

  const CollisionModel& model_;
  const StepFrame& frame_;
  const btSoftBody& soft_;
  const Query& query_;
  CollisionData& data_;
  const ToolFrameBounds bounds_;
  const FloatBox near_, memory_, release_;  // query_'s tool-frame boxes in float, rounded outwards
};

// GCC deletes a loop whose body only prefetches (-ffinite-loops, on by default for C++ at -O2:
// __builtin_prefetch has no side effect, so such a loop counts as doing nothing): objdump showed
// the staged prefetches below compiled to no instruction at all before this. The empty volatile
// asm is a side effect the optimiser must keep, so the loops and their prefetches stay.
inline void prefetch(const void* address) {
  __builtin_prefetch(address);
  asm volatile("");
}

// The three dependent levels of data the pre-filter reads, one level at a time for all nodes.
void prefetch_faces_around(const CollisionModel& model, const btSoftBody& soft, const CollisionData& data, const std::vector<int>& nodes) {
  const SoftSurfaceModel& surface = model.soft;
  for (const int node : nodes) prefetch(&surface.faces_of_node_begin[static_cast<std::size_t>(node)]);
  for (const int node : nodes) {
    const auto n = static_cast<std::size_t>(node);
    if (surface.faces_of_node_begin[n] < surface.faces_of_node_begin[n + 1])
      prefetch(&surface.faces_of_node[static_cast<std::size_t>(surface.faces_of_node_begin[n])]);
  }
  for (const int node : nodes) {
    const auto n = static_cast<std::size_t>(node);
    for (int k = surface.faces_of_node_begin[n]; k < surface.faces_of_node_begin[n + 1]; ++k) {
      const auto f = static_cast<std::size_t>(surface.faces_of_node[static_cast<std::size_t>(k)]);
      prefetch(&surface.face_nodes[f]);
      prefetch(&data.broad.face_candidate_stamp[f]);
    }
  }
  for (const int node : nodes) {
    const auto n = static_cast<std::size_t>(node);
    for (int k = surface.faces_of_node_begin[n]; k < surface.faces_of_node_begin[n + 1]; ++k) {
      for (const int vertex : surface.face_nodes[static_cast<std::size_t>(surface.faces_of_node[static_cast<std::size_t>(k)])]) {
        // m_x and m_q are 16 bytes apart but may straddle a cache line (they do on the bench's
        // 20 480-face sphere: m_x at 48 mod 64).
        prefetch(&soft.m_nodes[vertex].m_x);
        prefetch(&soft.m_nodes[vertex].m_q);
      }
    }
  }
}

// What the exact test reads and writes for the vertices of the faces the pre-filter kept.
void prefetch_kept_faces(const CollisionModel& model, const CollisionData& data) {
  for (const int face : data.broad.faces_kept) {
    for (const int vertex : model.soft.face_nodes[static_cast<std::size_t>(face)]) {
      const auto v = static_cast<std::size_t>(vertex);
      prefetch(&data.broad.soft_stamp[v]);
      prefetch(&data.broad.start_tool_m[v]);
      prefetch(&data.broad.end_tool_m[v]);
      prefetch(&data.displacement.hold_stamp[v]);
      prefetch(&data.broad.listed_stamp[v]);
    }
  }
}

// What a broad phase that found nothing leaves: no candidates, no work counted.
void clear_step_results(CollisionData& data) {
  data.broad.candidate_nodes.clear();
  data.broad.candidate_faces.clear();
  data.broad.nodes_scanned = 0;
  data.broad.seed_nodes = 0;
  data.broad.faces_tested = 0;
  data.broad.faces_transformed = 0;
}

}  // namespace

bool broad_phase_out_of_reach(const CollisionModel& model, const ToolPose& previous, const ToolPose& current,
                              const SoftNodeBounds* node_bounds, CollisionData& data) {
  if (node_bounds == nullptr || !node_bounds->valid || node_bounds->node_count != model.soft.node_count) return false;
  // The padded tool box's bounding sphere at both poses: its swept box holds every corner of the
  // box at either pose, so it holds Query::faces_world's swept near box; the rotation slack is
  // bounded with that box's size (|centre move| + 2√3·radius) and the turn θ from the quaternions,
  // θ ≤ π·sin(θ/2) = π·√(1 − (q₀·q₁)²) (no acos: after Bullet's step even libm's code is cold).
  const Eigen::Vector3d& centre_tool = model.near_sphere_centre_tool_m;
  const double radius_m = model.near_sphere_radius_m;
  const Eigen::Vector3d centre_prev = previous.orientation_world * centre_tool + previous.position_world_m;
  const Eigen::Vector3d centre_cur = current.orientation_world * centre_tool + current.position_world_m;
  const double cos_half = std::min(1.0, std::abs(previous.orientation_world.normalized().dot(current.orientation_world.normalized())));
  const double angle = 3.14159265358979323846 * std::sqrt(1.0 - cos_half * cos_half);
  const double move_m = (current.position_world_m - previous.position_world_m).norm();
  const double slack_m =
      0.25 * angle * (move_m + (centre_cur - centre_prev).norm() + 2.0 * std::sqrt(3.0) * radius_m + 2.0 * seed_reach_m(model));
  Eigen::AlignedBox3d box(centre_prev);
  box.extend(centre_cur);
  if (body_meets(*node_bounds, grown(box, radius_m + slack_m))) return false;
  clear_step_results(data);
  return true;
}

bool broad_phase(const CollisionModel& model, const StepFrame& frame, const btSoftBody& soft, CollisionData& data,
                 const SoftNodeBounds* node_bounds) {
  if (data.broad.listed_stamp.size() != static_cast<std::size_t>(model.soft.node_count)) {
    // First call: size the broad phase's own buffers (the step allocates nothing afterwards).
    data.broad.listed_stamp.assign(static_cast<std::size_t>(model.soft.node_count), -1);
    data.broad.previous_candidates.clear();
    data.broad.previous_candidates.reserve(static_cast<std::size_t>(model.soft.node_count));
    data.broad.candidate_nodes.reserve(static_cast<std::size_t>(model.soft.node_count));
    data.broad.scan_hits.reserve(static_cast<std::size_t>(model.soft.node_count));
    data.broad.faces_kept.reserve(static_cast<std::size_t>(model.soft.face_count));
  }
  data.broad.candidate_nodes.swap(data.broad.previous_candidates);
  clear_step_results(data);
  data.broad.faces_kept.clear();

  const Query query = make_query(model, frame, data);
  const bool bounds_usable = node_bounds != nullptr && node_bounds->valid && node_bounds->node_count == model.soft.node_count;
  // Out of contact — nothing carried from last step and the body's bounds away from the tool: no
  // face can be needed (Query::faces_world), and nothing else is touched. That matters: after
  // Bullet's step this stage's code and data are cold, and its remaining setup and empty loops
  // cost ~3 µs of cache misses doing nothing (measured on bench collision's 20 480-face sphere).
  if (bounds_usable && data.broad.previous_candidates.empty() && !body_meets(*node_bounds, query.faces_world)) {
    data.broad.scan_hits.clear();
    return false;
  }
  Collector collect(model, frame, soft, query, data);

  // The scan (see the header comment), in Bullet's single precision against the union of the
  // seed boxes rounded outwards.
  const Eigen::AlignedBox3d& any = query.any_seed_world;
  const float lo_x = float_below(any.min().x()), lo_y = float_below(any.min().y()), lo_z = float_below(any.min().z());
  const float hi_x = float_above(any.max().x()), hi_y = float_above(any.max().y()), hi_z = float_above(any.max().z());
  const int count = model.soft.node_count;
  data.broad.scan_hits.clear();
  int scanned = 0;
  // Nodes [first, last): the union box test on each, in memory order.
  const auto scan = [&](int first, int last) {
    for (int i = first; i < last; ++i) {
      // Nodes are 256 bytes apart: a software prefetch this far ahead keeps enough misses in flight
      // (measured on the 10 242-node sphere: 10 ns per node without it, 6 with it). m_x and m_q
      // straddle a cache line when the node array sits at 32 mod 64 (m_x at 48 mod 64 on the bench's
      // 20 480-face sphere): both lines are prefetched.
      if (i + kScanPrefetchAhead < last) {
        __builtin_prefetch(&soft.m_nodes[i + kScanPrefetchAhead].m_x);
        __builtin_prefetch(&soft.m_nodes[i + kScanPrefetchAhead].m_q);
      }
      const btVector3& x = soft.m_nodes[i].m_x;
      const btVector3& q = soft.m_nodes[i].m_q;
      // Six independent compares and one branch (taken only near the tool).
      const bool near = (std::min(x.x(), q.x()) <= hi_x) & (std::max(x.x(), q.x()) >= lo_x) & (std::min(x.y(), q.y()) <= hi_y) &
                        (std::max(x.y(), q.y()) >= lo_y) & (std::min(x.z(), q.z()) <= hi_z) & (std::max(x.z(), q.z()) >= lo_z);
      if (near) data.broad.scan_hits.push_back(i);
    }
    scanned += last - first;
  };
  if (bounds_usable) {
    // The solver's bounds of this step (node_bounds_solver.hpp): the whole body against the query
    // without the seed reach, then only the blocks of nodes whose box meets the seed boxes' union (the
    // same test on a box: a node passing it lies in a block that passes it too).
    if (body_meets(*node_bounds, query.faces_world)) {
      constexpr int kBlock = SoftNodeBounds::kNodesPerBlock;
      for (int b = 0; b < node_bounds->block_count(); ++b) {
        const btVector3& lo = node_bounds->block_lo[static_cast<std::size_t>(b)];
        const btVector3& hi = node_bounds->block_hi[static_cast<std::size_t>(b)];
        if (lo.x() <= hi_x && hi.x() >= lo_x && lo.y() <= hi_y && hi.y() >= lo_y && lo.z() <= hi_z && hi.z() >= lo_z)
          scan(b * kBlock, std::min(count, (b + 1) * kBlock));
      }
    }
  } else {
    scan(0, count);
  }
  data.broad.nodes_scanned = scanned;
  // Everything the faces around these nodes read is cold after Bullet's step (a few thousand
  // misses on the finest mesh, ~60 µs when taken one after another): it is prefetched in stages,
  // each stage's misses in flight together, before the faces are reached in the usual order.
  // Only the seeds' faces: the scan's union box also takes in nodes between the near and the
  // memory query.
  std::size_t seeds = 0;
  for (const int node : data.broad.scan_hits)
    if (collect.is_seed(node)) data.broad.scan_hits[seeds++] = node;
  data.broad.scan_hits.resize(seeds);
  data.broad.seed_nodes = static_cast<int>(seeds);
  prefetch_faces_around(model, soft, data, data.broad.previous_candidates);
  prefetch_faces_around(model, soft, data, data.broad.scan_hits);
  for (const int node : data.broad.previous_candidates) collect.reach_faces_around(node);
  for (const int node : data.broad.scan_hits) collect.reach_faces_around(node);
  // The exact test, in the order the faces were reached.
  prefetch_kept_faces(model, data);
  collect.test_kept_faces();
  if (model.soft.has_faceless_nodes) {
    for (const int node : data.broad.previous_candidates) collect.take_faceless(node);
    for (const int node : data.broad.scan_hits) collect.take_faceless(node);
  }
  // A canonical order for the later stages: the node sweep gives a tool node to the FIRST of
  // several triangles it touches at the same moment (a held node: τ = 1 on each), so the
  // traversal order would otherwise decide contacts (clamp scenes: ±25 % peak force between two
  // orders). Face index order does not depend on how the faces were reached.
  std::sort(data.broad.candidate_faces.begin(), data.broad.candidate_faces.end());
  // And the candidate nodes in index order: the response visits them in this order and the
  // first moved node round a face gives it its force plane, so the order the faces were reached
  // in (which depends on the seeds) would otherwise reach the force — and, through a haptic
  // loop, the trajectory.
  std::sort(data.broad.candidate_nodes.begin(), data.broad.candidate_nodes.end());
  return !data.broad.candidate_faces.empty();
}

}  // namespace fissure::host::thin_body
