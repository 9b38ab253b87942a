#pragma once
// Shape checks and clean-up of a tetrahedral mesh before it becomes a volumetric soft body
// (issue 24), each n log n in the mesh size: duplicate vertices welded, unused ones dropped, the
// boundary surface extracted (the triangles of exactly one tetrahedron, facing out of it), and
// refused with a MeshError naming the file and the element when a face is shared by more than
// two tetrahedra or by two on the same side (overlap), the mesh is several separate volumes, or
// its boundary is not one closed, manifold surface (check_closed_surface: a non-conforming
// interface leaves the boundary open).
#include <array>
#include <string>
#include <vector>

#include "fissure/host_sim/tet_mesh.hpp"

namespace fissure::host {

/// What weld_and_compact changed (for the loader's messages and the tests).
struct TetMeshCleanup {
  int welded_vertices_count = 0;  ///< vertices with bit-identical coordinates merged into their first
  int unused_vertices_count = 0;  ///< vertices no tetrahedron uses, dropped
};

/// Merges vertices with bit-identical coordinates (an exporter that writes each element's
/// points apart) and drops the vertices no tetrahedron uses (Gmsh keeps its geometry's points),
/// renumbering the tetrahedra; vertex order otherwise kept.
TetMeshCleanup weld_and_compact(TetMesh& mesh);

/// A tetrahedral mesh's boundary: each triangle face that belongs to exactly one tetrahedron,
/// counter-clockwise seen from outside, and that tetrahedron (0-based), in tetrahedron order.
struct TetBoundary {
  std::vector<std::array<int, 3>> triangles;
  std::vector<int> tetrahedra;
};

/// Extracts the boundary and checks the mesh (see the file comment). Throws MeshError
/// "'SOURCE': tetrahedron 7 (line 40): REASON". The mesh's tetrahedra must be positively oriented
/// (as the readers leave them).
[[nodiscard]] TetBoundary check_tet_mesh(const TetMesh& mesh);

/// Sum of the tetrahedra's volumes [m³].
[[nodiscard]] double tet_mesh_volume_m3(const TetMesh& mesh);

}  // namespace fissure::host
