// Convex thin tool meshes: OBJ read/write with validation.
#include "fissure/host_sim/tool_mesh_io.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <utility>

#include <tiny_obj_loader.h>

#include <Eigen/Geometry>

namespace fissure::host {

namespace {

// A vertex may sit this far outside a face's plane and the mesh still counts as convex
// (relative to the mesh size): OBJ files carry ~7 significant digits.
constexpr double kConvexityToleranceRatio = 1e-5;

Eigen::Vector3d v3(const Vec3& v) { return {v[0], v[1], v[2]}; }

/// Checks every vertex line ("v x y z") of an OBJ file for coordinates that are not finite
/// numbers: the OBJ reader turns a token it cannot parse ("nan", "1,5") into 0, which would
/// surface later as a misleading shape error ("not convex").
void check_obj_vertex_lines(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::size_t vertex = 0;
  for (int number = 1; std::getline(in, line); ++number) {
    std::istringstream tokens(line);
    std::string keyword;
    if (!(tokens >> keyword) || keyword != "v") continue;
    ++vertex;
    for (const char axis : {'x', 'y', 'z'}) {
      std::string token;
      tokens >> token;
      char* end = nullptr;
      const double value = token.empty() ? 0.0 : std::strtod(token.c_str(), &end);
      if (token.empty() || end != token.c_str() + token.size() || !std::isfinite(value)) {
        throw std::runtime_error("'" + path + "' line " + std::to_string(number) + ": vertex " + std::to_string(vertex) +
                                 " coordinate " + axis + " is '" + token + "', not a finite number");
      }
    }
  }
}

}  // namespace

void check_tool_mesh(const ToolMesh& mesh) {
  if (mesh.vertices_m.size() < 4 || mesh.triangles.size() < 4) {
    throw std::runtime_error("a closed convex tool needs at least 4 vertices and 4 triangles, the mesh has " +
                             std::to_string(mesh.vertices_m.size()) + " vertices and " + std::to_string(mesh.triangles.size()) +
                             " triangles");
  }
  for (std::size_t i = 0; i < mesh.vertices_m.size(); ++i) {
    for (int axis = 0; axis < 3; ++axis) {
      if (!std::isfinite(mesh.vertices_m[i][static_cast<std::size_t>(axis)])) {
        throw std::runtime_error("vertex " + std::to_string(i + 1) + " has a non-finite coordinate (" + "xyz"[axis] + " = " +
                                 std::to_string(mesh.vertices_m[i][static_cast<std::size_t>(axis)]) + ")");
      }
    }
  }
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = Eigen::Vector3d::Constant(-1e300), centre = Eigen::Vector3d::Zero();
  for (const Vec3& v : mesh.vertices_m) {
    lo = lo.cwiseMin(v3(v));
    hi = hi.cwiseMax(v3(v));
    centre += v3(v);
  }
  centre /= static_cast<double>(mesh.vertices_m.size());
  const Eigen::Vector3d extent = hi - lo;
  if (!(extent.y() < extent.x() && extent.y() < extent.z())) {
    throw std::runtime_error("the thin axis must be local y (y extent " + std::to_string(extent.y()) + " m is not the smallest)");
  }
  const double tolerance_m = kConvexityToleranceRatio * extent.norm();
  std::map<std::pair<int, int>, int> directed_edges;
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    const auto& t = mesh.triangles[f];
    for (int i : t) {
      if (i < 0 || static_cast<std::size_t>(i) >= mesh.vertices_m.size()) throw std::runtime_error("triangle " + std::to_string(f) + " has a bad vertex index");
    }
    const Eigen::Vector3d a = v3(mesh.vertices_m[t[0]]), b = v3(mesh.vertices_m[t[1]]), c = v3(mesh.vertices_m[t[2]]);
    const Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.norm() <= 1e-14) throw std::runtime_error("triangle " + std::to_string(f) + " is degenerate");
    const Eigen::Vector3d unit = n.normalized();
    if (unit.dot((a + b + c) / 3.0 - centre) <= 0.0) throw std::runtime_error("triangle " + std::to_string(f) + " faces inwards");
    for (const Vec3& v : mesh.vertices_m) {
      if (unit.dot(v3(v) - a) > tolerance_m) throw std::runtime_error("not convex (a vertex lies outside triangle " + std::to_string(f) + "'s plane)");
    }
    for (int e = 0; e < 3; ++e) {
      if (++directed_edges[{t[e], t[(e + 1) % 3]}] > 1) throw std::runtime_error("edge used twice in the same direction (inconsistent winding)");
    }
  }
  for (const auto& [edge, uses] : directed_edges) {
    if (directed_edges.count({edge.second, edge.first}) == 0) throw std::runtime_error("not closed (an edge has only one triangle)");
  }
}

ToolMesh read_tool_mesh_obj(const std::string& path) {
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::string warn, err;
  std::error_code code;
  if (std::filesystem::is_directory(path, code)) throw std::runtime_error("'" + path + "' is a directory, not an OBJ file");
  std::ifstream probe(path);
  if (!probe) throw std::runtime_error("cannot open '" + path + "'");
  check_obj_vertex_lines(path);
  if (!tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, path.c_str(), nullptr, true)) {
    throw std::runtime_error("'" + path + "' is not a readable OBJ: " + err);
  }
  ToolMesh mesh;
  for (std::size_t i = 0; i + 2 < attrib.vertices.size(); i += 3) {
    mesh.vertices_m.push_back({attrib.vertices[i], attrib.vertices[i + 1], attrib.vertices[i + 2]});
  }
  for (const auto& shape : shapes) {
    for (std::size_t i = 0; i + 2 < shape.mesh.indices.size(); i += 3) {
      mesh.triangles.push_back({shape.mesh.indices[i].vertex_index, shape.mesh.indices[i + 1].vertex_index, shape.mesh.indices[i + 2].vertex_index});
    }
  }
  try {
    check_tool_mesh(mesh);
  } catch (const std::exception& e) {
    throw std::runtime_error("'" + path + "': " + e.what());
  }
  return mesh;
}

void write_tool_mesh_obj(const ToolMesh& mesh, const std::string& path, const std::string& comment) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write '" + path + "'");
  out << "# " << comment << "\n";
  out.precision(9);
  for (const Vec3& v : mesh.vertices_m) out << "v " << v[0] << ' ' << v[1] << ' ' << v[2] << '\n';
  for (const auto& t : mesh.triangles) out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
  if (!out) throw std::runtime_error("failed writing '" + path + "'");
}

}  // namespace fissure::host
