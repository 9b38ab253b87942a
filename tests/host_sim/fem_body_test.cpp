// host_sim/src/fem_body.cpp: the deformable-world body — lumped masses in kg from the density,
// Bullet's rest volume per tetrahedron, the scratch arrays at rest, no sleep.
#include "fissure/host_sim/fem_body.hpp"

#include <memory>

#include <BulletSoftBody/btSoftBody.h>
#include <gtest/gtest.h>

#include "fissure/host_sim/tet_box.hpp"

namespace fissure::host {
namespace {

TEST(FemBody, MassesVolumesAndScratchFromTheMeshAndDensity) {
  const VolumeMesh mesh = make_tet_box(even_coordinates(0.0, 0.02, 2), even_coordinates(0.0, 0.01, 1), even_coordinates(0.0, 0.02, 2));
  FemMaterial material;
  material.density_kg_per_m3 = 1040.0;
  btSoftBodyWorldInfo info;
  const std::unique_ptr<btSoftBody> body(create_fem_body(info, mesh, material, FemContact{}));
  ASSERT_EQ(body->m_nodes.size(), static_cast<int>(mesh.vertices_m.size()));
  ASSERT_EQ(body->m_tetras.size(), static_cast<int>(mesh.tetrahedra.size()));
  double mass = 0.0;
  for (int i = 0; i < body->m_nodes.size(); ++i) mass += body->getMass(i);
  EXPECT_NEAR(mass, 1040.0 * 0.02 * 0.01 * 0.02, 1e-9);  // 4.16 g
  double volume = 0.0;
  for (int i = 0; i < body->m_tetras.size(); ++i) volume += body->m_tetras[i].m_element_measure;
  EXPECT_NEAR(volume, 0.02 * 0.01 * 0.02, 1e-11);
  ASSERT_EQ(body->m_tetraScratches.size(), body->m_tetras.size());
  EXPECT_EQ(body->m_tetraScratches[0].m_J, 1);
  EXPECT_EQ(body->m_faces.size(), static_cast<int>(mesh.boundary_triangles.size()));
  EXPECT_EQ(body->getActivationState(), DISABLE_DEACTIVATION);
}

}  // namespace
}  // namespace fissure::host
