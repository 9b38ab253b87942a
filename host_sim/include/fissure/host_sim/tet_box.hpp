#pragma once
// Structured tetrahedral meshes of a box, generated in code (issue 24's validation specimens:
// the compressed cube, the punched block, the cantilever): deterministic, no external mesher.
// A rectilinear grid (any spacing per axis, so a block can be fine under a punch and coarse
// far from it) whose every cell is split into the 6 Kuhn tetrahedra along its (0,0,0)–(1,1,1)
// diagonal; neighbouring cells split their shared face along the same diagonal, so the mesh is
// conforming (tet_mesh_checks_test checks a Kuhn grid).
#include <vector>

#include "fissure/host_sim/soft_body_builder.hpp"

namespace fissure::host {

/// The box's tetrahedral mesh on the grid xs × ys × zs (each strictly increasing, ≥ 2 values, m).
/// Vertex (i, j, k) has index (k · ny + j) · nx + i. Every tetrahedron positive; the boundary
/// from check_tet_mesh. Throws std::invalid_argument for an axis that is not increasing.
[[nodiscard]] VolumeMesh make_tet_box(const std::vector<double>& xs_m, const std::vector<double>& ys_m, const std::vector<double>& zs_m);

/// n + 1 evenly spaced values from lo to hi.
[[nodiscard]] std::vector<double> even_coordinates(double lo_m, double hi_m, int cells);

/// Symmetric graded coordinates on [−extent, extent]: even spacing `spacing_m` on
/// [−fine_half_width, fine_half_width] (a whole number of cells), then cells growing by `growth`
/// per cell outwards, the last one cut to end at ±extent (merged into its neighbour when it would
/// be shorter than half the one before).
[[nodiscard]] std::vector<double> graded_coordinates(double fine_half_width_m, double spacing_m, double extent_m, double growth);

/// One-sided graded coordinates on [lo, hi] fine at hi: `fine_depth_m` of even cells of
/// `spacing_m` below hi, then cells growing by `growth` towards lo (the punched block's depth).
[[nodiscard]] std::vector<double> graded_coordinates_down(double lo_m, double hi_m, double fine_depth_m, double spacing_m, double growth);

/// A straight tube along world z (a vessel's wall as a volume): the annulus inner_radius ..
/// outer_radius, `length_m` long, centred at `centre_world_m`; a structured grid of cells_through
/// × cells_around × cells_along cells split as make_tet_box's. Vertex (i radial, j around, k along)
/// has index (k · cells_around + j) · (cells_through + 1) + i; j = 0 is the lowest generator
/// (−y), angles counter-clockwise seen from +z. Throws std::invalid_argument for a bad size.
struct TetTube {
  double inner_radius_m = 0.013;
  double outer_radius_m = 0.015;
  double length_m = 0.06;
  Vec3 centre_world_m{0.0, 0.0, 0.0};
  int cells_through = 2;
  int cells_around = 32;
  int cells_along = 20;
};
[[nodiscard]] VolumeMesh make_tet_tube(const TetTube& tube);

}  // namespace fissure::host
