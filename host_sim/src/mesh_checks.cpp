// Closed-surface shape checks (mesh_checks.hpp).
#include "fissure/host_sim/mesh_checks.hpp"
#include "mesh_detail.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

#include <Eigen/Geometry>

#include "fissure/host_sim/mesh_bvh.hpp"

namespace fissure::host {
namespace {

using Element = MeshDefect::Element;

Eigen::Vector3d e3(const Vec3& v) { return {v[0], v[1], v[2]}; }

std::string n1(int index) { return std::to_string(index + 1); }

std::string metres(double value) {
  std::ostringstream out;
  out.precision(4);
  out << value;
  return out.str();
}

using mesh_detail::find_root;

}  // namespace

void check_closed_surface(const std::vector<Vec3>& vertices_m, const std::vector<std::array<int, 3>>& triangles, double min_cross_m2) {
  if (vertices_m.size() < 4 || triangles.size() < 4) {
    throw MeshDefect(Element::kMesh, -1,
                     "a closed surface needs at least 4 vertices and 4 triangles, the mesh has " + std::to_string(vertices_m.size()) +
                         " vertices and " + std::to_string(triangles.size()) + " triangles");
  }
  for (std::size_t i = 0; i < vertices_m.size(); ++i) {
    for (std::size_t axis = 0; axis < 3; ++axis) {
      if (!std::isfinite(vertices_m[i][axis])) {
        throw MeshDefect(Element::kVertex, static_cast<int>(i),
                         std::string("non-finite coordinate (") + "xyz"[axis] + " = " + std::to_string(vertices_m[i][axis]) + ")");
      }
    }
  }
  const int vertex_count = static_cast<int>(vertices_m.size());
  for (std::size_t f = 0; f < triangles.size(); ++f) {
    for (const int i : triangles[f]) {
      if (i < 0 || i >= vertex_count) {
        throw MeshDefect(Element::kTriangle, static_cast<int>(f),
                         "bad vertex index " + std::to_string(i + 1) + " (the mesh has " + std::to_string(vertex_count) + " vertices)");
      }
    }
  }
  for (std::size_t f = 0; f < triangles.size(); ++f) {
    const auto& t = triangles[f];
    const Eigen::Vector3d a = e3(vertices_m[static_cast<std::size_t>(t[0])]), b = e3(vertices_m[static_cast<std::size_t>(t[1])]),
                          c = e3(vertices_m[static_cast<std::size_t>(t[2])]);
    const double cross = (b - a).cross(c - a).norm();
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || !(cross > min_cross_m2)) {
      throw MeshDefect(Element::kTriangle, static_cast<int>(f),
                       "degenerate (vertices " + n1(t[0]) + ", " + n1(t[1]) + ", " + n1(t[2]) + ", area " + metres(0.5 * cross) +
                           " m²; the limit is " + metres(0.5 * min_cross_m2) + " m²)");
    }
  }
  // Edges: sorted by their (lower, higher) vertex pair, so each undirected edge's uses are
  // adjacent — n log n instead of a lookup per edge in a tree (same order of cost) or a scan.
  struct Use {
    int lo, hi, triangle;
    bool forward;  // runs lo → hi
  };
  std::vector<Use> uses;
  uses.reserve(3 * triangles.size());
  for (std::size_t f = 0; f < triangles.size(); ++f) {
    for (int e = 0; e < 3; ++e) {
      const int from = triangles[f][static_cast<std::size_t>(e)], to = triangles[f][static_cast<std::size_t>((e + 1) % 3)];
      uses.push_back({std::min(from, to), std::max(from, to), static_cast<int>(f), from < to});
    }
  }
  std::sort(uses.begin(), uses.end(), [](const Use& x, const Use& y) {
    return x.lo != y.lo ? x.lo < y.lo : x.hi != y.hi ? x.hi < y.hi : x.triangle < y.triangle;
  });
  std::vector<int> parent(triangles.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (std::size_t begin = 0; begin < uses.size();) {
    std::size_t end = begin;
    while (end < uses.size() && uses[end].lo == uses[begin].lo && uses[end].hi == uses[begin].hi) ++end;
    const Use& first = uses[begin];
    const std::string edge = "edge " + n1(first.lo) + "–" + n1(first.hi);
    if (end - begin == 1) {
      throw MeshDefect(Element::kTriangle, first.triangle, "open: its " + edge + " has no other triangle (the surface has a hole there)");
    }
    if (end - begin > 2) {
      throw MeshDefect(Element::kTriangle, first.triangle,
                       "non-manifold: its " + edge + " is shared by " + std::to_string(end - begin) + " triangles (" + n1(uses[begin + 1].triangle) +
                           ", " + n1(uses[begin + 2].triangle) + (end - begin > 3 ? ", …" : "") + "); a closed surface has 2 per edge");
    }
    const Use& second = uses[begin + 1];
    if (first.forward == second.forward) {
      throw MeshDefect(Element::kTriangle, second.triangle,
                       "inconsistent orientation: it runs its " + edge + " the same way as triangle " + n1(first.triangle) +
                           " (one of the two is flipped)");
    }
    parent[static_cast<std::size_t>(find_root(parent, first.triangle))] = find_root(parent, second.triangle);
    begin = end;
  }
  // One surface: a file holding two closed surfaces is two bodies, not one.
  const int root = find_root(parent, 0);
  for (std::size_t f = 1; f < triangles.size(); ++f) {
    if (find_root(parent, static_cast<int>(f)) != root) {
      throw MeshDefect(Element::kTriangle, static_cast<int>(f), "not connected to triangle 1: the file holds more than one closed surface");
    }
  }
  double volume6 = 0.0;
  for (const auto& t : triangles) {
    volume6 += e3(vertices_m[static_cast<std::size_t>(t[0])]).dot(e3(vertices_m[static_cast<std::size_t>(t[1])]).cross(e3(vertices_m[static_cast<std::size_t>(t[2])])));
  }
  if (!(volume6 > 0.0)) {
    throw MeshDefect(Element::kMesh, -1,
                     "inverted: the triangles face inwards (enclosed volume " + metres(volume6 / 6.0) +
                         " m³ is not positive); triangles must run counter-clockwise seen from outside");
  }
}

void check_convex(const std::vector<Eigen::Vector3d>& vertices_m, const std::vector<std::array<int, 3>>& triangles, double tolerance_m) {
  const VertexTree tree(vertices_m);
  for (std::size_t f = 0; f < triangles.size(); ++f) {
    const auto& t = triangles[f];
    const Eigen::Vector3d& a = vertices_m[static_cast<std::size_t>(t[0])];
    const Eigen::Vector3d unit = (vertices_m[static_cast<std::size_t>(t[1])] - a).cross(vertices_m[static_cast<std::size_t>(t[2])] - a).normalized();
    const int v = tree.find_beyond(unit, unit.dot(a) + tolerance_m, [&](const Eigen::Vector3d& p) { return unit.dot(p - a) > tolerance_m; });
    if (v >= 0) {
      const Eigen::Vector3d& p = vertices_m[static_cast<std::size_t>(v)];
      throw MeshDefect(Element::kTriangle, static_cast<int>(f),
                       "not convex: vertex " + n1(v) + " (at " + metres(p.x()) + ", " + metres(p.y()) + ", " + metres(p.z()) + " m) lies " +
                           metres(unit.dot(p - a)) + " m outside its plane (tolerance " + metres(tolerance_m) + " m)");
    }
  }
}

std::string describe(const MeshFile& file, const MeshDefect& defect) {
  std::string where = "'" + file.path + "'";
  switch (defect.element()) {
    case MeshDefect::Element::kMesh: break;
    case MeshDefect::Element::kTriangle: where += ": " + triangle_name(file, defect.index()); break;
    case MeshDefect::Element::kVertex: where += ": vertex " + n1(defect.index()); break;
  }
  return where + ": " + defect.what();
}

}  // namespace fissure::host
