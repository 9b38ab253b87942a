// Tetrahedral mesh checks: the boundary of a cube (5 and Kuhn tetrahedra) is its closed outward
// surface; duplicate vertices are welded and unused ones dropped; several volumes, overlapping
// or non-conforming tetrahedra and a face of three are refused naming the tetrahedron.
#include "fissure/host_sim/tet_mesh_checks.hpp"

#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "fissure/host_sim/mesh_file.hpp"
#include "tet_test_meshes.hpp"

namespace fissure::host {
namespace {

namespace tt = test_tets;

std::string error_of(const TetMesh& mesh) {
  try {
    (void)check_tet_mesh(mesh);
  } catch (const MeshError& e) {
    return e.what();
  }
  return "(no error)";
}

double enclosed_volume_m3(const TetMesh& mesh, const TetBoundary& boundary) {
  double sum = 0.0;
  for (const auto& t : boundary.triangles) {
    const Vec3& a = mesh.vertices_m[static_cast<std::size_t>(t[0])];
    const Vec3& b = mesh.vertices_m[static_cast<std::size_t>(t[1])];
    const Vec3& c = mesh.vertices_m[static_cast<std::size_t>(t[2])];
    sum += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  return sum / 6.0;
}

TEST(TetMeshChecks, BoundaryIsTheClosedOutwardSurface) {
  const TetMesh cube = tt::cube5(0.04, 0.02, 0.03);
  const TetBoundary b = check_tet_mesh(cube);
  ASSERT_EQ(b.triangles.size(), 12U) << "two triangles per face of the box; the central tetrahedron has none";
  for (const int t : b.tetrahedra) EXPECT_NE(t, 4) << "the central tetrahedron is all inside";
  EXPECT_NEAR(enclosed_volume_m3(cube, b), 0.04 * 0.02 * 0.03, 1e-18) << "outward: the boundary encloses the box's volume, positive";
  EXPECT_NEAR(tet_mesh_volume_m3(cube), 0.04 * 0.02 * 0.03, 1e-18);
  const TetMesh box = tt::kuhn_box({2, 3, 4}, 0.01);
  const TetBoundary kb = check_tet_mesh(box);
  EXPECT_EQ(kb.triangles.size(), static_cast<std::size_t>(4 * (2 * 3 + 3 * 4 + 2 * 4)));
  EXPECT_NEAR(enclosed_volume_m3(box, kb), 24e-6, 1e-15);
  EXPECT_TRUE(std::is_sorted(kb.tetrahedra.begin(), kb.tetrahedra.end())) << "in tetrahedron order";
}

TEST(TetMeshChecks, DuplicateVerticesAreWeldedAndUnusedOnesDropped) {
  // Each tetrahedron with its own four points (as some exporters write), plus two no element uses.
  const TetMesh cube = tt::cube5();
  TetMesh apart;
  apart.source = "apart.vtk";
  apart.vertices_m.push_back({9.0, 9.0, 9.0});
  for (const auto& t : cube.tetrahedra) {
    std::array<int, 4> corners{};
    for (std::size_t k = 0; k < 4; ++k) {
      corners[k] = static_cast<int>(apart.vertices_m.size());
      apart.vertices_m.push_back(cube.vertices_m[static_cast<std::size_t>(t[k])]);
    }
    apart.tetrahedra.push_back(corners);
  }
  apart.vertices_m.push_back({-0.0, 5.0, 5.0});
  EXPECT_NE(error_of(apart).find("5 separate volumes"), std::string::npos) << "unwelded, the tetrahedra touch by no face: " << error_of(apart);
  const TetMeshCleanup cleanup = weld_and_compact(apart);
  EXPECT_EQ(cleanup.welded_vertices_count, 20 - 8);
  EXPECT_EQ(cleanup.unused_vertices_count, 2);
  ASSERT_EQ(apart.vertices_m.size(), 8U);
  EXPECT_EQ(check_tet_mesh(apart).triangles.size(), 12U);
  EXPECT_DOUBLE_EQ(tet_mesh_volume_m3(apart), 1.0);
}

TEST(TetMeshChecks, RefusesNamingTheTetrahedronAndReason) {
  // Two boxes apart: two volumes.
  TetMesh two = tt::cube5();
  two.source = "two.msh";
  const TetMesh other = tt::kuhn_box({1, 1, 1}, 1.0, {3.0, 0.0, 0.0});
  for (const auto& v : other.vertices_m) two.vertices_m.push_back(v);
  for (auto t : other.tetrahedra) {
    for (int& c : t) c += 8;
    two.tetrahedra.push_back(t);
  }
  EXPECT_NE(error_of(two).find("'two.msh': 2 separate volumes (from tetrahedron 1: 5 tetrahedra; from tetrahedron 6: 6 tetrahedra), joined by no face"), std::string::npos)
      << error_of(two);
  // Four unit cells in a 2 × 2 square, welded: the 5-tetrahedron cube, Kuhn cells to its +x and
  // +y (their shared faces split alike), and in the far corner a Kuhn cell mirrored in x, which
  // matches its −x neighbour's face split but crosses its −y neighbour's: a non-conforming
  // interface inside one connected volume: its two face splits are both boundary, the square's
  // edges carry 4 boundary triangles. (A tetrahedral mesh's boundary has an even number of
  // triangles on every edge — it bounds a volume — so it is never "open" by count; a
  // non-conforming interface shows as a non-manifold edge.)
  TetMesh square = tt::cube5();
  square.source = "square.vtk";
  const auto append = [&](const TetMesh& part, const std::function<Vec3(const Vec3&)>& place) {
    const int base = static_cast<int>(square.vertices_m.size());
    for (const auto& v : part.vertices_m) square.vertices_m.push_back(place(v));
    for (auto t : part.tetrahedra) {
      for (int& c : t) c += base;
      square.tetrahedra.push_back(t);
    }
  };
  const TetMesh kuhn = tt::kuhn_box({1, 1, 1}, 1.0);
  append(kuhn, [](const Vec3& v) { return Vec3{v[0] + 1.0, v[1], v[2]}; });
  append(kuhn, [](const Vec3& v) { return Vec3{v[0], v[1] + 1.0, v[2]}; });
  append(kuhn, [](const Vec3& v) { return Vec3{2.0 - v[0], v[1] + 1.0, v[2]}; });
  tt::orient_positive(square);
  (void)weld_and_compact(square);
  EXPECT_NE(error_of(square).find("'square.vtk': tetrahedron "), std::string::npos) << error_of(square);
  EXPECT_NE(error_of(square).find(": non-manifold: its edge "), std::string::npos) << error_of(square);
  EXPECT_EQ(error_of(square).find("separate"), std::string::npos) << "one volume, joined by faces: " << error_of(square);
  // The same tetrahedron twice: overlap.
  TetMesh twice = tt::cube5();
  twice.source = "twice.node";
  twice.tetrahedra.push_back(twice.tetrahedra[0]);
  EXPECT_NE(error_of(twice).find("'twice.node': tetrahedron 6: overlaps tetrahedron 1: both lie on the same side of their shared face"), std::string::npos)
      << error_of(twice);
  // A face of three tetrahedra.
  TetMesh fan;
  fan.source = "fan.msh";
  fan.vertices_m = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, 0, -1}, {0.2, 0.2, 0.5}};
  fan.tetrahedra = {{0, 1, 2, 3}, {0, 2, 1, 4}, {0, 1, 2, 5}};
  EXPECT_NE(error_of(fan).find("'fan.msh': tetrahedron 1: non-manifold: its face 1–2–3 is shared by 3 tetrahedra (2, 3); an inner face has 2"), std::string::npos)
      << error_of(fan);
  // A generated mesh with an inverted element (the readers turn them round; a generator must not make them).
  TetMesh inverted = tt::cube5();
  std::swap(inverted.tetrahedra[3][0], inverted.tetrahedra[3][1]);
  EXPECT_NE(error_of(inverted).find("'cube5': tetrahedron 4: not positively oriented (volume -0.1667 m³"), std::string::npos) << error_of(inverted);
}

}  // namespace
}  // namespace fissure::host
