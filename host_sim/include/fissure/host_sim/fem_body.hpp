#pragma once
// A volumetric soft body for Bullet's deformable world (btDeformableMultiBodyDynamicsWorld,
// issue 24): the tetrahedral body of create_from_tet_mesh (nodes with lumped masses, a link per
// tetrahedron edge, Bullet tetras, the boundary as faces) made ready for the FEM forces.
#include "fissure/host_sim/fem_material.hpp"
#include "fissure/host_sim/soft_body_builder.hpp"

class btSoftBody;
struct btSoftBodyWorldInfo;

namespace fissure::host {

/// How the body meets rigid bodies through Bullet (the deformable world's own contact: node and
/// face against the rigid shape's signed distance, projected in the velocity solve).
struct FemContact {
  double collision_margin_m = 1.0e-4;  ///< soft body margin: contact when a node is within it
  double friction_ratio = 0.0;         ///< kDF (× the rigid body's friction); 0: frictionless
};

/// Builds the body: create_from_tet_mesh with the material's density (node mass = density × ¼ of
/// each adjacent tetrahedron's volume, kg), then what Bullet's FEM forces read and its own
/// helpers (btSoftBodyHelpers::CreateFromTetGenData) set up but appendTetra does not: the inverse
/// rest shape matrix Dm⁻¹ and the element measure (rest volume) per tetrahedron
/// (initializeDmInverse), and the per-tetrahedron scratch arrays (deformation gradient,
/// corotation; without them the first step reads past an empty array). The links are kept: the
/// deformable world's node tree is built bottom-up from them (btSoftBody::rebuildNodeTree merges
/// only linked nodes and never ends without them). Not yet in a world; the caller owns it.
[[nodiscard]] btSoftBody* create_fem_body(btSoftBodyWorldInfo& world_info, const VolumeMesh& mesh, const FemMaterial& material, const FemContact& contact);

}  // namespace fissure::host
