// Convex thin tool meshes: OBJ / STL read with validation, OBJ write (tool_mesh_io.hpp).
#include "fissure/host_sim/tool_mesh_io.hpp"

#include <cmath>
#include <fstream>
#include <stdexcept>

#include <Eigen/Geometry>

#include "fissure/host_sim/mesh_checks.hpp"
#include "fissure/host_sim/mesh_file.hpp"

namespace fissure::host {

namespace {

// A vertex may sit this far outside a face's plane and the mesh still counts as convex
// (relative to the mesh size): OBJ files carry ~7 significant digits.
constexpr double kConvexityToleranceRatio = 1e-5;
// A triangle with |(b − a) × (c − a)| at or under this [m²] is degenerate (twice its area: a
// 0.1 µm × 0.1 µm sliver), whatever the mesh's size.
constexpr double kDegenerateCross_m2 = 1e-14;

Eigen::Vector3d v3(const Vec3& v) { return {v[0], v[1], v[2]}; }

void check_tool_shape(const ToolMesh& mesh) {
  check_closed_surface(mesh.vertices_m, mesh.triangles, kDegenerateCross_m2);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = Eigen::Vector3d::Constant(-1e300), centre = Eigen::Vector3d::Zero();
  for (const Vec3& v : mesh.vertices_m) {
    lo = lo.cwiseMin(v3(v));
    hi = hi.cwiseMax(v3(v));
    centre += v3(v);
  }
  centre /= static_cast<double>(mesh.vertices_m.size());
  const Eigen::Vector3d extent = hi - lo;
  if (!(extent.y() < extent.x() && extent.y() < extent.z())) {
    throw MeshDefect(MeshDefect::Element::kMesh, -1,
                     "the thin axis must be local y (y extent " + std::to_string(extent.y()) + " m is not the smallest)");
  }
  // A convex tool's every triangle faces away from the vertices' mean (inside the body).
  std::vector<Eigen::Vector3d> vertices;
  vertices.reserve(mesh.vertices_m.size());
  for (const Vec3& v : mesh.vertices_m) vertices.push_back(v3(v));
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    const auto& t = mesh.triangles[f];
    const Eigen::Vector3d &a = vertices[static_cast<std::size_t>(t[0])], &b = vertices[static_cast<std::size_t>(t[1])],
                          &c = vertices[static_cast<std::size_t>(t[2])];
    if ((b - a).cross(c - a).normalized().dot((a + b + c) / 3.0 - centre) <= 0.0) {
      throw MeshDefect(MeshDefect::Element::kTriangle, static_cast<int>(f), "inverted: it faces inwards (towards the tool's centre)");
    }
  }
  check_convex(vertices, mesh.triangles, kConvexityToleranceRatio * extent.norm());
}

}  // namespace

void check_tool_mesh(const ToolMesh& mesh) {
  try {
    check_tool_shape(mesh);
  } catch (const MeshDefect& defect) {
    std::string where;
    if (defect.element() == MeshDefect::Element::kTriangle) where = "triangle " + std::to_string(defect.index() + 1) + ": ";
    if (defect.element() == MeshDefect::Element::kVertex) where = "vertex " + std::to_string(defect.index() + 1) + ": ";
    throw std::runtime_error(where + defect.what());
  }
}

ToolMesh read_tool_mesh(const std::string& path) {
  MeshFile file = read_mesh_file(path, kToolMeshMaxTriangles);
  ToolMesh mesh;
  mesh.vertices_m = std::move(file.vertices_m);
  mesh.triangles = std::move(file.triangles);
  try {
    check_tool_shape(mesh);
  } catch (const MeshDefect& defect) {
    throw MeshError(describe(file, defect));
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
