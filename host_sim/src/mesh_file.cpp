// OBJ / STL mesh files (mesh_file.hpp).
#include "fissure/host_sim/mesh_file.hpp"
#include "mesh_detail.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <unordered_map>

#include <tiny_obj_loader.h>

namespace fissure::host {
namespace {

std::string quoted(const std::string& path) { return "'" + path + "'"; }

std::string too_many(const std::string& path, std::size_t count, std::size_t limit) {
  return quoted(path) + ": too large: " + std::to_string(count) + " triangles, the limit is " + std::to_string(limit);
}

/// Parses a coordinate token; false when it is not a whole finite number.
bool parse_finite(const std::string& token, double& value) {
  if (token.empty()) return false;
  char* end = nullptr;
  value = std::strtod(token.c_str(), &end);
  return end == token.c_str() + token.size() && std::isfinite(value);
}

/// Welds vertices with bit-identical coordinates (STL stores each triangle's corners apart).
class Welder {
 public:
  explicit Welder(std::vector<Vec3>& vertices) : vertices_(vertices) {}
  int index(const Vec3& p) {
    const Vec3 key{p[0] + 0.0, p[1] + 0.0, p[2] + 0.0};  // −0 and +0 are one point
    const auto [it, added] = map_.try_emplace(key, static_cast<int>(vertices_.size()));
    if (added) vertices_.push_back(key);
    return it->second;
  }

