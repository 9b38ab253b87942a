// OBJ / STL mesh files: the three formats give the same mesh, and every unreadable file is
// refused naming the file, the element (line, triangle) and the reason.
#include "fissure/host_sim/mesh_file.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "mesh_test_meshes.hpp"

namespace fissure::host {
namespace {

namespace tm = test_meshes;

std::string error_of(const std::string& path, std::size_t max_triangles = 1000) {
  try {
    (void)read_mesh_file(path, max_triangles);
  } catch (const MeshError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(MeshFile, ObjAsciiStlAndBinaryStlGiveTheSameMesh) {
  const auto dir = tm::scratch_dir("mesh_file_same");
  const tm::Mesh cube = tm::cube(0.04, 0.002, 0.03);
  const MeshFile obj = read_mesh_file(tm::write_obj(cube, dir / "cube.obj"), 1000);
  const MeshFile ascii = read_mesh_file(tm::write_stl_ascii(cube, dir / "cube.stl"), 1000);
  const MeshFile binary = read_mesh_file(tm::write_bytes(tm::stl_binary_bytes(cube), dir / "cube-binary.STL"), 1000);
  EXPECT_EQ(obj.format, MeshFormat::kObj);
  EXPECT_EQ(ascii.format, MeshFormat::kStlAscii);
  EXPECT_EQ(binary.format, MeshFormat::kStlBinary) << "a binary STL whose header starts with 'solid' is still binary";
  for (const MeshFile* m : {&obj, &ascii, &binary}) {
    ASSERT_EQ(m->vertices_m.size(), 8U) << to_string(m->format) << ": STL corners welded into the cube's 8 vertices";
    ASSERT_EQ(m->triangles.size(), 12U);
    for (std::size_t t = 0; t < 12; ++t) {
      for (std::size_t k = 0; k < 3; ++k) {
        const Vec3& got = m->vertices_m[static_cast<std::size_t>(m->triangles[t][k])];
        const Vec3& want = cube.vertices_m[static_cast<std::size_t>(cube.triangles[t][k])];
        // ASCII STL is parsed in double; binary STL stores float32 and tinyobjloader reads float.
        for (std::size_t a = 0; a < 3; ++a) EXPECT_NEAR(got[a], want[a], m == &ascii ? 0.0 : 1e-7 * std::abs(want[a])) << to_string(m->format);
      }
    }
  }
  EXPECT_EQ(obj.triangle_lines.front(), 10) << "comment + 8 vertex lines, then the faces";
  EXPECT_EQ(ascii.triangle_lines[1], 9) << "facet 2 starts at line 2 + 7";
  EXPECT_TRUE(binary.triangle_lines.empty());
  EXPECT_EQ(triangle_name(ascii, 1), "triangle 2 (line 9)");
  EXPECT_EQ(triangle_name(binary, 1), "triangle 2");
}

TEST(MeshFile, ObjPolygonsAreFanTriangulatedWithTheirLine) {
  const auto dir = tm::scratch_dir("mesh_file_quads");
  std::ofstream(dir / "quad.obj") << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nf 1 2 3 4\nf 1 2 5\n";
  const MeshFile m = read_mesh_file((dir / "quad.obj").string(), 10);
  ASSERT_EQ(m.triangles.size(), 3U);
  EXPECT_EQ(m.triangle_lines, (std::vector<int>{6, 6, 7}));
}

TEST(MeshFile, RefusesNamingFileElementAndReason) {
  const auto dir = tm::scratch_dir("mesh_file_errors");
  const tm::Mesh cube = tm::cube();
  // Missing, directory, unknown extension.
  EXPECT_EQ(error_of((dir / "missing.stl").string()), "cannot open '" + (dir / "missing.stl").string() + "'");
  std::filesystem::create_directories(dir / "folder.stl");
  EXPECT_NE(error_of((dir / "folder.stl").string()).find("folder.stl' is a directory, not an STL file"), std::string::npos);
  std::ofstream(dir / "cube.ply") << "ply\n";
  EXPECT_NE(error_of((dir / "cube.ply").string()).find("cube.ply': unknown mesh format '.ply' (expected .obj or .stl)"), std::string::npos);
  // ASCII STL: a non-finite coordinate, a quad facet, a missing endsolid, a bad keyword — each with its line.
  std::string text;
  {
    const std::string path = tm::write_stl_ascii(cube, dir / "nan.stl");
    std::ifstream in(path);
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  std::string nan = text;
  nan.replace(nan.find("vertex 0 0 0"), 12, "vertex 0 nan 0");
  std::ofstream(dir / "nan.stl") << nan;
  EXPECT_NE(error_of((dir / "nan.stl").string()).find("nan.stl' line 4: vertex coordinate y is 'nan', not a finite number"), std::string::npos)
      << error_of((dir / "nan.stl").string());
  std::string quad = text;
  quad.replace(quad.find("    endloop"), 11, "      vertex 0 0 1\n    endloop");
  std::ofstream(dir / "quad.stl") << quad;
  EXPECT_NE(error_of((dir / "quad.stl").string()).find("quad.stl' line 7: the facet at line 2 has more than 3 vertices"), std::string::npos)
      << error_of((dir / "quad.stl").string());
  std::ofstream(dir / "cut.stl") << text.substr(0, text.find("endsolid"));
  EXPECT_NE(error_of((dir / "cut.stl").string()).find("cut.stl' line 86: the file ends inside a solid"), std::string::npos)
      << error_of((dir / "cut.stl").string());
  std::string typo = text;
  typo.replace(typo.find("endfacet"), 8, "endfacett");
  std::ofstream(dir / "typo.stl") << typo;
  EXPECT_NE(error_of((dir / "typo.stl").string()).find("typo.stl' line 8: expected 'endfacet', got 'endfacett'"), std::string::npos);
  // Binary STL: a non-finite coordinate names the triangle and corner; a truncated file is neither format.
  std::string bytes = tm::stl_binary_bytes(cube);
  const float inf = std::numeric_limits<float>::infinity();
  std::memcpy(&bytes[84 + 50 * 4 + 12 + 12 + 8], &inf, 4);  // triangle 5, corner 2, z
  EXPECT_NE(error_of(tm::write_bytes(bytes, dir / "inf.stl")).find("inf.stl': triangle 5 corner 2 coordinate z is inf, not a finite number"),
            std::string::npos)
      << error_of((dir / "inf.stl").string());
  const std::string cut = tm::stl_binary_bytes(cube).substr(0, 84 + 50 * 11);
  std::string cut_bytes = cut;
  cut_bytes.replace(0, 5, "xxxxx");
  EXPECT_NE(error_of(tm::write_bytes(cut_bytes, dir / "short.stl"))
                .find("short.stl' is neither ASCII STL (it does not start with 'solid') nor binary STL (its header says 12 triangles, 684 bytes, "
                      "the file has 634)"),
            std::string::npos)
      << error_of((dir / "short.stl").string());
}

// Too large: refused with the count and the limit; a binary STL's header count is checked
// before its triangles are read.
TEST(MeshFile, RefusesMoreTrianglesThanTheLimit) {
  const auto dir = tm::scratch_dir("mesh_file_large");
  const tm::Mesh cube = tm::cube();
  EXPECT_NE(error_of(tm::write_bytes(tm::stl_binary_bytes(cube), dir / "big.stl"), 11).find("big.stl': too large: 12 triangles, the limit is 11"),
            std::string::npos);
  EXPECT_NE(error_of(tm::write_stl_ascii(cube, dir / "big-ascii.stl"), 11).find("big-ascii.stl' line 85: too large: 12 triangles, the limit is 11"),
            std::string::npos)
      << error_of((dir / "big-ascii.stl").string(), 11);
  EXPECT_NE(error_of(tm::write_obj(cube, dir / "big.obj"), 11).find("big.obj': too large: 12 triangles, the limit is 11 (at line 21)"),
            std::string::npos)
      << error_of((dir / "big.obj").string(), 11);
}

}  // namespace
}  // namespace fissure::host
