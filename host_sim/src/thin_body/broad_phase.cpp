// Stage 1: broad phase (BRIEF §3 item 6: "broad phase on the swept tool bounds first, nothing when
// out of contact"). Its cost follows the contact patch, not the mesh: nothing here loops over all
// soft nodes or faces (except once, on the first call, to re-fit Bullet's leaves).
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
// force). Faces are reached through seed nodes:
//   1. Bullet's node tree (btSoftBody::m_ndbvt) walked with the world query box: the swept tool
//      bounds + pads + two rest edge lengths (a large triangle can cross the tool with all three
//      vertices outside it). Bullet re-fits each leaf around the node's PREDICTED position
//      (predictMotion) with the soft collision margin; the solver then moves the node a little:
//      the walk tests leaves against the query grown by broad_phase_margin_m (that correction
//      allowance), and each reached node's actual start/end box against the exact query;
//   2. the faces around last step's candidate nodes, re-tested directly whatever the leaves say:
//      the candidates include every node this collision moved (they carry the tool's velocity, so
//      Bullet predicts them centimetres from where its solver leaves them when the tool stops or
//      jumps — the stale leaves that once let a node tunnel in HostSimulation), and those faces
//      bring in their neighbours. Elsewhere the soft body moves by its own dynamics, which
//      Bullet's leaves follow (its own soft-rigid collision trusts them the same way).
// Out of contact: one test of the tree root, nothing else.
#include "collision_state.hpp"

#include <BulletCollision/BroadphaseCollision/btDbvt.h>
#include <BulletSoftBody/btSoftBody.h>

#include <algorithm>
#include <cmath>

namespace fissure::host::thin_body {
namespace {

Eigen::Vector3d to_eigen(const btVector3& v) { return {v.x(), v.y(), v.z()}; }

bool overlaps(const btDbvtVolume& volume, const Eigen::AlignedBox3d& box) {
  const btVector3& lo = volume.Mins();
  const btVector3& hi = volume.Maxs();
  return lo.x() <= box.max().x() && hi.x() >= box.min().x() && lo.y() <= box.max().y() && hi.y() >= box.min().y() &&
         lo.z() <= box.max().z() && hi.z() >= box.min().z();
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
  Eigen::AlignedBox3d near_world;     // world: seeds of near_tool faces (+ reach)
  Eigen::AlignedBox3d memory_world;   // world: seeds of memory_tool faces (+ reach; may be empty)
  // The same grown by broad_phase_margin_m for the tree walk: leaves may lag their node by that
  // much (the solver's correction after Bullet fitted them).
  Eigen::AlignedBox3d near_leaves;
  Eigen::AlignedBox3d memory_leaves;

  bool face_needed(const Eigen::AlignedBox3d& face_tool) const {
    return face_tool.intersects(near_tool) || (!memory_tool.isEmpty() && face_tool.intersects(memory_tool));
  }
  bool seed(const Eigen::AlignedBox3d& node_world) const {
    return node_world.intersects(near_world) || (!memory_world.isEmpty() && node_world.intersects(memory_world));
  }
  bool leaf_may_hold_seed(const btDbvtVolume& volume) const {
    return overlaps(volume, near_leaves) || (!memory_leaves.isEmpty() && overlaps(volume, memory_leaves));
  }
};

// A soft triangle can cross the padded region with every vertex outside it: seeds are taken this
// much further out. Every point of a triangle lies within (longest edge)/√3 of its nearest vertex
// (the circumradius bound of an acute triangle; half the longest edge for an obtuse one), and an
// edge is allowed to stretch to kStretchAllowance times its rest length.
constexpr double kStretchAllowance = 2.0;
double seed_reach_m(const CollisionModel& model) { return kStretchAllowance * model.soft.max_rest_edge_m / std::sqrt(3.0); }

double near_pad_m(const CollisionModel& model) { return model.params.contact_distance_m + model.params.skin_m; }
double release_pad_m(const CollisionModel& model) { return std::max(model.params.contact_distance_m, model.params.release_distance_m) + model.params.skin_m; }
double memory_pad_m(const CollisionModel& model) { return model.memory_depth_m + model.params.contact_distance_m; }

// Tool-frame straight lines are not straight in the world when the tool turns within the step: a
// point of the relative path lies within ¼·θ·|relative move| of the world segment (θ = the step's
// rotation angle); the relative move is bounded by the translation plus the query's size (+ reach).
double rotation_slack_m(const CollisionModel& model, const StepFrame& frame, double query_size_m) {
  const double angle = frame.angular_velocity_world.norm() * frame.dt_s;
  return 0.25 * angle * ((frame.t_cur - frame.t_prev).norm() + query_size_m + 2.0 * seed_reach_m(model));
}

Query make_query(const CollisionModel& model, const StepFrame& frame, const CollisionData& data) {
  const ThinBodyCollisionParams& p = model.params;
  const double near_pad = near_pad_m(model);
  const double memory_pad = memory_pad_m(model);
  const double reach = seed_reach_m(model);

  Query q;
  const auto& positions = model.tool.positions_tool_m();
  q.near_tool = grown(model.tool.bounds_tool_m(), near_pad);
  q.release_tool = grown(model.tool.bounds_tool_m(), release_pad_m(model));
  for (const int node : data.contact_nodes)
    if (data.node_face[static_cast<std::size_t>(node)] >= 0) q.memory_tool.extend(positions[static_cast<std::size_t>(node)]);
  if (!q.memory_tool.isEmpty()) q.memory_tool = grown(q.memory_tool, memory_pad);
  // The padded tool-frame boxes are transformed corner by corner, so their world bounds hold the
  // pads whatever the orientation.
  const auto world_of = [&](const Eigen::AlignedBox3d& box_tool) {
    const Eigen::AlignedBox3d world = swept_world(frame, box_tool);
    return grown(world, reach + rotation_slack_m(model, frame, world.sizes().norm()));
  };
  q.near_world = world_of(q.near_tool);
  q.near_leaves = grown(q.near_world, p.broad_phase_margin_m);
  if (!q.memory_tool.isEmpty()) {
    q.memory_world = world_of(q.memory_tool);
    q.memory_leaves = grown(q.memory_world, p.broad_phase_margin_m);
  }
  return q;
}

// Bullet inserts each leaf with the collision margin in force at creation (0.25 m by default,
// usually reduced afterwards) and never shrinks a leaf that still contains its node: once, re-fit
// every leaf to the body's margin, else the walk is 0.25 m loose. O(nodes), first call only.
void fit_leaves_once(btSoftBody& soft) {
  const btScalar margin = soft.getCollisionShape()->getMargin();
  for (int i = 0; i < soft.m_nodes.size(); ++i) {
    btSoftBody::Node& node = soft.m_nodes[i];
    if (node.m_leaf == nullptr) continue;
    btDbvtVolume merged;
    Merge(btDbvtVolume::FromCR(node.m_x, margin), btDbvtVolume::FromCR(node.m_q, margin), merged);
    soft.m_ndbvt.update(node.m_leaf, merged);
  }
}

class Collector {
 public:
  Collector(const CollisionModel& model, const StepFrame& frame, const btSoftBody& soft, const Query& query, CollisionData& data)
      : model_(model), frame_(frame), soft_(soft), query_(query), data_(data) {}

