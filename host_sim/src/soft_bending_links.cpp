// Bending links of an edge-link shell (soft_bending_links.hpp).
#include "fissure/host_sim/soft_bending_links.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include <BulletSoftBody/btSoftBody.h>

namespace fissure::host {

std::vector<std::array<int, 2>> bending_link_pairs(int nodes_count, const std::vector<std::array<int, 2>>& links, int distance) {
  if (distance < 2) throw std::invalid_argument("bending links join nodes 2 or more edges apart (got " + std::to_string(distance) + ")");
  const auto n = static_cast<std::size_t>(nodes_count);
  std::vector<std::vector<int>> neighbours(n);
  for (const auto& l : links) {
    neighbours[static_cast<std::size_t>(l[0])].push_back(l[1]);
    neighbours[static_cast<std::size_t>(l[1])].push_back(l[0]);
  }
  for (auto& list : neighbours) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  // Breadth-first from each node up to `distance` edges; `seen_from` stamps the nodes reached
  // from the current source, so the per-source cost is its neighbourhood, not the body.
  std::vector<int> seen_from(n, -1);
  std::vector<int> frontier, next, far;
  std::vector<std::array<int, 2>> pairs;
  for (int source = 0; source < nodes_count; ++source) {
    seen_from[static_cast<std::size_t>(source)] = source;
    frontier.assign(1, source);
    for (int depth = 1; depth <= distance && !frontier.empty(); ++depth) {
      next.clear();
      for (const int a : frontier) {
        for (const int b : neighbours[static_cast<std::size_t>(a)]) {
          if (seen_from[static_cast<std::size_t>(b)] == source) continue;
          seen_from[static_cast<std::size_t>(b)] = source;
          next.push_back(b);
        }
      }
      frontier.swap(next);
    }
    far.clear();
    for (const int b : frontier) {
      if (b > source) far.push_back(b);
    }
    std::sort(far.begin(), far.end());
    for (const int b : far) pairs.push_back({source, b});
  }
  return pairs;
}

int append_bending_links(btSoftBody& body, int distance, double stiffness_ratio) {
  if (!(stiffness_ratio > 0.0 && stiffness_ratio <= 1.0)) {
    throw std::invalid_argument("a bending link's stiffness ratio is in (0, 1] (got " + std::to_string(stiffness_ratio) + ")");
  }
  if (body.m_nodes.size() == 0) return 0;
  const btSoftBody::Node* base = &body.m_nodes[0];
  std::vector<std::array<int, 2>> links;
  links.reserve(static_cast<std::size_t>(body.m_links.size()));
  for (int i = 0; i < body.m_links.size(); ++i) {
    links.push_back({static_cast<int>(body.m_links[i].m_n[0] - base), static_cast<int>(body.m_links[i].m_n[1] - base)});
  }
  const std::vector<std::array<int, 2>> pairs = bending_link_pairs(body.m_nodes.size(), links, distance);
  if (pairs.empty()) return 0;
  btSoftBody::Material* material = body.appendMaterial();  // a copy of material 0
  material->m_kLST = static_cast<btScalar>(stiffness_ratio);
  body.m_links.reserve(body.m_links.size() + static_cast<int>(pairs.size()));
  for (const auto& p : pairs) {
    // Bullet's generateBendingConstraints appends (higher, lower).
    body.appendLink(p[1], p[0], material, false);
    // Link::m_bbending is a signed 1-bit field: Bullet's own `= 1` stores −1 as well, and
    // Bullet only ever tests it for non-zero.
    body.m_links[body.m_links.size() - 1].m_bbending = -1;
  }
  // btSoftBody::randomizeConstraints' sequence over the links.
  std::uint64_t seed = 243703;
  const int count = body.m_links.size();
  for (int i = 0; i < count; ++i) {
    seed = (1664525ULL * seed + 1013904223ULL) & 0xffffffffULL;
    body.m_links.swap(i, static_cast<int>(seed % static_cast<std::uint64_t>(count)));
  }
  return static_cast<int>(pairs.size());
}

}  // namespace fissure::host
