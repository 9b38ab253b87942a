// Closed-surface checks: a closed cube passes; each defect is refused naming the element and
// the reason; the box-tree convexity check gives the verdict of a scan of every vertex.
#include "fissure/host_sim/mesh_checks.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include <string>

#include "fissure/host_sim/thin_tool.hpp"
#include "mesh_test_meshes.hpp"

namespace fissure::host {
namespace {

namespace tm = test_meshes;

struct Refusal {
  MeshDefect::Element element = MeshDefect::Element::kMesh;
  int index = -2;
  std::string reason = "(no error)";
};

Refusal refusal(const tm::Mesh& m, double min_cross_m2 = 1e-14) {
  try {
    check_closed_surface(m.vertices_m, m.triangles, min_cross_m2);
  } catch (const MeshDefect& d) {
    return {d.element(), d.index(), d.what()};
  }
  return {};
}

TEST(MeshChecks, ClosedCubePasses) { EXPECT_EQ(refusal(tm::cube()).reason, "(no error)"); }

TEST(MeshChecks, OpenSurfaceNamesATriangleOnTheHole) {
  tm::Mesh m = tm::cube();
  m.triangles.pop_back();  // triangle 12 (1, 6, 5) gone: its edges 1-6, 6-5, 5-1 lose a partner
  const Refusal r = refusal(m);
  EXPECT_EQ(r.element, MeshDefect::Element::kTriangle);
  EXPECT_NE(r.reason.find("open: its edge 2–6 has no other triangle"), std::string::npos) << r.reason;
  EXPECT_EQ(r.index, 4) << "triangle 5 (0, 1, 5) borders the hole at edge 1-5 (1-based 2-6)";
}

TEST(MeshChecks, NonManifoldEdgeNamesItsTriangles) {
  tm::Mesh m = tm::cube();
  m.vertices_m.push_back({0.5, -1.0, 0.5});
  m.triangles.push_back({0, 1, 8});  // a fin on edge 0-1
  m.triangles.push_back({1, 0, 8});
  const Refusal r = refusal(m);
  EXPECT_EQ(r.element, MeshDefect::Element::kTriangle);
  EXPECT_NE(r.reason.find("non-manifold: its edge 1–2 is shared by 4 triangles"), std::string::npos) << r.reason;
}

TEST(MeshChecks, FlippedTriangleIsInconsistent) {
  tm::Mesh m = tm::cube();
  std::swap(m.triangles[6][1], m.triangles[6][2]);  // triangle 7
  const Refusal r = refusal(m);
  EXPECT_EQ(r.element, MeshDefect::Element::kTriangle);
  EXPECT_TRUE(r.index == 6 || r.reason.find("triangle 7") != std::string::npos) << r.reason;
  EXPECT_NE(r.reason.find("inconsistent orientation"), std::string::npos) << r.reason;
}

TEST(MeshChecks, AllTrianglesInwardIsInverted) {
  tm::Mesh m = tm::cube();
  for (auto& t : m.triangles) std::swap(t[1], t[2]);
  const Refusal r = refusal(m);
  EXPECT_EQ(r.element, MeshDefect::Element::kMesh);
  EXPECT_NE(r.reason.find("inverted: the triangles face inwards (enclosed volume -1 m³ is not positive)"), std::string::npos) << r.reason;
}

TEST(MeshChecks, DegenerateTriangleAndBadIndexAndNonFiniteVertex) {
  tm::Mesh degenerate = tm::cube();
  degenerate.triangles[3] = {0, 0, 2};
  Refusal r = refusal(degenerate);
  EXPECT_EQ(r.index, 3);
  EXPECT_NE(r.reason.find("degenerate (vertices 1, 1, 3, area 0 m²"), std::string::npos) << r.reason;
  tm::Mesh sliver = tm::cube();
  sliver.vertices_m[3] = {1e-8, 1e-8, 0.0};  // triangle 2 (0, 3, 2): its corners on one line
  r = refusal(sliver, 1e-14);
  EXPECT_EQ(r.index, 1) << r.reason;
  EXPECT_NE(r.reason.find("degenerate"), std::string::npos) << r.reason;
  tm::Mesh bad_index = tm::cube();
  bad_index.triangles[5][2] = 8;
  r = refusal(bad_index);
  EXPECT_EQ(r.index, 5);
  EXPECT_EQ(r.reason, "bad vertex index 9 (the mesh has 8 vertices)");
  tm::Mesh nan = tm::cube();
  nan.vertices_m[6][2] = std::nan("");
  r = refusal(nan);
  EXPECT_EQ(r.element, MeshDefect::Element::kVertex);
  EXPECT_EQ(r.index, 6);
  EXPECT_NE(r.reason.find("non-finite coordinate (z = nan)"), std::string::npos) << r.reason;
}

TEST(MeshChecks, TwoSurfacesAreRefused) {
  tm::Mesh m = tm::cube();
  const tm::Mesh second = tm::cube();
  for (const Vec3& v : second.vertices_m) m.vertices_m.push_back({v[0] + 2.0, v[1], v[2]});
  for (const auto& t : second.triangles) m.triangles.push_back({t[0] + 8, t[1] + 8, t[2] + 8});
  const Refusal r = refusal(m);
  EXPECT_EQ(r.index, 12);
  EXPECT_NE(r.reason.find("more than one closed surface"), std::string::npos) << r.reason;
}

TEST(MeshChecks, DescribeNamesFileElementAndLine) {
  MeshFile file;
  file.path = "/x/organ.stl";
  file.triangle_lines = {2, 9, 16};
  EXPECT_EQ(describe(file, MeshDefect(MeshDefect::Element::kTriangle, 1, "open: …")), "'/x/organ.stl': triangle 2 (line 9): open: …");
  EXPECT_EQ(describe(file, MeshDefect(MeshDefect::Element::kVertex, 0, "non-finite")), "'/x/organ.stl': vertex 1: non-finite");
  EXPECT_EQ(describe(file, MeshDefect(MeshDefect::Element::kMesh, -1, "inverted")), "'/x/organ.stl': inverted");
}

// The convexity verdict with its tolerance is the one a scan of every vertex gives, also for
// meshes whose flat faces are bent by about the tolerance (some convex within it, some not):
// the rounded spatula's flat faces hold many coplanar vertices, one of them moved along y.
TEST(MeshChecks, ConvexVerdictMatchesAScanOfEveryVertex) {
  const ConvexMeshToolShape spatula = make_rounded_spatula_mesh(RoundedSpatulaParams{}, 0.0);
  std::mt19937 rng(20261203U);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  constexpr double kTolerance_m = 1e-6;
  std::vector<std::size_t> flat;  // vertices on a flat face (|y| = half the thickness)
  for (std::size_t i = 0; i < spatula.vertices_tool_m.size(); ++i)
    if (std::abs(std::abs(spatula.vertices_tool_m[i].y()) - 0.001) < 1e-12) flat.push_back(i);
  ASSERT_GT(flat.size(), 100U);
  int convex = 0, not_convex = 0;
  for (int trial = 0; trial < 60; ++trial) {
    std::vector<Eigen::Vector3d> v = spatula.vertices_tool_m;
    // Out of or into the face by up to 2 tolerances.
    Eigen::Vector3d& p = v[flat[static_cast<std::size_t>(unit(rng) * static_cast<double>(flat.size())) % flat.size()]];
    p.y() += (trial % 2 == 0 ? 1.0 : -1.0) * (p.y() > 0.0 ? 1.0 : -1.0) * 2.0 * kTolerance_m * unit(rng);
    int scan = -1;
    for (std::size_t f = 0; f < spatula.triangles.size() && scan < 0; ++f) {
      const auto& t = spatula.triangles[f];
      const Eigen::Vector3d& a = v[static_cast<std::size_t>(t[0])];
      const Eigen::Vector3d n = (v[static_cast<std::size_t>(t[1])] - a).cross(v[static_cast<std::size_t>(t[2])] - a).normalized();
      for (const auto& q : v)
        if (n.dot(q - a) > kTolerance_m) scan = static_cast<int>(f);
    }
    int tree = -1;
    try {
      check_convex(v, spatula.triangles, kTolerance_m);
    } catch (const MeshDefect& d) {
      tree = d.index();
      EXPECT_NE(std::string(d.what()).find("not convex: vertex"), std::string::npos);
    }
    EXPECT_EQ(tree, scan) << "trial " << trial;
    (scan < 0 ? convex : not_convex) += 1;
  }
  EXPECT_GT(convex, 0) << "the trials must cover both verdicts";
  EXPECT_GT(not_convex, 0);
}

}  // namespace
}  // namespace fissure::host
