// Structured tetrahedral boxes (tet_box.hpp).
#include "fissure/host_sim/tet_box.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "fissure/host_sim/tet_mesh_checks.hpp"

namespace fissure::host {

namespace {

void check_axis(const std::vector<double>& v, const char* name) {
  if (v.size() < 2) throw std::invalid_argument(std::string("make_tet_box: axis ") + name + " needs at least 2 coordinates");
  for (std::size_t i = 1; i < v.size(); ++i) {
    if (!(v[i] > v[i - 1])) throw std::invalid_argument(std::string("make_tet_box: axis ") + name + " is not strictly increasing at index " + std::to_string(i));
  }
}

// Outward from `start` (exclusive) to `end`, cells from `first` growing by `growth`; the last
// cell ends exactly at `end` (a sliver shorter than half its neighbour is merged into it).
std::vector<double> grow(double start, double end, double first, double growth) {
  std::vector<double> out;
  const double direction = end > start ? 1.0 : -1.0;
  double x = start, h = first;
  while (direction * (end - x) > 1e-12) {
    x += direction * h;
    h *= growth;
    out.push_back(direction * (end - x) > 0.0 ? x : end);
  }
  if (out.size() >= 2) {
    const double last = std::abs(out[out.size() - 1] - out[out.size() - 2]);
    const double before = std::abs(out[out.size() - 2] - (out.size() >= 3 ? out[out.size() - 3] : start));
    if (last < 0.5 * before) {
      out.pop_back();
      out.back() = end;
    }
  }
  return out;
}

// The 6 Kuhn tetrahedra of a cell whose corner b = (b & 1, (b >> 1) & 1, (b >> 2) & 1) is vertex
// corner[b]: each path from corner 0 to corner 7 along the three axes in one order, turned
// positive. Every cell split so shares the diagonal of each face with its neighbour.
void append_kuhn_cell(TetMesh& tet, const std::array<int, 8>& corner) {
  constexpr int kKuhn[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7}, {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};
  const auto e3 = [&tet](int v) {
    const Vec3& p = tet.vertices_m[static_cast<std::size_t>(v)];
    return Eigen::Vector3d(p[0], p[1], p[2]);
  };
  for (const auto& t : kKuhn) {
    std::array<int, 4> q{corner[static_cast<std::size_t>(t[0])], corner[static_cast<std::size_t>(t[1])], corner[static_cast<std::size_t>(t[2])],
                         corner[static_cast<std::size_t>(t[3])]};
    const Eigen::Vector3d a = e3(q[0]);
    if ((e3(q[1]) - a).dot((e3(q[2]) - a).cross(e3(q[3]) - a)) < 0.0) std::swap(q[2], q[3]);
    tet.tetrahedra.push_back(q);
  }
}

}  // namespace

std::vector<double> even_coordinates(double lo_m, double hi_m, int cells) {
  std::vector<double> v(static_cast<std::size_t>(cells) + 1);
  for (int i = 0; i <= cells; ++i) v[static_cast<std::size_t>(i)] = lo_m + (hi_m - lo_m) * i / cells;
  return v;
}

std::vector<double> graded_coordinates(double fine_half_width_m, double spacing_m, double extent_m, double growth) {
  const int fine = std::max(1, static_cast<int>(std::lround(fine_half_width_m / spacing_m)));
  std::vector<double> positive;
  for (int i = 0; i <= fine; ++i) positive.push_back(i * spacing_m);
  for (double x : grow(positive.back(), extent_m, spacing_m * growth, growth)) positive.push_back(x);
  std::vector<double> out;
  for (auto it = positive.rbegin(); it != positive.rend(); ++it) {
    if (*it > 0.0) out.push_back(-*it);
  }
  out.insert(out.end(), positive.begin(), positive.end());
  return out;
}

std::vector<double> graded_coordinates_down(double lo_m, double hi_m, double fine_depth_m, double spacing_m, double growth) {
  const int fine = std::max(1, static_cast<int>(std::lround(fine_depth_m / spacing_m)));
  std::vector<double> down;
  for (int i = 0; i <= fine; ++i) down.push_back(hi_m - i * spacing_m);
  for (double y : grow(down.back(), lo_m, spacing_m * growth, growth)) down.push_back(y);
  std::reverse(down.begin(), down.end());
  return down;
}

VolumeMesh make_tet_box(const std::vector<double>& xs, const std::vector<double>& ys, const std::vector<double>& zs) {
  check_axis(xs, "x");
  check_axis(ys, "y");
  check_axis(zs, "z");
  const int nx = static_cast<int>(xs.size()), ny = static_cast<int>(ys.size()), nz = static_cast<int>(zs.size());
  TetMesh tet;
  tet.source = "tet box " + std::to_string(nx - 1) + " x " + std::to_string(ny - 1) + " x " + std::to_string(nz - 1);
  tet.vertices_m.reserve(static_cast<std::size_t>(nx) * ny * nz);
  for (int k = 0; k < nz; ++k) {
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) tet.vertices_m.push_back({xs[static_cast<std::size_t>(i)], ys[static_cast<std::size_t>(j)], zs[static_cast<std::size_t>(k)]});
    }
  }
  auto index = [&](int i, int j, int k) { return (k * ny + j) * nx + i; };
  tet.tetrahedra.reserve(6 * static_cast<std::size_t>(nx - 1) * (ny - 1) * (nz - 1));
  for (int k = 0; k + 1 < nz; ++k) {
    for (int j = 0; j + 1 < ny; ++j) {
      for (int i = 0; i + 1 < nx; ++i) {
        std::array<int, 8> corner{};
        for (int b = 0; b < 8; ++b) corner[static_cast<std::size_t>(b)] = index(i + (b & 1), j + ((b >> 1) & 1), k + ((b >> 2) & 1));
        append_kuhn_cell(tet, corner);
      }
    }
  }
  return volume_mesh_from(std::move(tet));
}