  // A node whose own start/end box meets the world query: test every face around it.
  void seed_if_near(int node) {
    const btSoftBody::Node& n = soft_.m_nodes[node];
    Eigen::AlignedBox3d box(to_eigen(n.m_x));
    box.extend(to_eigen(n.m_q));
    if (!query_.seed(box)) return;
    ++data_.broad_seed_nodes;
    test_faces_around(node);
  }

  void test_faces_around(int node) {
    const auto n = static_cast<std::size_t>(node);
    for (int k = model_.soft.faces_of_node_begin[n]; k < model_.soft.faces_of_node_begin[n + 1]; ++k)
      test_face(model_.soft.faces_of_node[static_cast<std::size_t>(k)]);
  }

  // Last step's candidate: every face around it, whatever its leaf says.
  void retest_previous(int node) { test_faces_around(node); }

 private:
  void transform(int node) {
    const auto i = static_cast<std::size_t>(node);
    if (data_.soft_stamp[i] == frame_.step) return;
    data_.soft_stamp[i] = frame_.step;
    const btSoftBody::Node& n = soft_.m_nodes[node];
    data_.start_tool_m[i] = frame_.r_prev.transpose() * (to_eigen(n.m_q) - frame_.t_prev);
    data_.end_tool_m[i] = frame_.r_cur.transpose() * (to_eigen(n.m_x) - frame_.t_cur);
  }

  // A vertex held on a tool face last step and still within the release pad of the tool.
  bool has_held_vertex_in_reach(std::size_t face) const {
    for (const int vertex : model_.soft.face_nodes[face]) {
      const auto v = static_cast<std::size_t>(vertex);
      if (data_.hold_stamp[v] == frame_.step - 1 && query_.release_tool.contains(data_.end_tool_m[v])) return true;
    }
    return false;
  }

