// Volumetric FEM bodies for the deformable world (fem_body.hpp).
#include "fissure/host_sim/fem_body.hpp"

#include <BulletSoftBody/btSoftBody.h>

namespace fissure::host {

btSoftBody* create_fem_body(btSoftBodyWorldInfo& world_info, const VolumeMesh& mesh, const FemMaterial& material, const FemContact& contact) {
  btSoftBody* body = create_from_tet_mesh(world_info, mesh, material.density_kg_per_m3);
  body->initializeDmInverse();
  // Filled with the rest state (F = I) rather than Bullet's uninitialised default.
  btSoftBody::TetraScratch rest;
  rest.m_F.setIdentity();
  rest.m_trace = 3;
  rest.m_J = 1;
  rest.m_cofF.setIdentity();
  rest.m_corotation.setIdentity();
  body->m_tetraScratches.resize(body->m_tetras.size(), rest);
  body->m_tetraScratchesTn.resize(body->m_tetras.size(), rest);
  body->m_cfg.kDF = static_cast<btScalar>(contact.friction_ratio);
  // Contact hardness 1 with kinematic and dynamic rigid bodies, as the classic bodies (BRIEF §3).
  body->m_cfg.kKHR = 1;
  body->m_cfg.kCHR = 1;
  // Node and face against rigid bodies, resolved in the deformable velocity solve (Bullet's
  // deformable demos use the same pair).
  body->m_cfg.collisions = btSoftBody::fCollision::SDF_RD | btSoftBody::fCollision::SDF_RDN;
  body->getCollisionShape()->setMargin(static_cast<btScalar>(contact.collision_margin_m));
  // Never put to sleep: a resting organ must still answer the tool at once.
  body->m_sleepingThreshold = 0;
  body->setActivationState(DISABLE_DEACTIVATION);
  return body;
}

}  // namespace fissure::host
