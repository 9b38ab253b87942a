#pragma once
// A tetrahedral (volume) mesh of a soft body (issue 24): what a `.msh` / `.vtk` reader, the
// built-in generators (a box, a tube) and TetGen's output become before Bullet's deformable
// world turns it into a volumetric body. SI units, world frame.
//
// Orientation: every tetrahedron (a, b, c, d) has a positive signed volume
// (b − a)·((c − a) × (d − a)) / 6 > 0; readers reorder an inverted element's corners only where
// the format leaves the order open, and refuse it otherwise (the check names the element).
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
