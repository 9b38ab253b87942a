// Bounding-box trees for the load-time mesh queries (mesh_bvh.hpp).
#include "fissure/host_sim/mesh_bvh.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <Eigen/Eigenvalues>

namespace fissure::host {
namespace {

// Leaf size: a few elements per leaf keeps the tree shallow without testing many per leaf.
constexpr int kLeafSize = 4;
// Boxes are widened by this fraction of the whole mesh's size (plus the rounding of a dot
// product over coordinates of that size, ~1e-16): the exact per-element tests keep the
// verdict, the widening only keeps a box from being skipped by a rounding difference.
constexpr double kSlackRelative = 1e-9;

double mesh_size(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const auto& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return points.empty() ? 0.0 : (hi - lo).norm() + hi.cwiseAbs().maxCoeff() + lo.cwiseAbs().maxCoeff();
}

}  // namespace

BoxTree::BoxTree(const std::vector<Eigen::Vector3d>& lo, const std::vector<Eigen::Vector3d>& hi) : lo_(&lo), hi_(&hi) {
  const int n = static_cast<int>(lo.size());
  items_.resize(static_cast<std::size_t>(n));
  std::iota(items_.begin(), items_.end(), 0);
  std::vector<Eigen::Vector3d> centre(lo.size());
  for (std::size_t i = 0; i < lo.size(); ++i) centre[i] = 0.5 * (lo[i] + hi[i]);
  nodes_.reserve(static_cast<std::size_t>(2 * std::max(1, n / kLeafSize) + 1));
  if (n > 0) build(0, n, centre);
  lo_ = hi_ = nullptr;
}

// Median split along the widest axis of the centres: depth log2(n / kLeafSize), n log n build.
int BoxTree::build(int begin, int end, const std::vector<Eigen::Vector3d>& centre) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.push_back(Node{});
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  Eigen::Vector3d clo = lo, chi = hi;
  for (int i = begin; i < end; ++i) {
    const int item = items_[static_cast<std::size_t>(i)];
    lo = lo.cwiseMin((*lo_)[static_cast<std::size_t>(item)]);
    hi = hi.cwiseMax((*hi_)[static_cast<std::size_t>(item)]);
    clo = clo.cwiseMin(centre[static_cast<std::size_t>(item)]);
    chi = chi.cwiseMax(centre[static_cast<std::size_t>(item)]);
  }
  nodes_[static_cast<std::size_t>(index)].lo = lo;
  nodes_[static_cast<std::size_t>(index)].hi = hi;
  if (end - begin <= kLeafSize) {
    nodes_[static_cast<std::size_t>(index)].first = begin;
    nodes_[static_cast<std::size_t>(index)].count = end - begin;
    return index;
  }
  int axis = 0;
  (chi - clo).maxCoeff(&axis);
  const int mid = begin + (end - begin) / 2;
  std::nth_element(items_.begin() + begin, items_.begin() + mid, items_.begin() + end,
                   [&](int x, int y) { return centre[static_cast<std::size_t>(x)][axis] < centre[static_cast<std::size_t>(y)][axis]; });
  const int left = build(begin, mid, centre);
  const int right = build(mid, end, centre);
  nodes_[static_cast<std::size_t>(index)].first = left;
  nodes_[static_cast<std::size_t>(index)].count = -right;  // negative: inner node, -right child
  return index;
}

VertexTree::VertexTree(const std::vector<Eigen::Vector3d>& vertices)
    : vertices_(vertices), tree_(vertices, vertices), slack_m_(kSlackRelative * mesh_size(vertices)) {
  slabs_.resize(tree_.nodes().size());
  if (!tree_.nodes().empty()) (void)fill_slabs(0);
}

