#pragma once
// Bending resistance for an edge-link shell: links between the nodes a fixed number of edges
// apart (Bullet's "bending constraints", btSoftBody::generateBendingConstraints). A link from a
// node to its neighbour's neighbour spans the angle between two edges, so its length changes,
// to first order, with the fold of the surface at the node between: a shell of edge links alone
// folds freely at every edge (it wrinkles and flattens like cloth), one with these links keeps
// its curvature — a vessel's round section.
//
// Bullet's own generateBendingConstraints builds a nodes × nodes distance table (n² unsigned
// ints: 40 GB at 100k nodes) and, for a distance above 2, runs Floyd's algorithm (n³); this
// builds the same links from each node's breadth-first neighbourhood, linear in the body.
#include <array>
#include <vector>

class btSoftBody;

namespace fissure::host {

/// The loader's largest bending-link distance [edges]. Past a few edges a link no longer spans
/// one fold but a patch of the surface (at 4 edges, a quarter of the shipped 16-segment
/// vessel's circumference), and the link count grows as the square of the distance.
inline constexpr int kMaxBendingDistance = 4;

/// The node pairs exactly `distance` links apart in the graph of `links` (over nodes
/// 0 … nodes_count − 1), each once as {lower, higher}, in Bullet's generateBendingConstraints
/// order (ascending lower node, then ascending higher node). `distance` ≥ 2; an empty result
/// when no pair is that far apart.
[[nodiscard]] std::vector<std::array<int, 2>> bending_link_pairs(int nodes_count, const std::vector<std::array<int, 2>>& links, int distance);

/// Appends a bending link (Link::m_bbending = 1) for every node pair exactly `distance` edges
/// apart in `body`'s current links, with their own material: a copy of the body's material 0
/// with kLST = stiffness_ratio ∈ (0, 1] (the share of a link's length error the position solver
/// corrects per iteration, as for the edge links). Then shuffles all links with Bullet's own
/// deterministic randomizeConstraints sequence (links only: the faces keep their order), so
/// that the Gauss–Seidel link sweep has no order bias from the appended block, as Bullet's demos
/// do after generateBendingConstraints. Rest lengths are the current node distances (call on
/// the body as built). Returns the number of links appended.
int append_bending_links(btSoftBody& body, int distance, double stiffness_ratio);

}  // namespace fissure::host
