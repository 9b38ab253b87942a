#pragma once
// Tetrahedral mesh files for volumetric soft bodies (issue 24, "Import"): Gmsh `.msh` 4.1 ASCII,
// VTK legacy ASCII unstructured grids (`.vtk`, versions up to 5.1) and TetGen's `.node` / `.ele`
// pair. The format comes from the extension (case-insensitive; a TetGen mesh is named by either
// file of its pair). Only 4-node tetrahedra are read: Gmsh element type 4, VTK cell type 10,
// TetGen's first four corners; every other element (points, lines, boundary triangles, second-
// order elements) is skipped. Read in one pass over the file's text, linear in its size.
//
// Orientation (tet_mesh.hpp): a linear tetrahedron's corner order carries nothing but its
// orientation, so an inverted element (negative signed volume, a writer with the other
// convention) is turned round by swapping its last two corners and counted in reordered_count;
// an element whose 6·|volume| is at most kDegenerateVolumeRelative × (mesh diagonal)³ is refused.
//
// Errors (MeshError, mesh_file.hpp) name the file, the line, the element or node as the file
// numbers it (Gmsh tag, VTK cell id from 0, TetGen number), what is wrong and the range
// expected: "'PATH' line 12: node 5 coordinate y is 'nan', not a finite number".
#include <cstddef>
#include <string>

#include "fissure/host_sim/mesh_file.hpp"
#include "fissure/host_sim/tet_mesh.hpp"

namespace fissure::host {

/// An element is degenerate when 6·|volume| ≤ this × (bounding-box diagonal)³: a sliver whose
/// rest volume Bullet divides by (the same relative 1e-12 as a surface triangle's cross product).
inline constexpr double kDegenerateVolumeRelative = 1e-12;

/// True for the extensions read_tet_mesh_file reads: .msh, .vtk, .node, .ele.
[[nodiscard]] bool is_tet_mesh_path(const std::string& path);

/// Reads a Gmsh / VTK / TetGen tetrahedral mesh (by extension). Throws MeshError for a missing
/// file, an unknown extension, a binary file, a syntax error, a missing section, counts that
/// disagree, a node index out of range, a non-finite coordinate, a degenerate tetrahedron, no
/// tetrahedron at all, or more than max_tetrahedra (checked against the count the file
/// announces before its elements are read). The shape is NOT checked here (tet_mesh_checks.hpp).
[[nodiscard]] TetMesh read_tet_mesh_file(const std::string& path, std::size_t max_tetrahedra);

/// "tetrahedron 7 (line 40)" / "tetrahedron 7": index 0-based in, 1-based out.
[[nodiscard]] std::string tetrahedron_name(const TetMesh& mesh, int tetrahedron);

}  // namespace fissure::host