  void test_face(int face) {
    const auto f = static_cast<std::size_t>(face);
    if (data_.face_candidate_stamp[f] == frame_.step) return;
    data_.face_candidate_stamp[f] = frame_.step;
    ++data_.broad_faces_tested;
    Eigen::AlignedBox3d box_tool;
    for (const int vertex : model_.soft.face_nodes[f]) {
      transform(vertex);
      box_tool.extend(data_.start_tool_m[static_cast<std::size_t>(vertex)]);
      box_tool.extend(data_.end_tool_m[static_cast<std::size_t>(vertex)]);
    }
    if (!query_.face_needed(box_tool) && !has_held_vertex_in_reach(f)) return;
    data_.candidate_faces.push_back(face);
    for (const int vertex : model_.soft.face_nodes[f]) {
      const auto v = static_cast<std::size_t>(vertex);
      if (data_.broad_listed_stamp[v] == frame_.step) continue;
      data_.broad_listed_stamp[v] = frame_.step;
      data_.candidate_nodes.push_back(vertex);
    }
  }

  const CollisionModel& model_;
  const StepFrame& frame_;
  const btSoftBody& soft_;
  const Query& query_;
  CollisionData& data_;
};

}  // namespace

bool broad_phase(const CollisionModel& model, const StepFrame& frame, btSoftBody& soft, CollisionData& data) {
  if (!data.broad_leaves_fitted) {
    // First call: size the broad phase's own buffers (the step allocates nothing afterwards).
    data.broad_listed_stamp.assign(static_cast<std::size_t>(model.soft.node_count), -1);
    data.broad_previous_candidates.clear();
    data.broad_previous_candidates.reserve(static_cast<std::size_t>(model.soft.node_count));
    data.candidate_nodes.reserve(static_cast<std::size_t>(model.soft.node_count));
    fit_leaves_once(soft);
    data.broad_leaves_fitted = true;
  }
  data.candidate_nodes.swap(data.broad_previous_candidates);
  data.candidate_nodes.clear();
  data.candidate_faces.clear();
  data.broad_tree_nodes_visited = 0;
  data.broad_seed_nodes = 0;
  data.broad_faces_tested = 0;

  // Out of contact: one root test against everything the query can reach (built below only when
  // it may be needed), and nothing else.
  const btDbvtNode* root = soft.m_ndbvt.m_root;
  if (root != nullptr && data.broad_previous_candidates.empty()) {
    // Both padded tool-frame boxes lie within the tool's bounds + the larger pad; rotated into the
    // world that is at most √3 × the pad more than the swept tool bounds on every side.
    const double pad_world = std::sqrt(3.0) * std::max(near_pad_m(model), memory_pad_m(model));
    const double size_m = frame.swept_tool_world_m.sizes().norm() + 2.0 * pad_world;
    const double reach_all = pad_world + seed_reach_m(model) + rotation_slack_m(model, frame, size_m) + model.params.broad_phase_margin_m;
    data.broad_tree_nodes_visited = 1;
    if (!overlaps(root->volume, grown(frame.swept_tool_world_m, reach_all))) return false;
  }
  const Query query = make_query(model, frame, data);
  Collector collect(model, frame, soft, query, data);
  for (const int node : data.broad_previous_candidates) collect.retest_previous(node);

  if (root != nullptr) {
    data.broad_tree_nodes_visited = 1;
    if (query.leaf_may_hold_seed(root->volume)) {
      // The walk runs right after Bullet's own step over the whole body, so the tree is cold in
      // the cache: both children are prefetched before either is tested (their misses overlap),
      // and a leaf's soft node as soon as the leaf is known to be near.
      data.tree_stack.clear();
      data.tree_stack.push_back(root);
      while (!data.tree_stack.empty()) {
        const btDbvtNode* node = data.tree_stack.back();
        data.tree_stack.pop_back();
        if (node->isleaf()) {
          const auto* soft_node = static_cast<const btSoftBody::Node*>(node->data);
          collect.seed_if_near(static_cast<int>(soft_node - &soft.m_nodes[0]));
          continue;
        }
        __builtin_prefetch(node->childs[0]);
        __builtin_prefetch(node->childs[1]);
        for (const btDbvtNode* child : node->childs) {
          ++data.broad_tree_nodes_visited;
          if (!query.leaf_may_hold_seed(child->volume)) continue;
          if (child->isleaf()) __builtin_prefetch(&static_cast<const btSoftBody::Node*>(child->data)->m_x);
          data.tree_stack.push_back(child);
        }
      }
    }
  } else {
    // No node tree (a body Bullet never stepped, or a solver without one): scan the nodes.
    for (int i = 0; i < model.soft.node_count; ++i) collect.seed_if_near(i);
  }
  return !data.candidate_faces.empty();
}

}  // namespace fissure::host::thin_body
