// Stage 1: broad phase. The tool's bounds swept from the previous to the current pose are tested
// against the soft body's node tree (btSoftBody::m_ndbvt, refreshed by Bullet every step). Out of
// contact this is one box test at the tree root and nothing else runs (BRIEF §3 item 6). In
// contact, the tree gives the soft nodes near the tool, so the cost follows the contact patch and
// not the mesh size.
#include "collision_state.hpp"

#include <BulletCollision/BroadphaseCollision/btDbvt.h>
#include <BulletSoftBody/btSoftBody.h>

namespace fissure::host::thin_body {
namespace {

bool overlaps(const btDbvtVolume& volume, const Eigen::AlignedBox3d& box) {
  const btVector3& lo = volume.Mins();
  const btVector3& hi = volume.Maxs();
  return lo.x() <= box.max().x() && hi.x() >= box.min().x() && lo.y() <= box.max().y() && hi.y() >= box.min().y() &&
         lo.z() <= box.max().z() && hi.z() >= box.min().z();
}

bool contains(const Eigen::AlignedBox3d& box, const btVector3& p) {
  return p.x() >= box.min().x() && p.x() <= box.max().x() && p.y() >= box.min().y() && p.y() <= box.max().y() &&
         p.z() >= box.min().z() && p.z() <= box.max().z();
}

void add_soft_node(const StepFrame& frame, const btSoftBody& soft, int index, CollisionData& data) {
  const auto i = static_cast<std::size_t>(index);
  if (data.soft_stamp[i] == frame.step) return;
  data.soft_stamp[i] = frame.step;
  const btVector3& q = soft.m_nodes[index].m_q;  // start of this step (Bullet's predictMotion)
  const btVector3& x = soft.m_nodes[index].m_x;
  data.start_tool_m[i] = frame.r_prev.transpose() * (Eigen::Vector3d(q.x(), q.y(), q.z()) - frame.t_prev);
  data.end_tool_m[i] = frame.r_cur.transpose() * (Eigen::Vector3d(x.x(), x.y(), x.z()) - frame.t_cur);
  data.candidate_nodes.push_back(index);
}

// Whether a triangle around a candidate node has bounds (over the step) overlapping the swept box.
bool any_face_spans(const CollisionModel& model, const btSoftBody& soft, const Eigen::AlignedBox3d& swept,
                    const CollisionData& data) {
  for (const int node : data.candidate_nodes) {
    for (int k = model.soft.faces_of_node_begin[static_cast<std::size_t>(node)];
         k < model.soft.faces_of_node_begin[static_cast<std::size_t>(node + 1)]; ++k) {
      Eigen::AlignedBox3d face_box;
      for (const int vertex : model.soft.face_nodes[static_cast<std::size_t>(model.soft.faces_of_node[static_cast<std::size_t>(k)])]) {
        const btSoftBody::Node& n = soft.m_nodes[vertex];
        face_box.extend(Eigen::Vector3d(n.m_x.x(), n.m_x.y(), n.m_x.z()));
        face_box.extend(Eigen::Vector3d(n.m_q.x(), n.m_q.y(), n.m_q.z()));
      }
      if (face_box.intersects(swept)) return true;
    }
  }
  return false;
}

}  // namespace

bool broad_phase(const CollisionModel& model, const StepFrame& frame, const btSoftBody& soft, CollisionData& data) {
  data.candidate_nodes.clear();
  data.candidate_faces.clear();
  const double margin = model.params.broad_phase_margin_m;
  const Eigen::AlignedBox3d swept(frame.swept_tool_world_m.min() - Eigen::Vector3d::Constant(margin),
                                  frame.swept_tool_world_m.max() + Eigen::Vector3d::Constant(margin));
  const btDbvtNode* root = soft.m_ndbvt.m_root;
  // Soft triangles larger than the tool can cross its bounds with every vertex outside them:
  // query the nodes within two rest edge lengths (stretch allowance) of the swept bounds.
  const double reach = 2.0 * model.soft.max_rest_edge_m;
  const Eigen::AlignedBox3d query(swept.min() - Eigen::Vector3d::Constant(reach),
                                  swept.max() + Eigen::Vector3d::Constant(reach));
  if (root != nullptr) {
    if (!overlaps(root->volume, swept)) return false;
    data.tree_stack.clear();
    data.tree_stack.push_back(root);
    while (!data.tree_stack.empty()) {
      const btDbvtNode* node = data.tree_stack.back();
      data.tree_stack.pop_back();
      if (!overlaps(node->volume, query)) continue;
      if (node->isinternal()) {
        data.tree_stack.push_back(node->childs[0]);
        data.tree_stack.push_back(node->childs[1]);
      } else {
        // Leaf volumes are loose (collision margin, velocity expansion, never shrunk while the
        // node stays inside): the node's actual position decides.
        const auto* soft_node = static_cast<const btSoftBody::Node*>(node->data);
        if (contains(query, soft_node->m_x) || contains(query, soft_node->m_q))
          add_soft_node(frame, soft, static_cast<int>(soft_node - &soft.m_nodes[0]), data);
      }
    }
  } else {
    // No node tree (a body Bullet never stepped): fall back to a scan of the nodes.
    Eigen::AlignedBox3d bounds;
    for (int i = 0; i < model.soft.node_count; ++i) {
      const btVector3& x = soft.m_nodes[i].m_x;
      bounds.extend(Eigen::Vector3d(x.x(), x.y(), x.z()));
    }
    if (!bounds.intersects(swept)) return false;
    for (int i = 0; i < model.soft.node_count; ++i) {
      if (contains(query, soft.m_nodes[i].m_x) || contains(query, soft.m_nodes[i].m_q)) add_soft_node(frame, soft, i, data);
    }
  }
  // The query reached out by two soft edge lengths (for large triangles); a soft node actually
  // within the swept bounds, or a triangle spanning them, is needed for contact.
  bool near = false;
  for (const int node : data.candidate_nodes) {
    const btSoftBody::Node& n = soft.m_nodes[node];
    if (contains(swept, n.m_x) || contains(swept, n.m_q)) {
      near = true;
      break;
    }
  }
  if (!near && !any_face_spans(model, soft, swept, data)) {
    data.candidate_nodes.clear();
    return false;
  }
  // Faces around the candidate nodes; their other vertices join the candidates.
  const std::size_t seed_count = data.candidate_nodes.size();
  for (std::size_t c = 0; c < seed_count; ++c) {
    const int node = data.candidate_nodes[c];
    for (int k = model.soft.faces_of_node_begin[static_cast<std::size_t>(node)];
         k < model.soft.faces_of_node_begin[static_cast<std::size_t>(node + 1)]; ++k) {
      const int face = model.soft.faces_of_node[static_cast<std::size_t>(k)];
      if (data.face_candidate_stamp[static_cast<std::size_t>(face)] == frame.step) continue;
      data.face_candidate_stamp[static_cast<std::size_t>(face)] = frame.step;
      data.candidate_faces.push_back(face);
      for (const int vertex : model.soft.face_nodes[static_cast<std::size_t>(face)])
        add_soft_node(frame, soft, vertex, data);
    }
  }
  return !data.candidate_nodes.empty();
}

}  // namespace fissure::host::thin_body
