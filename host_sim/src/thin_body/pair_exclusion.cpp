// Stage 3: infeasible-pair exclusion (BRIEF §3 item 3; paper: "when a node belongs to an
// infeasible pair, the associated index is stored in a vector collecting all the indices of the
// nodes that cannot collide in the current simulation step. Thus, a cross-check is necessary at
// each step").
//
// Both nodes of a pair in contact means the soft surface is on both faces of a tool thinner than
// the step — only one face can be feasible: the one that LED. Leading is decided by
//   1. side memory: the node that has been in contact for more consecutive steps came first;
//   2. facing: the node whose face meets its triangle head-on (tool normal · soft normal most
//      negative) rather than from behind;
//   3. the earlier crossing within the step (τ);
//   4. the lower node index (determinism).
// Pairs from a convex mesh are not always mutual, so every node in contact is checked against
// its own pair AND against every node that chose it as a pair (ToolNodes::paired_by): the
// cross-check. The ray-only variant skips this stage (both faces push).
//
// Then every contacted soft face gets the tool plane of its leading (non-excluded) node.
#include "collision_state.hpp"

#include <cmath>

namespace fissure::host::thin_body {
namespace {

// Two facing values / crossing times closer than this are treated as a tie.
constexpr double kTie = 1e-9;
// Facing difference (cosines) above which an edge node and a node on another plane are ranked by
// facing rather than side memory: 0.25 ≈ 15° near head-on — a clear difference, not float noise.
constexpr double kFacingMargin = 0.25;

bool leads(const CollisionData& data, int i, int j) {
  const auto a = static_cast<std::size_t>(i);
  const auto b = static_cast<std::size_t>(j);
  if (data.sweep.node_age[a] != data.sweep.node_age[b]) return data.sweep.node_age[a] > data.sweep.node_age[b];
  if (std::abs(data.sweep.node_facing[a] - data.sweep.node_facing[b]) > kTie) return data.sweep.node_facing[a] < data.sweep.node_facing[b];
  if (std::abs(data.sweep.node_tau[a] - data.sweep.node_tau[b]) > kTie) return data.sweep.node_tau[a] < data.sweep.node_tau[b];
  return i < j;
}

// Which of two non-excluded nodes that hit the same soft face places it on its plane. Between a
// large-face node and an edge (rim) node on a different plane, the side memory (age) says nothing
// — they are not the two sides of the thickness, the surface is at the tool's corner — so the node
// that meets the triangle more head-on wins: a blade moving edge-first also touches the triangle
// with the rim rows of both faces (grazing, facing ≈ 0), but the triangle belongs on the rim
// plane (facing ≈ −1); a plate moving face-first reaches rim triangles with its face (≈ −1) while
// its rim only grazes them. Otherwise (two face nodes, or no clear difference) the pair rule.
bool places_face(const CollisionModel& model, const CollisionData& data, int i, int j) {
  const auto& edge = model.tool.edge_node_flags();
  const auto& plane_of_node = model.tool.plane_of_node();
  const auto a = static_cast<std::size_t>(i);
  const auto b = static_cast<std::size_t>(j);
  if ((edge[a] != 0 || edge[b] != 0) && plane_of_node[a] != plane_of_node[b] &&
      std::abs(data.sweep.node_facing[a] - data.sweep.node_facing[b]) > kFacingMargin)
    return data.sweep.node_facing[a] < data.sweep.node_facing[b];
  return leads(data, i, j);
}

bool in_contact(const CollisionData& data, int node) { return node >= 0 && data.sweep.node_face[static_cast<std::size_t>(node)] >= 0; }

}  // namespace

int exclude_infeasible_pairs(const CollisionModel& model, CollisionData& data) {
  data.exclusion.vector.clear();
  const auto& pair_of = model.tool.pair_of();
  const auto& by_begin = model.tool.paired_by_begin();
  const auto& by_nodes = model.tool.paired_by_nodes();
  if (model.paired && model.tool.is_thin()) {
    for (const int i : data.sweep.contact_nodes) {
      bool loses = false;
      const int pair = pair_of[static_cast<std::size_t>(i)];
      if (in_contact(data, pair) && !leads(data, i, pair)) loses = true;
      for (int k = by_begin[static_cast<std::size_t>(i)]; !loses && k < by_begin[static_cast<std::size_t>(i + 1)]; ++k) {
        const int other = by_nodes[static_cast<std::size_t>(k)];
        if (in_contact(data, other) && !leads(data, i, other)) loses = true;
      }
      if (loses) data.exclusion.vector.push_back(i);
    }
    // Decisions above were taken on the contact state before any exclusion (the cross-check is
    // symmetric); now the excluded nodes stop colliding for this step and lose their memory.
    for (const int i : data.exclusion.vector) {
      data.exclusion.node_excluded_stamp[static_cast<std::size_t>(i)] = data.step;
      data.sweep.node_face[static_cast<std::size_t>(i)] = -1;
      data.sweep.node_age[static_cast<std::size_t>(i)] = 0;
    }
  }
  // Both-face contacts left (the ray-only variant's instability; 0 for paired by construction).
  int both_face = 0;
  for (const int i : data.sweep.contact_nodes) {
    const int pair = pair_of[static_cast<std::size_t>(i)];
    if (!in_contact(data, i) || !in_contact(data, pair)) continue;
    // Count a mutual pair once, a one-way pair from its source.
    if (pair_of[static_cast<std::size_t>(pair)] != i || i < pair) ++both_face;
  }
  // Contacted faces and the plane each is placed on.
  data.exclusion.contacted_faces.clear();
  const auto& plane_of_node = model.tool.plane_of_node();
  for (const int i : data.sweep.contact_nodes) {
    const int face = data.sweep.node_face[static_cast<std::size_t>(i)];
    if (face < 0) continue;
    const auto f = static_cast<std::size_t>(face);
    if (data.exclusion.face_contact_stamp[f] != data.step) {
      data.exclusion.face_contact_stamp[f] = data.step;
      data.exclusion.contacted_faces.push_back(face);
      data.exclusion.face_lead_node[f] = i;
      data.exclusion.face_plane[f] = plane_of_node[static_cast<std::size_t>(i)];
    } else if (model.paired && places_face(model, data, i, data.exclusion.face_lead_node[f])) {
      data.exclusion.face_lead_node[f] = i;
      data.exclusion.face_plane[f] = plane_of_node[static_cast<std::size_t>(i)];
    }
  }
  return both_face;
}

}  // namespace fissure::host::thin_body
