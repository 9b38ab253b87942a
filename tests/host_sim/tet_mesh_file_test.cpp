// Tetrahedral mesh files: a cube of 5 tetrahedra reads identically from Gmsh, VTK (3.0, 5.1)
// and TetGen files; inverted elements are turned round, and every unreadable file is refused
// naming the file, the line, the element or node and what is wrong.
#include "fissure/host_sim/tet_mesh_file.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "mesh_test_meshes.hpp"
#include "tet_test_meshes.hpp"

namespace fissure::host {
namespace {

namespace tt = test_tets;
namespace fs = std::filesystem;

std::string error_of(const std::string& path, std::size_t max_tetrahedra = 1000) {
  try {
    (void)read_tet_mesh_file(path, max_tetrahedra);
  } catch (const MeshError& e) {
    return e.what();
  }
  return "(no error)";
}

#define EXPECT_ERROR(path, text) EXPECT_NE(error_of(path).find(text), std::string::npos) << error_of(path)

TEST(TetMeshFile, CubeReadsIdenticallyFromAllFormats) {
  const fs::path dir = test_meshes::scratch_dir("tet_mesh_same");
  const TetMesh cube = tt::cube5(0.04, 0.02, 0.03);
  struct Case {
    std::string path;
    std::vector<int> lines;
  };
  std::vector<Case> cases;
  const auto lines = [&](auto line_of) {
    std::vector<int> l;
    for (std::size_t t = 0; t < cube.tetrahedra.size(); ++t) l.push_back(line_of(t));
    return l;
  };
  cases.push_back({tt::write_msh(cube, dir / "cube.msh"), lines([&](std::size_t t) { return tt::msh_tet_line(cube, t); })});
  cases.push_back({tt::write_vtk(cube, dir / "cube.vtk"), lines([&](std::size_t t) { return tt::vtk_tet_line(cube, t); })});
  cases.push_back({tt::write_vtk(cube, dir / "cube51.VTK", true), lines([&](std::size_t t) { return tt::vtk_tet_line(cube, t, true); })});
  cases.push_back({tt::write_tetgen(cube, dir / "cube"), lines([](std::size_t t) { return static_cast<int>(3 + t); })});
  cases.push_back({(dir / "cube.ele").string(), cases.back().lines});
  for (const Case& c : cases) {
    const TetMesh m = read_tet_mesh_file(c.path, 1000);
    EXPECT_EQ(m.source, c.path);
    // Gmsh's file has a ninth, unused geometry node (last): the reader keeps it, weld_and_compact drops it.
    ASSERT_GE(m.vertices_m.size(), 8U) << c.path;
    for (std::size_t i = 0; i < 8; ++i) EXPECT_EQ(m.vertices_m[i], cube.vertices_m[i]) << c.path << " vertex " << i;
    EXPECT_EQ(m.tetrahedra, cube.tetrahedra) << c.path;
    EXPECT_EQ(m.tetrahedron_lines, c.lines) << c.path;
    EXPECT_EQ(m.reordered_count, 0) << c.path;
  }
  EXPECT_EQ(read_tet_mesh_file(cases[0].path, 1000).vertices_m.size(), 9U);
  const TetMesh vtk = read_tet_mesh_file(cases[1].path, 1000);
  EXPECT_EQ(tetrahedron_name(vtk, 1), "tetrahedron 2 (line " + std::to_string(tt::vtk_tet_line(cube, 1)) + ")");
}

TEST(TetMeshFile, InvertedElementsAreTurnedRound) {
  const fs::path dir = test_meshes::scratch_dir("tet_mesh_inverted");
  TetMesh cube = tt::cube5();
  std::swap(cube.tetrahedra[1][0], cube.tetrahedra[1][1]);
  std::swap(cube.tetrahedra[4][2], cube.tetrahedra[4][3]);
  for (const std::string& path : {tt::write_msh(cube, dir / "inv.msh"), tt::write_vtk(cube, dir / "inv.vtk"), tt::write_tetgen(cube, dir / "inv")}) {
    const TetMesh m = read_tet_mesh_file(path, 1000);
    EXPECT_EQ(m.reordered_count, 2) << path;
    for (std::size_t t = 0; t < m.tetrahedra.size(); ++t) EXPECT_GT(tt::volume6(m, m.tetrahedra[t]), 0.0) << path << " tetrahedron " << t;
    EXPECT_EQ(m.tetrahedra[1], (std::array<int, 4>{cube.tetrahedra[1][0], cube.tetrahedra[1][1], cube.tetrahedra[1][3], cube.tetrahedra[1][2]}))
        << "the last two corners swapped";
    EXPECT_EQ(m.tetrahedra[0], cube.tetrahedra[0]);
  }
}

TEST(TetMeshFile, DegenerateElementIsRefusedWithItsLineAndVolume) {
  const fs::path dir = test_meshes::scratch_dir("tet_mesh_degenerate");
  TetMesh cube = tt::cube5();
  cube.tetrahedra[2] = {0, 1, 2, 3};  // the four corners of the bottom face: flat
  EXPECT_ERROR(tt::write_msh(cube, dir / "flat.msh"),
               "flat.msh' line " + std::to_string(tt::msh_tet_line(cube, 2)) + ": element 102 is degenerate: volume 0 m³ (nodes 7, 17, 27, 37)");
  EXPECT_ERROR(tt::write_vtk(cube, dir / "flat.vtk"), "flat.vtk' line " + std::to_string(tt::vtk_tet_line(cube, 2)) + ": cell 3 is degenerate: volume 0 m³");
  tt::write_tetgen(cube, dir / "flat");
  EXPECT_ERROR((dir / "flat.node").string(), "flat.ele' line 5: tetrahedron 3 is degenerate: volume 0 m³ (points 1, 2, 3, 4), a tetrahedron needs more than");
}

TEST(TetMeshFile, GmshErrorsNameLineAndElement) {
  const fs::path dir = test_meshes::scratch_dir("tet_mesh_gmsh_errors");
  const TetMesh cube = tt::cube5();
  const auto fresh = [&](const std::string& name) { return tt::write_msh(cube, dir / name); };
  std::string p = fresh("v22.msh");
  tt::edit(p, "4.1 0 8", "2.2 0 8");
  EXPECT_ERROR(p, "v22.msh' line 2: Gmsh format version 2.2; this reader reads 4.1 (save with: gmsh FILE.geo -3 -format msh41");
  p = fresh("binary.msh");
  tt::edit(p, "4.1 0 8", "4.1 1 8");
  EXPECT_ERROR(p, "binary.msh' line 2: a binary .msh; save it as ASCII");
  p = fresh("no-elements.msh");
  tt::edit(p, "$Elements", "$Unknown");
  tt::edit(p, "$EndElements", "$EndUnknown");
  EXPECT_ERROR(p, "no-elements.msh': no $Elements section (a Gmsh mesh has $MeshFormat, $Nodes and $Elements)");
  p = fresh("unclosed.msh");
  tt::edit(p, "$EndPhysicalNames", "");
  EXPECT_ERROR(p, "section $PhysicalNames (line 4) is not closed by $EndPhysicalNames");
  p = fresh("count.msh");
  tt::edit(p, "$Nodes\n2 9", "$Nodes\n2 10");
  EXPECT_ERROR(p, "count.msh' line 30: the $Nodes header announces 10 nodes, its blocks hold 9");
  p = fresh("elements-count.msh");
  tt::edit(p, "$Elements\n3 7", "$Elements\n3 6");
  EXPECT_ERROR(p, "element block 3 holds 5 elements, but only 4 of the header's numElements 6 are left");
  p = fresh("tag.msh");
  tt::edit(p, "\n102 ", "\n102 99 ");
  EXPECT_ERROR(p, "tag.msh' line " + std::to_string(tt::msh_tet_line(cube, 2)) + ": element 102 corner 1 is node 99, which $Nodes does not hold (it holds 9 nodes)");
  p = fresh("nan.msh");
  tt::edit(p, "\n1 0 0\n", "\n1 nan 0\n");
  EXPECT_ERROR(p, "nan.msh' line 20: node 17 coordinate y is 'nan', not a finite number");
  p = fresh("surface.msh");
  tt::edit(p, "3 1 4 5", "3 1 11 5");  // the tetrahedra declared second-order: skipped, none left
  EXPECT_ERROR(p, "surface.msh': no 4-node tetrahedron (element type 4) among its 7 elements");
  EXPECT_NE(error_of(fresh("large.msh"), 4).find("large.msh' line 37: too large: 5 tetrahedra, the limit is 4"), std::string::npos) << error_of(fresh("large.msh"), 4);
}

TEST(TetMeshFile, VtkErrorsNameLineAndCell) {
  const fs::path dir = test_meshes::scratch_dir("tet_mesh_vtk_errors");
  const TetMesh cube = tt::cube5();
  const auto fresh = [&](const std::string& name, bool v5 = false) { return tt::write_vtk(cube, dir / name, v5); };
  std::string p = fresh("binary.vtk");
  tt::edit(p, "ASCII", "BINARY");
  EXPECT_ERROR(p, "binary.vtk' line 3: a BINARY VTK file; save it as ASCII");
  p = fresh("polydata.vtk");
  tt::edit(p, "UNSTRUCTURED_GRID", "POLYDATA");
  EXPECT_ERROR(p, "polydata.vtk' line 4: DATASET POLYDATA: tetrahedra come in an UNSTRUCTURED_GRID");
  p = fresh("no-types.vtk");
  tt::edit(p, "CELL_TYPES 6\n5\n10\n10\n10\n10\n10\nCELL_DATA", "CELL_DATA");
  EXPECT_ERROR(p, "no-types.vtk' line 21: expected POINTS, CELLS or CELL_TYPES, got 'CELL_DATA'");
  p = fresh("truncated.vtk");
  tt::edit(p, "CELL_TYPES 6\n5\n10\n10\n10\n10\n10\nCELL_DATA 6\nSCALARS region int 1\nLOOKUP_TABLE default\n1\n1\n1\n1\n1\n1\n", "");
  EXPECT_ERROR(p, "truncated.vtk': no CELL_TYPES section (an unstructured grid has POINTS, CELLS and CELL_TYPES)");
  p = fresh("size.vtk");
  tt::edit(p, "CELLS 6 29", "CELLS 6 30");
  EXPECT_ERROR(p, "size.vtk' line 20: the CELLS size is 30, the cells hold 29 numbers");
  p = fresh("types.vtk");
  tt::edit(p, "CELL_TYPES 6", "CELL_TYPES 5");
  EXPECT_ERROR(p, "types.vtk' line 21: the CELL_TYPES count is 5, expected 6 .. 6");
  p = fresh("index.vtk");
  tt::edit(p, "\n4 2 1 6 3\n", "\n4 2 1 6 8\n");
  EXPECT_ERROR(p, "index.vtk' line 17: cell 2 corner 4 is point 8, the file has points 0 .. 7");
  p = fresh("nan.vtk");
  tt::edit(p, "\n1 1 0\n", "\n1 inf 0\n");
  EXPECT_ERROR(p, "nan.vtk' line 8: point 2 coordinate y is 'inf', not a finite number");
  p = fresh("offsets.vtk", true);
  tt::edit(p, "0 3 7", "0 3 9");
  EXPECT_ERROR(p, "offsets.vtk' line 19: cell 1 is a tetrahedron (type 10) with 6 points, not 4");
  p = fresh("notvtk.vtk");
  tt::edit(p, "# vtk DataFile", "# VTK file");
  EXPECT_ERROR(p, "notvtk.vtk' line 1: not a VTK legacy file");
}

TEST(TetMeshFile, TetGenErrorsNameFileLineAndPoint) {
  const fs::path dir = test_meshes::scratch_dir("tet_mesh_tetgen_errors");
  const TetMesh cube = tt::cube5();
  std::string p = tt::write_tetgen(cube, dir / "lonely");
  fs::remove(dir / "lonely.ele");
  EXPECT_ERROR(p, "cannot open '" + (dir / "lonely.ele").string() + "' (a TetGen mesh is the pair");
  p = tt::write_tetgen(cube, dir / "count");
  tt::edit(p, "8 3 0 1", "9 3 0 1");
  EXPECT_ERROR(p, "count.node' line 11: the file ends where point number is expected");
  p = tt::write_tetgen(cube, dir / "numbering");
  tt::edit(p, "\n3  ", "\n4  ");
  EXPECT_ERROR(p, "numbering.node' line 4: point number is 4, expected 3 .. 3");
  p = tt::write_tetgen(cube, dir / "index");
  tt::edit((dir / "index.ele").string(), "\n4 ", "\n4 9 ");
  EXPECT_ERROR(p, "index.ele' line 6: tetrahedron 4 node 1 is point 9, the .node file has points 1 .. 8");
  p = tt::write_tetgen(cube, dir / "nan");
  tt::edit(p, "\n2  1 ", "\n2  NaN ");
  EXPECT_ERROR(p, "nan.node' line 3: point 2 coordinate x is 'NaN', not a finite number");
  p = tt::write_tetgen(cube, dir / "big");
  EXPECT_NE(error_of(p, 4).find("big.ele' line 2: too large: 5 tetrahedra, the limit is 4"), std::string::npos) << error_of(p, 4);
}

TEST(TetMeshFile, UnknownExtensionsAndMissingFiles) {
  const fs::path dir = test_meshes::scratch_dir("tet_mesh_misc");
  EXPECT_TRUE(is_tet_mesh_path("a/B.MSH"));
  EXPECT_TRUE(is_tet_mesh_path("x.ele"));
  EXPECT_FALSE(is_tet_mesh_path("x.obj"));
  EXPECT_ERROR((dir / "x.obj").string(), "x.obj': unknown tetrahedral mesh format '.obj' (expected .msh, .vtk, or a TetGen .node / .ele)");
  EXPECT_EQ(error_of((dir / "missing.msh").string()), "cannot open '" + (dir / "missing.msh").string() + "'");
}

}  // namespace
}  // namespace fissure::host
