#pragma once
// Small closed meshes for the mesh import tests: a unit cube (12 outward triangles) and its
// files in OBJ, ASCII STL and binary STL.
#include <array>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "fissure/shared/messages.hpp"

namespace fissure::host::test_meshes {

struct Mesh {
  std::vector<Vec3> vertices_m;
  std::vector<std::array<int, 3>> triangles;
};

/// The cube [0, sx] × [0, sy] × [0, sz], counter-clockwise seen from outside.
inline Mesh cube(double sx = 1.0, double sy = 1.0, double sz = 1.0) {
  Mesh m;
  for (int i = 0; i < 8; ++i) {
    const int x = (i == 1 || i == 2 || i == 5 || i == 6) ? 1 : 0;
    const int y = (i == 2 || i == 3 || i == 6 || i == 7) ? 1 : 0;
    const int z = i >= 4 ? 1 : 0;
    m.vertices_m.push_back({sx * x, sy * y, sz * z});
  }
  m.triangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                 {3, 7, 6}, {3, 6, 2}, {0, 4, 7}, {0, 7, 3}, {1, 2, 6}, {1, 6, 5}};
  return m;
}

inline std::filesystem::path scratch_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("fissure_" + name);
  std::filesystem::create_directories(dir);
  return dir;
}

inline std::string write_obj(const Mesh& m, const std::filesystem::path& path) {
  std::ofstream out(path);
  out << "# test mesh\n";
  out.precision(17);
  for (const Vec3& v : m.vertices_m) out << "v " << v[0] << ' ' << v[1] << ' ' << v[2] << '\n';
  for (const auto& t : m.triangles) out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
  return path.string();
}

/// ASCII STL: line 1 "solid", then 7 lines per facet (facet i starts at line 2 + 7·i).
inline std::string write_stl_ascii(const Mesh& m, const std::filesystem::path& path) {
  std::ofstream out(path);
  out.precision(17);
  out << "solid test\n";
  for (const auto& t : m.triangles) {
    out << "  facet normal 0 0 0\n    outer loop\n";
    for (int k : t) out << "      vertex " << m.vertices_m[k][0] << ' ' << m.vertices_m[k][1] << ' ' << m.vertices_m[k][2] << '\n';
    out << "    endloop\n  endfacet\n";
  }
  out << "endsolid test\n";
  return path.string();
}

inline void put_u32(std::string& bytes, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) bytes.push_back(static_cast<char>((v >> (8 * k)) & 0xFFU));
}
inline void put_f32(std::string& bytes, float f) {
  std::uint32_t bits = 0;
  std::memcpy(&bits, &f, sizeof bits);
  put_u32(bytes, bits);
}

/// Binary STL bytes (header "solid …" on purpose: binary files often start so).
inline std::string stl_binary_bytes(const Mesh& m) {
  std::string bytes = "solid but binary";
  bytes.resize(80, ' ');
  put_u32(bytes, static_cast<std::uint32_t>(m.triangles.size()));
  for (const auto& t : m.triangles) {
    for (int k = 0; k < 3; ++k) put_f32(bytes, 0.0F);
    for (int c : t)
      for (int a = 0; a < 3; ++a) put_f32(bytes, static_cast<float>(m.vertices_m[static_cast<std::size_t>(c)][static_cast<std::size_t>(a)]));
    bytes.push_back(0);
    bytes.push_back(0);
  }
  return bytes;
}

inline std::string write_bytes(const std::string& bytes, const std::filesystem::path& path) {
  std::ofstream(path, std::ios::binary) << bytes;
  return path.string();
}

}  // namespace fissure::host::test_meshes
