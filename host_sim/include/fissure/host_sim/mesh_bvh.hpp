#pragma once
// Axis-aligned bounding-box trees over a mesh's vertices and triangles, built once at load
// (O(n log n)): the queries that made loading a mesh quadratic — "does any vertex lie beyond
// this plane?" (convexity) and "which triangle does this limited ray hit first?" (pairing) —
// visit only the boxes that can hold an answer instead of every element.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <vector>

namespace fissure::host {

/// The tree: nodes in one array, leaves holding up to kLeafSize element indices.
class BoxTree {
 public:
  struct Node {
    Eigen::Vector3d lo = Eigen::Vector3d::Zero();  ///< box of everything below
    Eigen::Vector3d hi = Eigen::Vector3d::Zero();
    int first = 0;           ///< leaf: first index in items(); inner: index of the left child
    int count = 0;           ///< leaf: number of items (> 0); inner: minus the index of the right child
  };
  /// One box per element (an element's own bounds, possibly a point).
  BoxTree(const std::vector<Eigen::Vector3d>& lo, const std::vector<Eigen::Vector3d>& hi);
  BoxTree() = default;

  [[nodiscard]] const std::vector<Node>& nodes() const { return nodes_; }
  [[nodiscard]] const std::vector<int>& items() const { return items_; }

 private:
  int build(int begin, int end, const std::vector<Eigen::Vector3d>& centre);
  std::vector<Node> nodes_;
  std::vector<int> items_;
  const std::vector<Eigen::Vector3d>* lo_ = nullptr;
  const std::vector<Eigen::Vector3d>* hi_ = nullptr;
};

/// Vertices of a mesh, for "is any vertex beyond this plane?". Each node also keeps the slab
/// its points lie in — the plane of least spread through their centroid (the covariance's
/// smallest eigenvector) and the largest distance from it: a box of points on a flat face that
/// is tilted to the axes sticks out of that face's plane, the slab does not, so the queries of
/// that face's own triangles stop at the top of the tree instead of visiting every vertex on
/// the face.
class VertexTree {
 public:
  explicit VertexTree(const std::vector<Eigen::Vector3d>& vertices);
  /// A vertex v (the first found in tree order) for which beyond(v) holds, or -1. The caller's
  /// `beyond` is the exact test (evaluated as written, so its verdict is unchanged); it must
  /// imply n·v > bound_m up to rounding (|n| = 1): a node is skipped only when an upper bound of
  /// n·v over it (the smaller of its box's support and its slab's) is below bound_m by more than
  /// a slack of 1e-9 of the coordinates' size (far above any rounding).
  template <class Beyond>
  [[nodiscard]] int find_beyond(const Eigen::Vector3d& n, double bound_m, Beyond&& beyond) const {
    const auto& nodes = tree_.nodes();
    if (nodes.empty()) return -1;
    const double threshold = bound_m - slack_m_;
    int stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const int index = stack[--top];
      const BoxTree::Node& node = nodes[static_cast<std::size_t>(index)];
      if (upper_bound(index, n) <= threshold) continue;
      if (node.count > 0) {
        for (int k = 0; k < node.count; ++k) {
          const int v = tree_.items()[static_cast<std::size_t>(node.first + k)];
          if (beyond(vertices_[static_cast<std::size_t>(v)])) return v;
        }
      } else {
        stack[top++] = -node.count;
        stack[top++] = node.first;
      }
    }
    return -1;
  }

 private:
  struct Slab {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();  ///< centroid of the node's points
    Eigen::Vector3d normal = Eigen::Vector3d::UnitY();  ///< unit normal of the plane of least spread
    double half_width_m = 0.0;                          ///< max |normal·(v − centre)| over the points
    Eigen::Vector3d reach_m = Eigen::Vector3d::Zero();  ///< max |v_k − centre_k| over the box, per axis
  };
  /// An upper bound of n·v over node `index`'s points: min(box support, slab bound), where for
  /// n = α·normal + w (w ⊥ normal), n·v = n·centre + α·normal·(v − centre) + w·(v − centre)
  /// ≤ n·centre + |α|·half_width + Σ_k |w_k|·reach_k.
  [[nodiscard]] double upper_bound(int index, const Eigen::Vector3d& n) const {
    const BoxTree::Node& node = tree_.nodes()[static_cast<std::size_t>(index)];
    double box = 0.0;
    for (int k = 0; k < 3; ++k) box += std::max(n[k] * node.lo[k], n[k] * node.hi[k]);
    const Slab& slab = slabs_[static_cast<std::size_t>(index)];
    const double alpha = n.dot(slab.normal);
    const Eigen::Vector3d w = n - alpha * slab.normal;
    const double flat = n.dot(slab.centre) + std::abs(alpha) * slab.half_width_m + w.cwiseAbs().dot(slab.reach_m);
    return std::min(box, flat);
  }
  int fill_slabs(int index);  ///< computes the slabs below `index`; returns the end of its item range

  const std::vector<Eigen::Vector3d>& vertices_;
  BoxTree tree_;
  std::vector<Slab> slabs_;
  double slack_m_ = 0.0;
};

/// Triangles of a mesh for limited ray casts.
class TriangleTree {
 public:
  TriangleTree(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b, const std::vector<Eigen::Vector3d>& c);
  /// The triangle (≠ skip) whose hit parameter t (Möller–Trumbore, two-sided, `ray_triangle`)
  /// satisfies t_min < t ≤ t_max with the smallest t; on equal t the largest index (the order a
  /// scan over all triangles in index order keeping `t <= best` gives). -1 when none.
  [[nodiscard]] int first_hit(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_min, double t_max, int skip) const;

 private:
  const std::vector<Eigen::Vector3d>& a_;
  const std::vector<Eigen::Vector3d>& b_;
  const std::vector<Eigen::Vector3d>& c_;
  BoxTree tree_;
  double slack_m_ = 0.0;
};

/// Möller–Trumbore, two-sided; the ray parameter of the hit or +inf (barycentric tolerance 1e-12).
[[nodiscard]] double ray_triangle(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, const Eigen::Vector3d& a,
                                  const Eigen::Vector3d& b, const Eigen::Vector3d& c);

}  // namespace fissure::host
