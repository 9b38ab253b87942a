#pragma once
// Soft bodies of a scene as Bullet btSoftBody objects (triangle surface meshes with links
// on the edges): the paper's sphere (Bullet's own CreateEllipsoid, 128 faces), geodesic
// icospheres for mesh refinement, a closed cylinder (the vessel) and a slab.
#include <array>
#include <vector>

#include "fissure/host_sim/scene_description.hpp"

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
[[nodiscard]] SurfaceMesh make_cylinder(const SoftCylinder& cylinder);
[[nodiscard]] SurfaceMesh make_slab(const SoftSlab& slab);

/// Builds the scene's soft body (not yet added to a world) and applies its material and
/// config (kLST, kPR, kVC, kDP, kDF, piterations, margin, mass; kKHR = kCHR = 1, BRIEF §3).
/// The caller owns the result (a btSoftRigidDynamicsWorld does not delete its bodies).
[[nodiscard]] btSoftBody* build_soft_body(btSoftBodyWorldInfo& world_info, const SoftBodyDescription& description);

/// The soft body's node positions as built (its rest shape, before any settling), world
/// frame: what [[soft_body.anchor]] boxes select from (the loader checks each box selects one).
[[nodiscard]] std::vector<Vec3> soft_body_rest_nodes_world_m(const SoftBodyDescription& description);

/// Indices of the nodes (of `nodes_world_m`) inside `box`, bounds included, ascending.
[[nodiscard]] std::vector<int> nodes_in_anchor_box(const std::vector<Vec3>& nodes_world_m, const SoftAnchorBox& box);

/// Anchors the body's nodes selected by the description's anchor boxes (by their current
/// positions: call right after build_soft_body, while the body is at rest) to `bed`, with
/// Bullet's own anchors: the node keeps its mass and a rigid-contact-free link to the bed
/// pulls it back to its rest place (btSoftBody::PSolve_Anchors, hardness Config::kAHR).
/// Returns the number of anchored nodes. Throws std::invalid_argument naming the box when a
/// box selects no node (a scene built in code; the loader reports it with file and line).
int anchor_soft_body(btSoftBody& body, btRigidBody& bed, const SoftBodyDescription& description);

}  // namespace fissure::host
