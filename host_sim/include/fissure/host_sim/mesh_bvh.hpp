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

/// Vertices of a mesh, for "is any vertex beyond this plane?".
class VertexTree {
 public:
  explicit VertexTree(const std::vector<Eigen::Vector3d>& vertices);
  /// A vertex v (the first found in tree order) for which beyond(v) holds, or -1. The caller's
  /// `beyond` is the exact test (evaluated as written, so its verdict is unchanged); it must
  /// imply n·v > bound_m up to rounding: a box is skipped only when its support in n is below
  /// bound_m by more than a slack of 1e-9 of the coordinates' size (far above any rounding).
  template <class Beyond>
  [[nodiscard]] int find_beyond(const Eigen::Vector3d& n, double bound_m, Beyond&& beyond) const {
    const auto& nodes = tree_.nodes();
    if (nodes.empty()) return -1;
    const double threshold = bound_m - slack_m_;
    int stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const BoxTree::Node& node = nodes[static_cast<std::size_t>(stack[--top])];
      double support = 0.0;
      for (int k = 0; k < 3; ++k) support += std::max(n[k] * node.lo[k], n[k] * node.hi[k]);
      if (support <= threshold) continue;
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
  const std::vector<Eigen::Vector3d>& vertices_;
  BoxTree tree_;
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
