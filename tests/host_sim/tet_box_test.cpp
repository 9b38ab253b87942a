// host_sim/src/tet_box.cpp: structured tetrahedral boxes — counts, orientation, volume, boundary,
// graded coordinates, refusals; and the tube (make_tet_tube).
#include "fissure/host_sim/tet_box.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

namespace fissure::host {
namespace {

Eigen::Vector3d e3(const Vec3& v) { return {v[0], v[1], v[2]}; }

double signed_volume(const VolumeMesh& m, const std::array<int, 4>& t) {
  const Eigen::Vector3d a = e3(m.vertices_m[static_cast<std::size_t>(t[0])]);
  return (e3(m.vertices_m[static_cast<std::size_t>(t[1])]) - a).dot((e3(m.vertices_m[static_cast<std::size_t>(t[2])]) - a).cross(e3(m.vertices_m[static_cast<std::size_t>(t[3])]) - a)) / 6.0;
}

TEST(TetBox, EvenCubeCountsOrientationVolumeAndBoundary) {
  const int n = 3;
  const VolumeMesh m = make_tet_box(even_coordinates(0.0, 0.03, n), even_coordinates(0.0, 0.03, n), even_coordinates(0.0, 0.03, n));
  EXPECT_EQ(m.vertices_m.size(), static_cast<std::size_t>((n + 1) * (n + 1) * (n + 1)));
  EXPECT_EQ(m.tetrahedra.size(), static_cast<std::size_t>(6 * n * n * n));
  EXPECT_EQ(m.boundary_triangles.size(), static_cast<std::size_t>(6 * 2 * n * n));  // 2 per face square
  double volume = 0.0;
  for (const auto& t : m.tetrahedra) {
    const double v = signed_volume(m, t);
    EXPECT_GT(v, 0.0);
    volume += v;
  }
  EXPECT_NEAR(volume, 0.03 * 0.03 * 0.03, 1e-15);
}

TEST(TetBox, VertexIndexIsXFastest) {
  const std::vector<double> xs{0.0, 1.0, 3.0}, ys{0.0, 2.0}, zs{0.0, 0.5, 1.0, 4.0};
  const VolumeMesh m = make_tet_box(xs, ys, zs);
  // (i, j, k) = (2, 1, 3) → (3 · 2 + 1) · 3 + 2 = 23.
  EXPECT_EQ(m.vertices_m[23][0], 3.0);
  EXPECT_EQ(m.vertices_m[23][1], 2.0);
  EXPECT_EQ(m.vertices_m[23][2], 4.0);
}

TEST(TetBox, GradedCoordinatesAreSymmetricEvenInsideAndEndAtTheExtent) {
  const std::vector<double> c = graded_coordinates(0.0075, 0.0025, 0.04, 1.3);
  ASSERT_GE(c.size(), 7u);
  EXPECT_DOUBLE_EQ(c.front(), -0.04);
  EXPECT_DOUBLE_EQ(c.back(), 0.04);
  for (std::size_t i = 0; i < c.size(); ++i) EXPECT_DOUBLE_EQ(c[i], -c[c.size() - 1 - i]);
  const std::size_t mid = c.size() / 2;
  EXPECT_DOUBLE_EQ(c[mid], 0.0);
  for (std::size_t i = mid; i < mid + 3; ++i) EXPECT_NEAR(c[i + 1] - c[i], 0.0025, 1e-15);
  for (std::size_t i = mid + 3; i + 2 < c.size(); ++i) EXPECT_GT(c[i + 1] - c[i], c[i] - c[i - 1]);  // growing (the last cell is cut)
  const std::vector<double> d = graded_coordinates_down(-0.04, 0.0, 0.0075, 0.0025, 1.3);
  EXPECT_DOUBLE_EQ(d.front(), -0.04);
  EXPECT_DOUBLE_EQ(d.back(), 0.0);
  EXPECT_NEAR(d[d.size() - 1] - d[d.size() - 2], 0.0025, 1e-15);
}

TEST(TetBox, RefusesAnAxisThatIsNotIncreasing) {
  EXPECT_THROW((void)make_tet_box({0.0, 1.0}, {0.0, 0.0}, {0.0, 1.0}), std::invalid_argument);
  EXPECT_THROW((void)make_tet_box({0.0}, {0.0, 1.0}, {0.0, 1.0}), std::invalid_argument);
}

TEST(TetTube, CountsOrientationVolumeBoundaryAndTheSeam) {
  TetTube tube;
  tube.cells_through = 2;
  tube.cells_around = 16;
  tube.cells_along = 3;
  const VolumeMesh m = make_tet_tube(tube);  // volume_mesh_from checks it: conforming, one volume, closed boundary
  EXPECT_EQ(m.vertices_m.size(), static_cast<std::size_t>(3 * 16 * 4));
  EXPECT_EQ(m.tetrahedra.size(), static_cast<std::size_t>(6 * 2 * 16 * 3));
  // Inner and outer walls (2 per cell face, 16 × 3 each) and two end annuli (2 × 16 × 2 each).
  EXPECT_EQ(m.boundary_triangles.size(), static_cast<std::size_t>(2 * (2 * 16 * 3) + 2 * (2 * 16 * 2)));
  double volume = 0.0;
  for (const auto& t : m.tetrahedra) {
    const double v = signed_volume(m, t);
    EXPECT_GT(v, 0.0);
    volume += v;
  }
  // The annulus between two regular 16-gons: (n/2) sin(2π/n) (R² − r²) L.
  const double polygon = 8.0 * std::sin(2.0 * std::numbers::pi / 16.0);
  EXPECT_NEAR(volume, polygon * (0.015 * 0.015 - 0.013 * 0.013) * 0.06, 1e-12);
  // Vertex (i, j, k) at index (k · around + j) · (through + 1) + i; j = 0 the lowest generator.
  const Vec3& lowest_outer = m.vertices_m[2];
  EXPECT_NEAR(lowest_outer[0], 0.0, 1e-15);
  EXPECT_NEAR(lowest_outer[1], -0.015, 1e-15);
  EXPECT_NEAR(lowest_outer[2], -0.03, 1e-15);
  EXPECT_THROW((void)make_tet_tube(TetTube{0.015, 0.013, 0.06, {0.0, 0.0, 0.0}, 2, 16, 3}), std::invalid_argument);
  EXPECT_THROW((void)make_tet_tube(TetTube{0.013, 0.015, 0.06, {0.0, 0.0, 0.0}, 2, 2, 3}), std::invalid_argument);
}

}  // namespace
}  // namespace fissure::host
