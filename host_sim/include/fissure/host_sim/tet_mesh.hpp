#pragma once
// A tetrahedral (volume) mesh of a soft body (issue 24): what a `.msh` / `.vtk` reader, the
// built-in generators (a box, a tube) and TetGen's output become before it is checked
// (tet_mesh_checks.hpp) and built into a volumetric Bullet body (soft_body_builder.hpp
// create_from_tet_mesh). SI units, world frame.
//
// Orientation: every tetrahedron (a, b, c, d) has a positive signed volume
// (b − a)·((c − a) × (d − a)) / 6 > 0. A linear tetrahedron's corner order carries nothing but
// this orientation, so the readers turn an inverted element round (tet_mesh_file.hpp) and
// refuse a degenerate one naming it; check_tet_mesh refuses a generated mesh that is not positive.
#include <array>
#include <string>
#include <vector>

#include "fissure/shared/messages.hpp"

namespace fissure::host {

struct TetMesh {
  /// Where the mesh came from: a file path, or the generator and its parameters (for errors).
  std::string source;
  std::vector<Vec3> vertices_m;
  /// Corner indices into vertices_m, 0-based.
  std::vector<std::array<int, 4>> tetrahedra;
  /// The line each tetrahedron was read from (text formats), 1-based; empty for generated meshes.
  std::vector<int> tetrahedron_lines;
  /// How many inverted elements a reader turned round (swapped its last two corners): a file
  /// written with the other orientation convention has all of them; 0 for generated meshes.
  int reordered_count = 0;
};

}  // namespace fissure::host
