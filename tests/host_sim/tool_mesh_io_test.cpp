// Convex tool meshes from files: OBJ and STL (ASCII, binary) give the same checked tool, and a
// mesh that is no convex thin tool is refused naming the file, the element and the reason.
#include "fissure/host_sim/tool_mesh_io.hpp"

#include <gtest/gtest.h>

#include <string>

#include "fissure/host_sim/thin_tool.hpp"
#include "mesh_test_meshes.hpp"

namespace fissure::host {
namespace {

namespace tm = test_meshes;

std::string error_of(const std::string& path) {
  try {
    (void)read_tool_mesh(path);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

tm::Mesh shipped_spatula() {
  RoundedSpatulaParams p;
  p.length_m = 0.06;
  p.width_m = 0.025;
  p.corner_segments = 6;
  p.rim_segments = 6;
  const ConvexMeshToolShape shape = make_rounded_spatula_mesh(p, 0.0);
  tm::Mesh m;
  for (const auto& v : shape.vertices_tool_m) m.vertices_m.push_back({v.x(), v.y(), v.z()});
  m.triangles = shape.triangles;
  return m;
}

TEST(ToolMeshIo, ObjAndStlGiveTheSameTool) {
  const auto dir = tm::scratch_dir("tool_mesh_io_same");
  const tm::Mesh spatula = shipped_spatula();
  const ToolMesh obj = read_tool_mesh(tm::write_obj(spatula, dir / "spatula.obj"));
  const ToolMesh ascii = read_tool_mesh(tm::write_stl_ascii(spatula, dir / "spatula.stl"));
  const ToolMesh binary = read_tool_mesh(tm::write_bytes(tm::stl_binary_bytes(spatula), dir / "spatula-binary.stl"));
  EXPECT_EQ(obj.vertices_m.size(), spatula.vertices_m.size());
  EXPECT_EQ(ascii.vertices_m.size(), spatula.vertices_m.size()) << "STL corners welded back into the mesh's vertices";
  EXPECT_EQ(binary.vertices_m.size(), spatula.vertices_m.size());
  EXPECT_EQ(obj.triangles, spatula.triangles);
  EXPECT_EQ(ascii.triangles.size(), spatula.triangles.size());
  EXPECT_EQ(binary.triangles.size(), spatula.triangles.size());
}

TEST(ToolMeshIo, RefusalsNameFileElementAndReason) {
  const auto dir = tm::scratch_dir("tool_mesh_io_errors");
  // A thin box (y thinnest) with its top face's centre pulled up: not convex.
  tm::Mesh dented = tm::cube(0.04, 0.004, 0.03);
  dented.vertices_m.push_back({0.02, 0.003, 0.015});
  dented.triangles.erase(dented.triangles.begin() + 6, dented.triangles.begin() + 8);  // the +y face (3, 7, 6), (3, 6, 2)
  dented.triangles.push_back({3, 7, 8});
  dented.triangles.push_back({7, 6, 8});
  dented.triangles.push_back({6, 2, 8});
  dented.triangles.push_back({2, 3, 8});
  const std::string dented_path = tm::write_stl_ascii(dented, dir / "dented.stl");
  const std::string dented_error = error_of(dented_path);
  EXPECT_NE(dented_error.find("dented.stl': triangle "), std::string::npos) << dented_error;
  EXPECT_NE(dented_error.find(": not convex: vertex "), std::string::npos) << dented_error;
  EXPECT_NE(dented_error.find("outside its plane (tolerance "), std::string::npos) << dented_error;
  // Open, binary: names the triangle (no line in a binary file; STL vertices are numbered in
  // the order they first appear, here 1 2 3 / 4 ... so the cube's vertex 2 is the file's 3).
  tm::Mesh open = tm::cube(0.04, 0.004, 0.03);
  open.triangles.pop_back();
  EXPECT_NE(error_of(tm::write_bytes(tm::stl_binary_bytes(open), dir / "open.stl")).find("open.stl': triangle 5: open: its edge 3–6 has no other triangle"),
            std::string::npos)
      << error_of((dir / "open.stl").string());
  // Thin axis not y.
  EXPECT_NE(error_of(tm::write_obj(tm::cube(0.004, 0.04, 0.03), dir / "upright.obj")).find("upright.obj': the thin axis must be local y"),
            std::string::npos);
  // Every triangle inward (OBJ): inverted.
  tm::Mesh inverted = tm::cube(0.04, 0.004, 0.03);
  for (auto& t : inverted.triangles) std::swap(t[1], t[2]);
  EXPECT_NE(error_of(tm::write_obj(inverted, dir / "inverted.obj")).find("inverted.obj': inverted: the triangles face inwards"), std::string::npos)
      << error_of((dir / "inverted.obj").string());
  // A degenerate triangle, with its OBJ line.
  tm::Mesh degenerate = tm::cube(0.04, 0.004, 0.03);
  degenerate.triangles[2] = {4, 5, 5};
  EXPECT_NE(error_of(tm::write_obj(degenerate, dir / "degenerate.obj")).find("degenerate.obj': triangle 3 (line 12): degenerate (vertices 5, 6, 6"),
            std::string::npos)
      << error_of((dir / "degenerate.obj").string());
}

// check_tool_mesh (the in-memory check `fissure sim --write-meshes` runs) names the element too.
TEST(ToolMeshIo, InMemoryCheckNamesTheElement) {
  tm::Mesh open = tm::cube(0.04, 0.004, 0.03);
  open.triangles.pop_back();
  try {
    check_tool_mesh(ToolMesh{open.vertices_m, open.triangles});
    FAIL() << "an open mesh passed";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("triangle 5: open:", 0), 0U) << e.what();
  }
  const tm::Mesh spatula = shipped_spatula();
  EXPECT_NO_THROW(check_tool_mesh(ToolMesh{spatula.vertices_m, spatula.triangles}));
}

}  // namespace
}  // namespace fissure::host
