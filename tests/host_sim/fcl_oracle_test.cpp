// The FCL oracle (fcl_oracle.hpp) against hand-built cases whose answer is known, and the
// project's clip (triangles_cut_by_volume, host_sim/contact_metrics.hpp) on the same cases; then
// both on random triangles around a blade and around the convex spatula.
#include "fcl_oracle.hpp"

#include <gtest/gtest.h>

#include <random>

#include "fissure/host_sim/contact_metrics.hpp"
#include "fissure/host_sim/thin_tool.hpp"

namespace fissure::host::test_oracle {
namespace {

constexpr double kTolM = kInsideToleranceM;                         // the metrics' 0.1 mm
const Eigen::Vector3d kSlabHalfM(0.02, 0.0005, 0.02);                // a 40 × 1 × 40 mm slab (the 1 mm blade)

struct Case {
  const char* name;
  Eigen::Vector3d a, b, c;  // tool frame
  bool cut;
};

bool project_cut(const ToolVolume& volume, const Case& k) {
  const std::vector<Eigen::Vector3d> nodes = {k.a, k.b, k.c};
  return triangles_cut_by_volume(volume, nodes, {{0, 1, 2}}, Eigen::Isometry3d::Identity(), kTolM) == 1;
}

// Hand-built cases on the 1 mm slab. x = +20 mm is its rim (a 1 mm wide side face), y = ±0.5 mm its large faces.
std::vector<Case> slab_cases() {
  return {
      // Through the whole thickness, the leading edge 0.5 mm in from the rim: deepest point 0.5 mm (the half thickness).
      {"crosses the slab 0.5 mm deep", {0.0195, -0.003, -0.001}, {0.0195, 0.003, -0.001}, {0.03, 0.0, 0.001}, true},
      // The same, 0.05 mm in: deepest point 0.05 mm < 0.1 mm.
      {"crosses the slab 0.05 mm deep", {0.01995, -0.003, -0.001}, {0.01995, 0.003, -0.001}, {0.03, 0.0, 0.001}, false},
      // A coarse 20 mm triangle parallel to the rim face, 1 mm in: every vertex outside (|y| > 0.5 mm or |z| > 20 mm),
      // the interior across the blade's edge region (deepest 0.5 mm).
      {"vertices outside, interior through the blade edge", {0.019, -0.01, -0.01}, {0.019, 0.01, -0.01}, {0.019, 0.0, 0.03}, true},
      // Lying on the large face (coplanar): touches, depth 0.
      {"lies on a face", {-0.005, 0.0005, -0.005}, {0.005, 0.0005, -0.005}, {0.0, 0.0005, 0.005}, false},
      // One vertex on the face, the rest above it.
      {"a vertex touches a face", {0.0, 0.0005, 0.0}, {0.005, 0.003, 0.0}, {0.0, 0.003, 0.005}, false},
      // One vertex 0.3 mm into the face (depth 0.3 mm at the vertex).
      {"a vertex 0.3 mm deep", {0.0, 0.0002, 0.0}, {0.005, 0.003, 0.0}, {0.0, 0.003, 0.005}, true},
      // Clear of the slab by 1 mm.
      {"clear of the slab", {0.0, 0.0015, 0.0}, {0.005, 0.003, 0.0}, {0.0, 0.003, 0.005}, false},
  };
}

TEST(FclOracle, ShrinksTheBoxByTheTolerance) {
  const FclToolOracle oracle = FclToolOracle::from_box(kSlabHalfM, kTolM);
  ASSERT_EQ(oracle.shrunk_vertices_tool_m().size(), 8U);
  for (const Eigen::Vector3d& v : oracle.shrunk_vertices_tool_m()) {
    const Eigen::Vector3d expected = (kSlabHalfM - Eigen::Vector3d::Constant(kTolM)).cwiseProduct(v.cwiseSign());
    EXPECT_LT((v - expected).norm(), 1e-8) << v.transpose();  // Bullet's float vertices
  }
}

TEST(FclOracle, ShrinksTheConvexSpatulaByTheTolerance) {
  // Every vertex of the shrunk spatula lies the tolerance inside the project's planes, to 0.3 µm:
  // the oracle's tool is the hull of the mesh's vertices (Bullet merges faces it finds coplanar on
  // its integer grid; a plane through a merged face is a fit), the project's is the intersection
  // of the mesh triangles' own planes; they differ by up to 0.21 µm on this mesh, well inside the
  // 1 µm agreement margin.
  RoundedSpatulaParams params;
  const ConvexMeshToolShape mesh = make_rounded_spatula_mesh(params, 3.0 * params.thickness_m);
  const FclToolOracle oracle(mesh.vertices_tool_m, kTolM);
  const ToolVolume volume = ToolVolume::from_convex_mesh(mesh.vertices_tool_m, mesh.triangles);
  EXPECT_GT(oracle.shrunk_vertices_tool_m().size(), 100U);
  for (const Eigen::Vector3d& v : oracle.shrunk_vertices_tool_m()) EXPECT_NEAR(volume.signed_distance_m(v), -kTolM, 3e-7) << v.transpose();
}

TEST(FclOracle, HandBuiltCasesOnASlabAndTheProjectsClipAgrees) {
  const FclToolOracle oracle = FclToolOracle::from_box(kSlabHalfM, kTolM);
  const ToolVolume volume = ToolVolume::from_box(kSlabHalfM);
  for (const Case& k : slab_cases()) {
    EXPECT_EQ(oracle.triangle_cut(k.a, k.b, k.c), k.cut) << "oracle: " << k.name;
    EXPECT_EQ(project_cut(volume, k), k.cut) << "project: " << k.name;
  }
}

TEST(FclOracle, NodesInsideDeeperThanTheTolerance) {
  const FclToolOracle oracle = FclToolOracle::from_box(kSlabHalfM, kTolM);
  const ToolVolume volume = ToolVolume::from_box(kSlabHalfM);
  // Depth 0.5 mm (mid-plane), 0.3 mm, 0.05 mm, on the face, outside.
  const std::vector<Eigen::Vector3d> nodes = {{0, 0, 0}, {0, 0.0002, 0}, {0, 0.00045, 0}, {0, 0.0005, 0}, {0, 0.001, 0}};
  const std::vector<char> expected = {1, 1, 0, 0, 0};
  const OracleCounts o = oracle.check(nodes, {}, Eigen::Isometry3d::Identity());
  ASSERT_EQ(o.inside.size(), nodes.size());
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    EXPECT_EQ(o.inside[i], expected[i]) << "oracle, node " << i;
    EXPECT_EQ(-volume.signed_distance_m(nodes[i]) > kTolM, expected[i] != 0) << "project, node " << i;
  }
}

TEST(FclOracle, WorksInTheWorldFrame) {
  // The crossing case moved and turned by a tool pose: the same answer.
  const FclToolOracle oracle = FclToolOracle::from_box(kSlabHalfM, kTolM);
  Eigen::Isometry3d tool_to_world = Eigen::Isometry3d::Identity();
  tool_to_world.translate(Eigen::Vector3d(0.1, 0.2, -0.05));
  tool_to_world.rotate(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  for (const Case& k : slab_cases()) {
    const std::vector<Eigen::Vector3d> nodes = {tool_to_world * k.a, tool_to_world * k.b, tool_to_world * k.c};
    EXPECT_EQ(oracle.check(nodes, {{0, 1, 2}}, tool_to_world).cut[0] != 0, k.cut) << k.name;
  }
}

// Random triangles of 1–20 mm around a tool: the project's clip and the oracle agree on every
// one up to the margin, and the sample contains cut and uncut triangles near the tolerance.
void random_triangles_agree(const ToolVolume& volume, const FclToolOracle& oracle, const Eigen::Vector3d& half_extent_m, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> size_m(0.001, 0.02);
  std::vector<Eigen::Vector3d> nodes;
  std::vector<std::array<int, 3>> faces;
  for (int i = 0; i < 3000; ++i) {
    // Centres near the surface: on the box around the tool, pushed in or out by up to 1 mm.
    const Eigen::Vector3d centre = half_extent_m.cwiseProduct(Eigen::Vector3d(unit(rng), unit(rng), unit(rng))) +
                                   0.001 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
    const double s = size_m(rng);
    const int base = static_cast<int>(nodes.size());
    for (int k = 0; k < 3; ++k) nodes.push_back(centre + s * Eigen::Vector3d(unit(rng), unit(rng), unit(rng)));
    faces.push_back({base, base + 1, base + 2});
  }
  std::vector<char> project(faces.size(), 0);
  std::vector<Eigen::Vector3d> scratch;
  for (std::size_t f = 0; f < faces.size(); ++f)
    project[f] = volume.reaches_inside(nodes[static_cast<std::size_t>(faces[f][0])], nodes[static_cast<std::size_t>(faces[f][1])],
                                       nodes[static_cast<std::size_t>(faces[f][2])], kTolM, scratch) ? 1 : 0;
  const OracleCounts o = oracle.check(nodes, faces, Eigen::Isometry3d::Identity());
  const Agreement tri = compare(project, o.cut, o.cut_loose, o.cut_strict);
  std::vector<char> project_inside(nodes.size(), 0);
  for (std::size_t i = 0; i < nodes.size(); ++i) project_inside[i] = -volume.signed_distance_m(nodes[i]) > kTolM ? 1 : 0;
  const Agreement node = compare(project_inside, o.inside, o.inside_loose, o.inside_strict);
  std::printf("random triangles: project %d cut, oracle %d, differ %d (beyond the margin %d); nodes inside: project %d, oracle %d, differ %d\n",
              tri.project, tri.oracle, tri.differ, tri.beyond_margin, node.project, node.oracle, node.differ);
  EXPECT_EQ(tri.beyond_margin, 0);
  EXPECT_EQ(node.beyond_margin, 0);
  EXPECT_GT(tri.project, 300) << "the sample must contain cut triangles";
  EXPECT_GT(static_cast<int>(faces.size()) - tri.project, 300) << "... and uncut ones";
  EXPECT_GT(node.project, 10);
}

TEST(FclOracle, RandomTrianglesAroundABladeAgreeWithTheProjectsClip) {
  random_triangles_agree(ToolVolume::from_box(kSlabHalfM), FclToolOracle::from_box(kSlabHalfM, kTolM), kSlabHalfM, 20261203);
}

TEST(FclOracle, RandomTrianglesAroundTheConvexSpatulaAgreeWithTheProjectsClip) {
  RoundedSpatulaParams params;  // 40 × 40 × 2 mm, rounded rims (the collision tests' spatula)
  const ConvexMeshToolShape mesh = make_rounded_spatula_mesh(params, 3.0 * params.thickness_m);
  const FclToolOracle oracle(mesh.vertices_tool_m, kTolM);
  Eigen::AlignedBox3d bounds;
  for (const Eigen::Vector3d& v : mesh.vertices_tool_m) bounds.extend(v);
  random_triangles_agree(ToolVolume::from_convex_mesh(mesh.vertices_tool_m, mesh.triangles), oracle, 0.5 * bounds.sizes(), 20261204);
}

}  // namespace
}  // namespace fissure::host::test_oracle
