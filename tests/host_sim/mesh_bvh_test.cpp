// Box trees: every query answers what a scan of all elements answers (the scans the load-time
// checks and the pairing did before the trees).
#include "fissure/host_sim/mesh_bvh.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "fissure/host_sim/thin_tool.hpp"

namespace fissure::host {
namespace {

ConvexMeshToolShape spatula() {
  RoundedSpatulaParams p;
  p.corner_segments = 10;
  p.face_divisions = 12;
  return make_rounded_spatula_mesh(p, 0.003);
}

// The pairing scan as it was: nearest t in (t_min, t_max], `t <= best` keeps the last of equals.
int scan_first_hit(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b, const std::vector<Eigen::Vector3d>& c,
                   const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_min, double t_max, int skip) {
  double best_t = t_max;
  int best = -1;
  for (std::size_t j = 0; j < a.size(); ++j) {
    if (static_cast<int>(j) == skip) continue;
    const double t = ray_triangle(origin, dir, a[j], b[j], c[j]);
    if (t > t_min && t <= best_t) {
      best_t = t;
      best = static_cast<int>(j);
    }
  }
  return best;
}

TEST(TriangleTree, FirstHitIsTheScansAnswerForEveryPairingRayAndRandomRays) {
  const ConvexMeshToolShape mesh = spatula();
  std::vector<Eigen::Vector3d> a, b, c, centroid, normal;
  for (const auto& t : mesh.triangles) {
    a.push_back(mesh.vertices_tool_m[static_cast<std::size_t>(t[0])]);
    b.push_back(mesh.vertices_tool_m[static_cast<std::size_t>(t[1])]);
    c.push_back(mesh.vertices_tool_m[static_cast<std::size_t>(t[2])]);
    centroid.push_back((a.back() + b.back() + c.back()) / 3.0);
    normal.push_back((b.back() - a.back()).cross(c.back() - a.back()).normalized());
  }
  const TriangleTree tree(a, b, c);
  int hits = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (const double limit : {0.003, 1.0}) {
      const int want = scan_first_hit(a, b, c, centroid[i], -normal[i], 1e-9, limit, static_cast<int>(i));
      EXPECT_EQ(tree.first_hit(centroid[i], -normal[i], 1e-9, limit, static_cast<int>(i)), want) << "node " << i << " limit " << limit;
      hits += want >= 0 ? 1 : 0;
    }
  }
  EXPECT_GT(hits, static_cast<int>(a.size()));
  // Rays through vertices and edges (ties between triangles sharing them) and from outside.
  std::mt19937 rng(7U);
  std::uniform_real_distribution<double> u(-0.04, 0.04);
  for (int k = 0; k < 2000; ++k) {
    const Eigen::Vector3d origin(u(rng), u(rng), u(rng));
    const Eigen::Vector3d target = k % 2 == 0 ? mesh.vertices_tool_m[static_cast<std::size_t>(k) % mesh.vertices_tool_m.size()]
                                              : Eigen::Vector3d(u(rng), 0.2 * u(rng), u(rng));
    const Eigen::Vector3d dir = (target - origin).normalized();
    EXPECT_EQ(tree.first_hit(origin, dir, 0.0, 0.2, -1), scan_first_hit(a, b, c, origin, dir, 0.0, 0.2, -1)) << "ray " << k;
  }
}

TEST(VertexTree, FindsAVertexBeyondAPlaneExactlyWhenAScanDoes) {
  const ConvexMeshToolShape mesh = spatula();
  const VertexTree tree(mesh.vertices_tool_m);
  std::mt19937 rng(11U);
  std::normal_distribution<double> g(0.0, 1.0);
  int found = 0;
  for (int k = 0; k < 3000; ++k) {
    const Eigen::Vector3d n = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
    double top = -std::numeric_limits<double>::infinity();
    for (const auto& p : mesh.vertices_tool_m) top = std::max(top, n.dot(p));
    // Planes at, just under and just over the top vertex: the boundary cases of the pruning.
    const double offset = top + (k % 3 - 1) * 1e-12;
    const auto beyond = [&](const Eigen::Vector3d& p) { return n.dot(p) - offset > 0.0; };
    bool scan = false;
    for (const auto& p : mesh.vertices_tool_m) scan = scan || beyond(p);
    const int v = tree.find_beyond(n, offset, beyond);
    EXPECT_EQ(v >= 0, scan) << "plane " << k;
    if (v >= 0) {
      EXPECT_TRUE(beyond(mesh.vertices_tool_m[static_cast<std::size_t>(v)]));
    }
    found += v >= 0 ? 1 : 0;
  }
  EXPECT_GT(found, 0);
  EXPECT_LT(found, 3000);
}

}  // namespace
}  // namespace fissure::host