VolumeMesh make_tet_tube(const TetTube& tube) {
  if (!(tube.inner_radius_m > 0.0) || !(tube.outer_radius_m > tube.inner_radius_m) || !(tube.length_m > 0.0)) {
    throw std::invalid_argument("make_tet_tube: needs 0 < inner radius < outer radius and a positive length");
  }
  if (tube.cells_through < 1 || tube.cells_around < 3 || tube.cells_along < 1) {
    throw std::invalid_argument("make_tet_tube: needs >= 1 cell through the wall, >= 3 around and >= 1 along");
  }
  const int nr = tube.cells_through + 1, nt = tube.cells_around, nz = tube.cells_along + 1;
  TetMesh tet;
  tet.source = "tet tube " + std::to_string(tube.cells_through) + " x " + std::to_string(nt) + " x " + std::to_string(tube.cells_along);
  tet.vertices_m.reserve(static_cast<std::size_t>(nr) * nt * nz);
  for (int k = 0; k < nz; ++k) {
    for (int j = 0; j < nt; ++j) {
      // Angle from the lowest generator (−y), counter-clockwise seen from +z.
      const double angle = -0.5 * std::numbers::pi + 2.0 * std::numbers::pi * j / nt;
      for (int i = 0; i < nr; ++i) {
        const double r = tube.inner_radius_m + (tube.outer_radius_m - tube.inner_radius_m) * i / (nr - 1);
        tet.vertices_m.push_back({tube.centre_world_m[0] + r * std::cos(angle), tube.centre_world_m[1] + r * std::sin(angle),
                                  tube.centre_world_m[2] - 0.5 * tube.length_m + tube.length_m * k / (nz - 1)});
      }
    }
  }
  // The cells of the (radial, around, along) index grid, split as make_tet_box's, across the seam
  // from the last angle to the first too.
  auto index = [&](int i, int j, int k) { return (k * nt + (j % nt)) * nr + i; };
  tet.tetrahedra.reserve(6 * static_cast<std::size_t>(nr - 1) * nt * (nz - 1));
  for (int k = 0; k + 1 < nz; ++k) {
    for (int j = 0; j < nt; ++j) {
      for (int i = 0; i + 1 < nr; ++i) {
        std::array<int, 8> corner{};
        for (int b = 0; b < 8; ++b) corner[static_cast<std::size_t>(b)] = index(i + (b & 1), j + ((b >> 1) & 1), k + ((b >> 2) & 1));
        append_kuhn_cell(tet, corner);
      }
    }
  }
  return volume_mesh_from(std::move(tet));
}

}  // namespace fissure::host
