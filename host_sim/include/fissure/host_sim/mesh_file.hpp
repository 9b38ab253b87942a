#pragma once
// Closed triangle meshes as files, for tools and soft bodies (issue 24, "Import"): Wavefront
// OBJ (tinyobjloader, polygons fan-triangulated) and STL, ASCII or binary (our reader: STL has
// no index, so vertices with bit-identical coordinates are welded into one). The format comes
// from the extension (.obj, .stl; case-insensitive); ASCII or binary STL from the content (a
// binary file's size is 84 + 50 bytes per triangle, whatever its header says).
//
// Errors name the file, the element and the reason: "'PATH' line 12: …" while parsing, and
// "'PATH': triangle 7 (line 40): …" / "'PATH': vertex 3: …" from the shape
// checks (mesh_checks.hpp). Triangles and vertices are numbered from 1 in the order of the file
// (an STL's welded vertices in the order they first appear).
#include <array>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "fissure/shared/messages.hpp"

namespace fissure::host {

enum class MeshFormat : std::uint8_t { kObj, kStlAscii, kStlBinary };
[[nodiscard]] const char* to_string(MeshFormat format) noexcept;

struct MeshFile {
  std::string path;
  MeshFormat format = MeshFormat::kObj;
  std::vector<Vec3> vertices_m;
  std::vector<std::array<int, 3>> triangles;
  /// The line each triangle was read from (text formats), 1-based; empty for binary STL.
  std::vector<int> triangle_lines;
};

/// A mesh file that cannot be used; what() names the file, the element and the reason.
class MeshError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Reads an OBJ or STL file (by extension). Throws MeshError for a missing file, a directory,
/// an unknown extension, a syntax error, a coordinate that is not a finite number, or more
/// than max_triangles triangles (checked before the triangles are read where the format says
/// its count: binary STL). The shape is NOT checked here (mesh_checks.hpp).
[[nodiscard]] MeshFile read_mesh_file(const std::string& path, std::size_t max_triangles);

/// "triangle 7 (line 40)" / "triangle 7" (binary STL): triangle index 0-based in, 1-based out.
[[nodiscard]] std::string triangle_name(const MeshFile& mesh, int triangle);

}  // namespace fissure::host
