// Tetrahedral mesh clean-up, boundary and checks (tet_mesh_checks.hpp).
#include "fissure/host_sim/tet_mesh_checks.hpp"
#include "mesh_detail.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>
#include <sstream>
#include <unordered_map>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "fissure/host_sim/mesh_checks.hpp"
#include "fissure/host_sim/mesh_file.hpp"
#include "fissure/host_sim/tet_mesh_file.hpp"

namespace fissure::host {
namespace {

Eigen::Vector3d e3(const Vec3& v) { return {v[0], v[1], v[2]}; }

std::string number_text(double value) {
  std::ostringstream out;
  out.precision(4);
  out << value;
  return out.str();
}

double volume6_m3(const TetMesh& mesh, const std::array<int, 4>& t) {
  const Eigen::Vector3d a = e3(mesh.vertices_m[static_cast<std::size_t>(t[0])]);
  return (e3(mesh.vertices_m[static_cast<std::size_t>(t[1])]) - a)
      .dot((e3(mesh.vertices_m[static_cast<std::size_t>(t[2])]) - a).cross(e3(mesh.vertices_m[static_cast<std::size_t>(t[3])]) - a));
}

using mesh_detail::find_root;

}  // namespace

TetMeshCleanup weld_and_compact(TetMesh& mesh) {
  struct Hash {
    std::size_t operator()(const Vec3& p) const noexcept {
      std::size_t h = 0;
      for (double c : p) h = h * 1000003U ^ std::hash<double>{}(c);
      return h;
    }
  };
  TetMeshCleanup cleanup;
  const std::size_t n = mesh.vertices_m.size();
  std::vector<int> first(n);
  std::unordered_map<Vec3, int, Hash> seen;
  seen.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& p = mesh.vertices_m[i];
    const Vec3 key{p[0] + 0.0, p[1] + 0.0, p[2] + 0.0};  // −0 and +0 are one point
    const auto [it, added] = seen.try_emplace(key, static_cast<int>(i));
    first[i] = it->second;
    if (!added) ++cleanup.welded_vertices_count;
  }
  std::vector<char> used(n, 0);
  for (auto& t : mesh.tetrahedra) {
    for (int& c : t) {
      c = first[static_cast<std::size_t>(c)];
      used[static_cast<std::size_t>(c)] = 1;
    }
  }
  std::vector<int> index(n, -1);
  std::vector<Vec3> kept;
  kept.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (used[i] != 0) {
      index[i] = static_cast<int>(kept.size());
      kept.push_back(mesh.vertices_m[i]);
    } else if (first[i] == static_cast<int>(i)) {
      ++cleanup.unused_vertices_count;
    }
  }
  for (auto& t : mesh.tetrahedra) {
    for (int& c : t) c = index[static_cast<std::size_t>(c)];
  }
  mesh.vertices_m = std::move(kept);
  return cleanup;
}

double tet_mesh_volume_m3(const TetMesh& mesh) {
  double sum6 = 0.0;
  for (const auto& t : mesh.tetrahedra) sum6 += volume6_m3(mesh, t);
  return sum6 / 6.0;
}

