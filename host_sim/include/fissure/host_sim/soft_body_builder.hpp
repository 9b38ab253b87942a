#pragma once
// Soft bodies of a scene as Bullet btSoftBody objects (triangle surface meshes with links
// on the edges): the paper's sphere (Bullet's own CreateEllipsoid, 128 faces), geodesic
// icospheres for mesh refinement, a closed cylinder (the vessel) and a slab.
#include <array>
#include <vector>

#include "fissure/host_sim/scene_description.hpp"

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
[[nodiscard]] SurfaceMesh make_cylinder(const SoftCylinder& cylinder);
[[nodiscard]] SurfaceMesh make_slab(const SoftSlab& slab);

/// Builds the scene's soft body (not yet added to a world) and applies its material and
/// config (kLST, kPR, kVC, kDP, kDF, piterations, margin, mass; kKHR = kCHR = 1, BRIEF §3).
/// The caller owns the result (a btSoftRigidDynamicsWorld does not delete its bodies).
[[nodiscard]] btSoftBody* build_soft_body(btSoftBodyWorldInfo& world_info, const SoftBodyDescription& description);

}  // namespace fissure::host