 private:
  struct Hash {
    std::size_t operator()(const Vec3& p) const noexcept {
      std::size_t h = 0;
      for (double c : p) h = h * 1000003U ^ std::hash<double>{}(c);
      return h;
    }
  };
  std::vector<Vec3>& vertices_;
  std::unordered_map<Vec3, int, Hash> map_;
};

/// OBJ: tinyobjloader reads it; this scan gives what tinyobj does not: every "v" line's
/// coordinates are finite numbers (tinyobj turns "nan" or "1,5" into 0, which would surface as
/// a misleading shape error), and the line of each face (for the shape checks' messages).
MeshFile read_obj(const std::string& path, std::size_t max_triangles) {
  MeshFile mesh;
  mesh.path = path;
  mesh.format = MeshFormat::kObj;
  std::vector<int> lines;
  {
    std::ifstream in(path);
    std::string line;
    std::size_t vertex = 0;
    for (int number = 1; std::getline(in, line); ++number) {
      std::istringstream tokens(line);
      std::string keyword;
      if (!(tokens >> keyword)) continue;
      if (keyword == "v") {
        ++vertex;
        for (const char axis : {'x', 'y', 'z'}) {
          std::string token;
          tokens >> token;
          double value = 0.0;
          if (!parse_finite(token, value)) {
            throw MeshError(quoted(path) + " line " + std::to_string(number) + ": vertex " + std::to_string(vertex) + " coordinate " + axis +
                            " is '" + token + "', not a finite number");
          }
        }
      } else if (keyword == "f") {
        int corners = 0;
        std::string token;
        while (tokens >> token) ++corners;
        for (int k = 2; k < corners; ++k) lines.push_back(number);
        if (lines.size() > max_triangles) throw MeshError(too_many(path, lines.size(), max_triangles) + " (at line " + std::to_string(number) + ")");
      }
    }
  }
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::string warn, err;
  if (!tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, path.c_str(), nullptr, true)) {
    throw MeshError(quoted(path) + " is not a readable OBJ: " + err);
  }
  for (std::size_t i = 0; i + 2 < attrib.vertices.size(); i += 3) {
    mesh.vertices_m.push_back({attrib.vertices[i], attrib.vertices[i + 1], attrib.vertices[i + 2]});
  }
  for (const auto& shape : shapes) {
    for (std::size_t i = 0; i + 2 < shape.mesh.indices.size(); i += 3) {
      mesh.triangles.push_back({shape.mesh.indices[i].vertex_index, shape.mesh.indices[i + 1].vertex_index, shape.mesh.indices[i + 2].vertex_index});
    }
  }
  // tinyobj fan-triangulates an n-gon into n − 2 triangles in file order; if it ever did
  // otherwise the lines would be wrong, so they are then left out rather than misleading.
  if (lines.size() == mesh.triangles.size()) mesh.triangle_lines = std::move(lines);
  return mesh;
}

/// ASCII STL: solid NAME / facet normal … / outer loop / vertex x y z ×3 / endloop / endfacet
/// … endsolid; several solids follow one another; the facet normals are ignored (the winding
/// decides, as for OBJ).
MeshFile read_stl_ascii(const std::string& path, std::size_t max_triangles) {
  MeshFile mesh;
  mesh.path = path;
  mesh.format = MeshFormat::kStlAscii;
  Welder welder(mesh.vertices_m);
  std::ifstream in(path);
  std::string line;
  enum class State { kSolid, kFacet, kLoop, kVertex, kEndLoop, kEndFacet } state = State::kSolid;
  std::array<int, 3> corners{};
  int corner = 0;
  int facet_line = 0;
  int number = 0;
  const auto fail = [&](const std::string& reason) {
    throw MeshError(quoted(path) + " line " + std::to_string(number) + ": " + reason);
  };
  while (std::getline(in, line)) {
    ++number;
    std::istringstream tokens(line);
    std::string keyword;
    if (!(tokens >> keyword)) continue;
    std::string second;
    switch (state) {
      case State::kSolid:
        if (keyword != "solid") fail("expected 'solid', got '" + keyword + "'");
        state = State::kFacet;
        break;
      case State::kFacet:
        if (keyword == "endsolid") {
          state = State::kSolid;
          break;
        }
        if (keyword != "facet") fail("expected 'facet' or 'endsolid', got '" + keyword + "'");
        facet_line = number;
        state = State::kLoop;
        break;
      case State::kLoop:
        if (keyword != "outer" || !(tokens >> second) || second != "loop") fail("expected 'outer loop', got '" + line + "'");
        corner = 0;
        state = State::kVertex;
        break;
      case State::kVertex:
        if (keyword == "endloop") fail("the facet at line " + std::to_string(facet_line) + " has " + std::to_string(corner) + " vertices (an STL facet is a triangle: 3)");
        if (keyword != "vertex") fail("expected 'vertex', got '" + keyword + "'");
        {
          Vec3 p{};
          for (std::size_t axis = 0; axis < 3; ++axis) {
            std::string token;
            tokens >> token;
            if (!parse_finite(token, p[axis])) fail(std::string("vertex coordinate ") + "xyz"[axis] + " is '" + token + "', not a finite number");
          }
          corners[static_cast<std::size_t>(corner++)] = welder.index(p);
        }
        if (corner == 3) state = State::kEndLoop;
        break;
      case State::kEndLoop:
        if (keyword == "vertex") fail("the facet at line " + std::to_string(facet_line) + " has more than 3 vertices (an STL facet is a triangle)");
        if (keyword != "endloop") fail("expected 'endloop', got '" + keyword + "'");
        state = State::kEndFacet;
        break;
      case State::kEndFacet:
        if (keyword != "endfacet") fail("expected 'endfacet', got '" + keyword + "'");
        mesh.triangles.push_back(corners);
        mesh.triangle_lines.push_back(facet_line);
        if (mesh.triangles.size() > max_triangles) fail(too_many(path, mesh.triangles.size(), max_triangles).substr(quoted(path).size() + 2));
        state = State::kFacet;
        break;
    }
  }
  if (state != State::kSolid) {
    ++number;
    fail("the file ends inside a solid (missing 'endsolid' or an unfinished facet)");
  }
  if (mesh.triangles.empty()) throw MeshError(quoted(path) + ": the STL has no facet");
  return mesh;
}

/// Binary STL: 80-byte header, uint32 triangle count (little-endian), then per triangle 12
/// little-endian float32 (normal, 3 corners) and a 16-bit attribute word.
MeshFile read_stl_binary(const std::string& path, const std::string& bytes, std::size_t max_triangles) {
  MeshFile mesh;
  mesh.path = path;
  mesh.format = MeshFormat::kStlBinary;
  std::uint32_t count = 0;
  for (int k = 3; k >= 0; --k) count = (count << 8) | static_cast<unsigned char>(bytes[80 + static_cast<std::size_t>(k)]);
  if (count > max_triangles) throw MeshError(too_many(path, count, max_triangles) + " (binary STL header)");
  Welder welder(mesh.vertices_m);
  mesh.triangles.reserve(count);
  for (std::uint32_t t = 0; t < count; ++t) {
    const char* record = bytes.data() + 84 + 50 * static_cast<std::size_t>(t);
    std::array<int, 3> corners{};
    for (int c = 0; c < 3; ++c) {
      Vec3 p{};
      for (int axis = 0; axis < 3; ++axis) {
        std::uint32_t bits = 0;
        for (int k = 3; k >= 0; --k) bits = (bits << 8) | static_cast<unsigned char>(record[12 + 12 * c + 4 * axis + k]);
        float value = 0.0F;
        std::memcpy(&value, &bits, sizeof value);
        if (!std::isfinite(value)) {
          throw MeshError(quoted(path) + ": triangle " + std::to_string(t + 1) + " corner " + std::to_string(c + 1) + " coordinate " + "xyz"[axis] +
                          " is " + std::to_string(value) + ", not a finite number");
        }
        p[static_cast<std::size_t>(axis)] = static_cast<double>(value);
      }
      corners[static_cast<std::size_t>(c)] = welder.index(p);
    }
    mesh.triangles.push_back(corners);
  }
  return mesh;
}

using mesh_detail::lower_extension;

}  // namespace