// Each node's points are items [begin, end) with begin = the first leaf's `first` below it: a
// node's range is its left child's followed by its right child's. Every level visits each point
// once: n log n.
int VertexTree::fill_slabs(int index) {
  const BoxTree::Node& node = tree_.nodes()[static_cast<std::size_t>(index)];
  int begin = 0, end = 0;
  if (node.count > 0) {
    begin = node.first;
    end = node.first + node.count;
  } else {
    int walk = index;
    while (tree_.nodes()[static_cast<std::size_t>(walk)].count <= 0) walk = tree_.nodes()[static_cast<std::size_t>(walk)].first;
    begin = tree_.nodes()[static_cast<std::size_t>(walk)].first;
    (void)fill_slabs(node.first);
    end = fill_slabs(-node.count);
  }
  Slab& slab = slabs_[static_cast<std::size_t>(index)];
  const auto point = [&](int i) -> const Eigen::Vector3d& { return vertices_[static_cast<std::size_t>(tree_.items()[static_cast<std::size_t>(i)])]; };
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (int i = begin; i < end; ++i) centre += point(i);
  centre /= static_cast<double>(end - begin);
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (int i = begin; i < end; ++i) covariance += (point(i) - centre) * (point(i) - centre).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  Eigen::Vector3d normal = solver.eigenvectors().col(0);  // eigenvalues ascending: the least spread
  if (!(normal.allFinite() && normal.norm() > 0.5)) normal = Eigen::Vector3d::UnitY();
  normal.normalize();
  double half_width = 0.0;
  for (int i = begin; i < end; ++i) half_width = std::max(half_width, std::abs(normal.dot(point(i) - centre)));
  slab.centre = centre;
  slab.normal = normal;
  slab.half_width_m = half_width;
  slab.reach_m = (node.hi - centre).cwiseAbs().cwiseMax((node.lo - centre).cwiseAbs());
  return end;
}

TriangleTree::TriangleTree(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b,
                           const std::vector<Eigen::Vector3d>& c)
    : a_(a), b_(b), c_(c) {
  std::vector<Eigen::Vector3d> lo(a.size()), hi(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    lo[i] = a[i].cwiseMin(b[i]).cwiseMin(c[i]);
    hi[i] = a[i].cwiseMax(b[i]).cwiseMax(c[i]);
  }
  slack_m_ = kSlackRelative * mesh_size(lo) + kSlackRelative * mesh_size(hi);
  tree_ = BoxTree(lo, hi);
}

int TriangleTree::first_hit(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_min, double t_max, int skip) const {
  const auto& nodes = tree_.nodes();
  if (nodes.empty()) return -1;
  // Möller–Trumbore accepts hits 1e-12 (barycentric) outside a triangle and its t carries
  // rounding: the boxes and the segment are widened by the slack so that no such hit is skipped.
  double best_t = t_max;
  int best = -1;
  int stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const BoxTree::Node& node = nodes[static_cast<std::size_t>(stack[--top])];
    // Slab test of the segment origin + s·dir, s ∈ [0, t_max], against the widened box.
    double s0 = -slack_m_, s1 = t_max + slack_m_ / std::max(dir.norm(), 1e-300);
    bool miss = false;
    for (int k = 0; k < 3 && !miss; ++k) {
      const double lo = node.lo[k] - slack_m_, hi = node.hi[k] + slack_m_;
      if (std::abs(dir[k]) < 1e-300) {
        miss = origin[k] < lo || origin[k] > hi;
      } else {
        double e0 = (lo - origin[k]) / dir[k], e1 = (hi - origin[k]) / dir[k];
        if (e0 > e1) std::swap(e0, e1);
        s0 = std::max(s0, e0);
        s1 = std::min(s1, e1);
        miss = s0 > s1;
      }
    }
    if (miss) continue;
    if (node.count > 0) {
      for (int k = 0; k < node.count; ++k) {
        const int j = tree_.items()[static_cast<std::size_t>(node.first + k)];
        if (j == skip) continue;
        const double t = ray_triangle(origin, dir, a_[static_cast<std::size_t>(j)], b_[static_cast<std::size_t>(j)], c_[static_cast<std::size_t>(j)]);
        if (t > t_min && (t < best_t || (t == best_t && j > best))) {
          best_t = t;
          best = j;
        }
      }
    } else if (node.count < 0) {
      stack[top++] = -node.count;
      stack[top++] = node.first;
    }
  }
  return best;
}

double ray_triangle(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                    const Eigen::Vector3d& c) {
  const Eigen::Vector3d e1 = b - a;
  const Eigen::Vector3d e2 = c - a;
  const Eigen::Vector3d pvec = dir.cross(e2);
  const double det = e1.dot(pvec);
  if (std::abs(det) < 1e-300) return std::numeric_limits<double>::infinity();
  const double inv_det = 1.0 / det;
  const Eigen::Vector3d tvec = origin - a;
  const double u = tvec.dot(pvec) * inv_det;
  if (u < -1e-12 || u > 1.0 + 1e-12) return std::numeric_limits<double>::infinity();
  const Eigen::Vector3d qvec = tvec.cross(e1);
  const double v = dir.dot(qvec) * inv_det;
  if (v < -1e-12 || u + v > 1.0 + 1e-12) return std::numeric_limits<double>::infinity();
  return e2.dot(qvec) * inv_det;
}

}  // namespace fissure::host
