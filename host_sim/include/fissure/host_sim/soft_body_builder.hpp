#pragma once
// Soft bodies of a scene as Bullet btSoftBody objects (triangle surface meshes with links
// on the edges): the paper's sphere (Bullet's own CreateEllipsoid, 128 faces), geodesic
// icospheres for mesh refinement, a closed cylinder (the vessel) and a slab; and volumetric
// bodies from a tetrahedral mesh file (nodes, a link per tetrahedron edge, Bullet tetras, the
// boundary triangles as faces).
#include <array>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include <LinearMath/btScalar.h>

#include "fissure/host_sim/scene_description.hpp"
#include "fissure/host_sim/tet_mesh.hpp"

class btRigidBody;
class btSoftBody;
struct btSoftBodyWorldInfo;

namespace fissure::host {

/// A closed triangle surface (counter-clockwise seen from outside).
struct SurfaceMesh {
  std::vector<Vec3> vertices_m;
  std::vector<std::array<int, 3>> triangles;
  std::vector<int> pinned_vertices;  ///< vertices given zero inverse mass (slab bottom)
};

/// Geodesic sphere: icosahedron subdivided `subdivisions` times (20·4^s faces).
[[nodiscard]] SurfaceMesh make_icosphere(const Vec3& center_m, double radius_m, int subdivisions);
/// Whether `faces` is an icosphere's face count, 20·4^k (20, 80, 320, 1280, …).
[[nodiscard]] bool is_icosphere_face_count(int faces) noexcept;
[[nodiscard]] SurfaceMesh make_cylinder(const SoftCylinder& cylinder);
[[nodiscard]] SurfaceMesh make_slab(const SoftSlab& slab);
/// The shipped organ-like lobe (scenes/meshes/organ-blob.obj, written by `fissure sim
/// --write-meshes`): an icosphere (20·4^subdivisions faces) mapped onto an ellipsoid of
/// 100 × 50 × 70 mm, flattened to 3/4 underneath, with a smooth dent on its +z side (a kidney's
/// hilum): closed, outward, not convex. Centred on the origin, metres.
[[nodiscard]] SurfaceMesh make_organ_blob(int subdivisions);

/// The most triangles a soft-body mesh may have: the sphere's faces_count bound in the scene
/// loader (400,000), the largest body the host step has been run with.
inline constexpr std::size_t kSoftMeshMaxTriangles = 400'000;

/// Reads a soft body's closed surface mesh (OBJ or STL by extension, mesh_file.hpp) and checks
/// it: closed, manifold, consistently oriented and facing outwards, one surface, no degenerate
/// triangle (|(b − a) × (c − a)| ≤ 1e-12 of the squared mesh size), at most
/// kSoftMeshMaxTriangles. Throws MeshError naming the file, the element (triangle / vertex, its
/// line in a text format) and the reason.
[[nodiscard]] SurfaceMesh read_soft_body_mesh(const std::string& path);

/// The most tetrahedra a volumetric soft body may have: a million tetrahedra make ~1.2 million
/// links and a million Bullet tetras, ~0.4 GB of btSoftBody (its Node, Link and Tetra records
/// are ~100–200 bytes each), the size of the largest surface body's 400,000 triangles.
inline constexpr std::size_t kSoftMeshMaxTetrahedra = 1'000'000;

/// A volumetric soft body's mesh: tetrahedra positive (tet_mesh.hpp) and the boundary triangles
/// counter-clockwise seen from outside.
struct VolumeMesh {
  std::vector<Vec3> vertices_m;
  std::vector<std::array<int, 4>> tetrahedra;
  std::vector<std::array<int, 3>> boundary_triangles;
};

/// Reads a soft body's tetrahedral mesh (.msh, .vtk, TetGen .node/.ele; tet_mesh_file.hpp),
/// welds duplicate vertices, drops unused ones and checks it (tet_mesh_checks.hpp): one
/// connected volume with a closed manifold boundary, no overlap, at most kSoftMeshMaxTetrahedra.
/// Throws MeshError naming the file, the element (tetrahedron and its line) and the reason.
[[nodiscard]] VolumeMesh read_soft_body_tet_mesh(const std::string& path);
/// A checked tetrahedral mesh as a VolumeMesh: check_tet_mesh (throws naming the element) gives
/// its outward boundary triangles.
[[nodiscard]] VolumeMesh volume_mesh_from(TetMesh tet);

/// A volumetric btSoftBody: a node per vertex with the lumped mass density × (a quarter of the
/// volume of each tetrahedron it is a corner of), a link per tetrahedron edge (once), a Bullet
/// tetra per tetrahedron (btSoftBody::appendTetra, rest volume), the boundary triangles as
/// faces (outward: the soft collisions take "outward" from the winding); then Bullet's
/// deterministic randomizeConstraints, as create_from_tri_mesh. Linear in the mesh size.
[[nodiscard]] btSoftBody* create_from_tet_mesh(btSoftBodyWorldInfo& world_info, const VolumeMesh& mesh, double density_kg_per_m3);

/// btSoftBodyHelpers::CreateFromTriMesh(…, randomizeConstraints = true) in linear memory and
/// time: the same nodes, links, faces and their order (xyz: 3 coordinates per vertex).
[[nodiscard]] btSoftBody* create_from_tri_mesh(btSoftBodyWorldInfo& world_info, const std::vector<btScalar>& xyz,
                                               const std::vector<std::array<int, 3>>& triangles);

/// Builds the scene's soft body (not yet added to a world; a tetrahedral SoftMesh through
/// create_from_tet_mesh with the density mass / volume, so mass_kg is spread by volume) and applies its material and
/// config (kLST, kPR, kVC, kDP, kDF, piterations, margin, mass; kKHR = kCHR = 1, BRIEF §3).
/// The caller owns the result (a btSoftRigidDynamicsWorld does not delete its bodies).
[[nodiscard]] btSoftBody* build_soft_body(btSoftBodyWorldInfo& world_info, const SoftBodyDescription& description);

/// Bullet's pose matching (kMT, shape_matching_ratio) needs the polar decomposition of the
/// pose matrix A = Σ wᵢ (xᵢ − c) qᵢᵀ (weights wᵢ summing to 1, so A is in m²). btPolarDecomposition
/// (LinearMath, Bullet 3.24) treats A as singular when ‖A‖₁·‖A‖∞ < SIMD_EPSILON and then returns
/// A itself as the "rotation": the goal shape shrinks with the body and the body collapses to
/// its centre. In Debian's single-precision build SIMD_EPSILON is FLT_EPSILON, so the bound is
/// 1.19e-7 m⁴ — a round shell of ~32 mm radius. The loader refuses a body under it; above it a
/// body keeps its shape falling, resting and dropped (SoftWorld.PoseMatching… tests).
inline constexpr double kPoseMatchingMinNormProduct_m4 = static_cast<double>(SIMD_EPSILON);

/// A soft body as built, before any settling: what the loader checks a description against.
struct SoftBodyRest {
  /// Node positions, world frame: what [[soft_body.anchor]] boxes select from (the loader
  /// checks each box selects one).
  std::vector<Vec3> nodes_world_m;
  /// ‖A‖₁·‖A‖∞ of the rest pose matrix A = Σ wᵢ qᵢ qᵢᵀ [m⁴] (see
  /// kPoseMatchingMinNormProduct_m4); +inf when the body has no pose matching.
  double pose_matrix_norm_product_m4 = std::numeric_limits<double>::infinity();
  /// √trace(A), the rest shape's mass-weighted radius of gyration about its centre [m] (a
  /// closed spherical shell's radius); 0 when the body has no pose matching.
  double pose_radius_of_gyration_m = 0.0;
};
/// Builds the body as the world does, in a throw-away world info (the meshes never touch its
/// broadphase or SDF), so the figures are exactly those of the world's body.
[[nodiscard]] SoftBodyRest soft_body_rest(const SoftBodyDescription& description);

/// Indices of the nodes (of `nodes_world_m`) inside `box`, bounds included, ascending.
[[nodiscard]] std::vector<int> nodes_in_anchor_box(const std::vector<Vec3>& nodes_world_m, const SoftAnchorBox& box);

/// The nodes (of `nodes_world_m`) the description's anchor boxes select, ascending, each once
/// (boxes may overlap). Throws std::invalid_argument naming the box when a box selects no node
/// (a scene built in code; the loader reports it with file and line).
[[nodiscard]] std::vector<int> anchored_nodes(const std::vector<Vec3>& nodes_world_m, const SoftBodyDescription& description);

/// Anchors the body's nodes selected by the description's anchor boxes (by their current
/// positions: call right after build_soft_body, while the body is at rest) to `bed`, with
/// Bullet's own anchors: the node keeps its mass and a rigid-contact-free link to the bed
/// pulls it back to its rest place (btSoftBody::PSolve_Anchors, hardness Config::kAHR).
/// Returns the number of anchored nodes. Throws std::invalid_argument naming the box when a
/// box selects no node (a scene built in code; the loader reports it with file and line).
int anchor_soft_body(btSoftBody& body, btRigidBody& bed, const SoftBodyDescription& description);

}  // namespace fissure::host