const char* to_string(MeshFormat format) noexcept {
  switch (format) {
    case MeshFormat::kObj: return "OBJ";
    case MeshFormat::kStlAscii: return "ASCII STL";
    case MeshFormat::kStlBinary: return "binary STL";
  }
  return "?";
}

MeshFile read_mesh_file(const std::string& path, std::size_t max_triangles) {
  std::error_code code;
  const std::string ext = lower_extension(path);
  if (std::filesystem::is_directory(path, code)) {
    throw MeshError(quoted(path) + " is a directory, not " + (ext == ".obj" ? "an OBJ file" : ext == ".stl" ? "an STL file" : "a mesh file"));
  }
  if (ext != ".obj" && ext != ".stl") throw MeshError(quoted(path) + ": unknown mesh format '" + ext + "' (expected .obj or .stl)");
  std::ifstream probe(path, std::ios::binary);
  if (!probe) throw MeshError("cannot open " + quoted(path));
  if (ext == ".obj") return read_obj(path, max_triangles);
  const std::string bytes((std::istreambuf_iterator<char>(probe)), std::istreambuf_iterator<char>());
  if (bytes.size() >= 84) {
    std::uint32_t count = 0;
    for (int k = 3; k >= 0; --k) count = (count << 8) | static_cast<unsigned char>(bytes[80 + static_cast<std::size_t>(k)]);
    if (bytes.size() == 84 + 50 * static_cast<std::size_t>(count)) return read_stl_binary(path, bytes, max_triangles);
  }
  std::size_t first = 0;
  while (first < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[first])) != 0) ++first;
  if (bytes.compare(first, 5, "solid") == 0) return read_stl_ascii(path, max_triangles);
  std::string why = "neither ASCII STL (it does not start with 'solid') nor binary STL (";
  if (bytes.size() < 84) {
    why += "shorter than the 84-byte header: " + std::to_string(bytes.size()) + " bytes)";
  } else {
    std::uint32_t count = 0;
    for (int k = 3; k >= 0; --k) count = (count << 8) | static_cast<unsigned char>(bytes[80 + static_cast<std::size_t>(k)]);
    why += "its header says " + std::to_string(count) + " triangles, " + std::to_string(84 + 50 * static_cast<std::size_t>(count)) +
           " bytes, the file has " + std::to_string(bytes.size()) + ")";
  }
  throw MeshError(quoted(path) + " is " + why);
}

std::string triangle_name(const MeshFile& mesh, int triangle) {
  std::string name = "triangle " + std::to_string(triangle + 1);
  if (static_cast<std::size_t>(triangle) < mesh.triangle_lines.size()) {
    name += " (line " + std::to_string(mesh.triangle_lines[static_cast<std::size_t>(triangle)]) + ")";
  }
  return name;
}

}  // namespace fissure::host