TetBoundary check_tet_mesh(const TetMesh& mesh) {
  const std::string file = "'" + mesh.source + "'";
  const auto fail = [&](int tet, const std::string& reason) -> void {
    throw MeshError(file + ": " + (tet >= 0 ? tetrahedron_name(mesh, tet) + ": " : std::string()) + reason);
  };
  if (mesh.tetrahedra.empty()) fail(-1, "no tetrahedron");
  const int vertex_count = static_cast<int>(mesh.vertices_m.size());
  for (std::size_t t = 0; t < mesh.tetrahedra.size(); ++t) {
    const auto& c = mesh.tetrahedra[t];
    for (const int i : c) {
      if (i < 0 || i >= vertex_count) fail(static_cast<int>(t), "bad vertex index " + std::to_string(i + 1) + " (the mesh has " + std::to_string(vertex_count) + " vertices)");
    }
    const double v6 = volume6_m3(mesh, c);
    if (!(v6 > 0.0)) fail(static_cast<int>(t), "not positively oriented (volume " + number_text(v6 / 6.0) + " m³; corners (a, b, c, d) need (b − a)·((c − a) × (d − a)) > 0)");
  }
  // Faces, each as its tetrahedron winds it seen from outside, sorted by their vertex set so a
  // face's uses are adjacent (n log n).
  struct Face {
    std::array<int, 3> key;      // sorted vertices
    std::array<int, 3> outward;  // counter-clockwise seen from outside its tetrahedron
    int tet, which;
    bool odd;  // outward is an odd permutation of key
  };
  std::vector<Face> faces;
  faces.reserve(4 * mesh.tetrahedra.size());
  for (std::size_t t = 0; t < mesh.tetrahedra.size(); ++t) {
    const auto& [a, b, c, d] = mesh.tetrahedra[t];
    // Positive (a, b, c, d): d lies on the side (b − a) × (c − a) points to, so (a, c, b) faces out.
    const std::array<std::array<int, 3>, 4> out = {{{a, c, b}, {a, b, d}, {a, d, c}, {b, c, d}}};
    for (int k = 0; k < 4; ++k) {
      const auto& f = out[static_cast<std::size_t>(k)];
      std::array<int, 3> key = f;
      std::sort(key.begin(), key.end());
      const int inversions = (f[0] > f[1]) + (f[0] > f[2]) + (f[1] > f[2]);
      faces.push_back({key, f, static_cast<int>(t), k, inversions % 2 == 1});
    }
  }
  std::sort(faces.begin(), faces.end(), [](const Face& x, const Face& y) { return x.key != y.key ? x.key < y.key : x.tet != y.tet ? x.tet < y.tet : x.which < y.which; });
  std::vector<int> parent(mesh.tetrahedra.size());
  std::iota(parent.begin(), parent.end(), 0);
  std::vector<const Face*> boundary;
  for (std::size_t begin = 0; begin < faces.size();) {
    std::size_t end = begin;
    while (end < faces.size() && faces[end].key == faces[begin].key) ++end;
    const Face& f = faces[begin];
    const auto vertices = [&f] { return "face " + std::to_string(f.key[0] + 1) + "–" + std::to_string(f.key[1] + 1) + "–" + std::to_string(f.key[2] + 1); };
    if (end - begin == 1) {
      boundary.push_back(&f);
    } else if (end - begin > 2) {
      fail(f.tet, "non-manifold: its " + vertices() + " is shared by " + std::to_string(end - begin) + " tetrahedra (" + std::to_string(faces[begin + 1].tet + 1) + ", " +
                      std::to_string(faces[begin + 2].tet + 1) + (end - begin > 3 ? ", …" : "") + "); an inner face has 2");
    } else {
      const Face& g = faces[begin + 1];
      if (f.odd == g.odd) {
        fail(g.tet, "overlaps tetrahedron " + std::to_string(f.tet + 1) + ": both lie on the same side of their shared " + vertices());
      }
      parent[static_cast<std::size_t>(find_root(parent, f.tet))] = find_root(parent, g.tet);
    }
    begin = end;
  }
  // One volume: several are several bodies (the file's parts joined at most by an edge or a point).
  std::unordered_map<int, std::pair<int, int>> volumes;  // root → (first tetrahedron, size)
  for (std::size_t t = 0; t < mesh.tetrahedra.size(); ++t) {
    auto [it, added] = volumes.try_emplace(find_root(parent, static_cast<int>(t)), static_cast<int>(t), 0);
    ++it->second.second;
  }
  if (volumes.size() > 1) {
    std::vector<std::pair<int, int>> parts;
    for (const auto& [root, part] : volumes) parts.push_back(part);
    std::sort(parts.begin(), parts.end());
    std::string list;
    for (std::size_t p = 0; p < std::min<std::size_t>(parts.size(), 3); ++p) {
      list += (p == 0 ? "" : "; ") + std::string("from ") + tetrahedron_name(mesh, parts[p].first) + ": " + std::to_string(parts[p].second) + " tetrahedra";
    }
    if (parts.size() > 3) list += "; …";
    fail(-1, std::to_string(parts.size()) + " separate volumes (" + list + "), joined by no face; a soft body is one connected volume: split the file, one body per volume");
  }
  std::sort(boundary.begin(), boundary.end(), [](const Face* x, const Face* y) { return x->tet != y->tet ? x->tet < y->tet : x->which < y->which; });
  TetBoundary result;
  result.triangles.reserve(boundary.size());
  result.tetrahedra.reserve(boundary.size());
  for (const Face* f : boundary) {
    result.triangles.push_back(f->outward);
    result.tetrahedra.push_back(f->tet);
  }
  Eigen::AlignedBox3d bounds;
  for (const Vec3& v : mesh.vertices_m) bounds.extend(e3(v));
  const double size_m = bounds.diagonal().norm();
  try {
    check_closed_surface(mesh.vertices_m, result.triangles, 1e-12 * size_m * size_m);
  } catch (const MeshDefect& defect) {
    switch (defect.element()) {
      case MeshDefect::Element::kTriangle: {
        const int tet = result.tetrahedra[static_cast<std::size_t>(defect.index())];
        fail(tet, "its boundary triangle " + std::to_string(defect.index() + 1) + ": " + defect.what());
        break;
      }
      case MeshDefect::Element::kVertex:
        fail(-1, "vertex " + std::to_string(defect.index() + 1) + ": " + defect.what());
        break;
      case MeshDefect::Element::kMesh: fail(-1, std::string("its boundary: ") + defect.what()); break;
    }
  }
  return result;
}

}  // namespace fissure::host
