// host_sim/src/fem_world.cpp: the deformable world's fixed nodes and reaction forces. A column
// hanging from its fixed top face settles under gravity; at equilibrium every free node's
// elastic force balances its weight and the internal forces sum to zero, so the elastic force on
// the fixed nodes is the weight of the free ones — exactly, whatever the mesh.
#include "fissure/host_sim/fem_world.hpp"

#include <cmath>
#include <stdexcept>

#include <BulletSoftBody/btSoftBody.h>
#include <gtest/gtest.h>

#include "fissure/host_sim/tet_box.hpp"

namespace fissure::host {
namespace {

constexpr double kG = 9.81;

TEST(FemWorld, ReactionOnFixedNodesIsTheWeightTheyCarry) {
  const double side = 0.01, length = 0.03;
  const VolumeMesh mesh = make_tet_box(even_coordinates(0.0, side, 2), even_coordinates(-length, 0.0, 6), even_coordinates(0.0, side, 2));
  FemMaterial material;
  material.youngs_modulus_pa = 5000.0;
  FemWorldConfig config;
  config.gravity_world_m_per_s2 = Eigen::Vector3d(0.0, -kG, 0.0);
  config.implicit = true;
  config.newton_iterations = 3;
  config.cg_max_iterations = 5000;
  FemWorld world(config);
  const int body = world.add_body(mesh, material);
  std::vector<int> top;
  for (std::size_t i = 0; i < mesh.vertices_m.size(); ++i) {
    if (mesh.vertices_m[i][1] >= -1e-12) top.push_back(static_cast<int>(i));
  }
  world.fix_nodes(body, top);
  double free_mass = 0.0;
  for (int i = 0; i < world.body(body).m_nodes.size(); ++i) free_mass += world.body(body).getMass(i);
  for (int s = 0; s < 40; ++s) world.step(0.05);
  EXPECT_LT(world.max_node_speed_m_per_s(body), 1e-6);
  std::vector<Eigen::Vector3d> force;
  world.elastic_forces(body, force);
  Eigen::Vector3d on_fixed = Eigen::Vector3d::Zero(), total = Eigen::Vector3d::Zero();
  for (int n : top) on_fixed += force[static_cast<std::size_t>(n)];
  for (const Eigen::Vector3d& f : force) total += f;
  const double weight_n = free_mass * kG;  // 1040 kg/m³ × 3 cm³ less the top layer's lumped mass
  EXPECT_NEAR(on_fixed.y(), -weight_n, 1e-3 * weight_n);  // the column pulls its support down
  EXPECT_NEAR(total.norm(), 0.0, 1e-4 * weight_n);
  // The fixed nodes did not move; the free end sagged.
  for (int n : top) EXPECT_EQ(world.node_position_m(body, n).y(), static_cast<double>(static_cast<float>(mesh.vertices_m[static_cast<std::size_t>(n)][1])));
  EXPECT_LT(world.node_position_m(body, 0).y(), -length);
}

TEST(FemWorld, AFixedNodeGoesWhereItIsMoved) {
  const VolumeMesh mesh = make_tet_box(even_coordinates(0.0, 0.01, 1), even_coordinates(0.0, 0.01, 1), even_coordinates(0.0, 0.01, 1));
  FemWorld world(FemWorldConfig{});
  const int body = world.add_body(mesh, FemMaterial{});
  world.fix_nodes(body, {0});
  world.move_fixed_node(body, 0, Eigen::Vector3d(-0.001, -0.002, 0.0));
  for (int s = 0; s < 10; ++s) world.step(1e-4);
  EXPECT_NEAR(world.node_position_m(body, 0).x(), -0.001, 1e-9);
  EXPECT_NEAR(world.node_position_m(body, 0).y(), -0.002, 1e-9);
  // Node 1 (at x = 10 mm, on the edge from node 0 stretched along −x) was pulled after it.
  EXPECT_LT(world.node_position_m(body, 1).x(), 0.01);
}

}  // namespace
}  // namespace fissure::host

namespace fissure::host {
namespace {

TEST(FemWorld, ElasticForcesOfEachBodyBeforeAnyStepSumToZero) {
  // Two bodies, the second's first node pulled 1 mm out: before a step, Bullet has not numbered
  // the nodes over the world yet; each body's forces are still its own.
  const VolumeMesh mesh = make_tet_box(even_coordinates(0.0, 0.01, 1), even_coordinates(0.0, 0.01, 1), even_coordinates(0.0, 0.01, 1));
  FemWorld world(FemWorldConfig{});
  const int first = world.add_body(mesh, FemMaterial{});
  const int second = world.add_body(mesh, FemMaterial{});
  world.fix_nodes(second, {0});
  world.move_fixed_node(second, 0, Eigen::Vector3d(-0.001, 0.0, 0.0));
  std::vector<Eigen::Vector3d> f_first, f_second;
  world.elastic_forces(first, f_first);
  world.elastic_forces(second, f_second);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& f : f_first) EXPECT_LT(f.norm(), 1e-9);  // at rest
  ASSERT_EQ(f_second.size(), mesh.vertices_m.size());
  for (const Eigen::Vector3d& f : f_second) sum += f;
  EXPECT_GT(f_second[0].x(), 1e-4);  // the stretched body pulls its moved node back (+x)
  EXPECT_LT(sum.norm(), 1e-5 * f_second[0].norm());
}

TEST(FemWorld, ABodyWithAnotherMaterialIsRefused) {
  // Bullet would attach it to the first body's force, with the first body's (μ, λ).
  const VolumeMesh mesh = make_tet_box(even_coordinates(0.0, 0.01, 1), even_coordinates(0.0, 0.01, 1), even_coordinates(0.0, 0.01, 1));
  FemWorld world(FemWorldConfig{});
  (void)world.add_body(mesh, FemMaterial{});
  FemMaterial stiffer;
  stiffer.youngs_modulus_pa = 7000.0;
  EXPECT_THROW((void)world.add_body(mesh, stiffer), std::invalid_argument);
  FemMaterial denser;
  denser.density_kg_per_m3 = 1100.0;  // the density is the body's own (its node masses)
  EXPECT_EQ(world.add_body(mesh, denser), 1);
}

}  // namespace
}  // namespace fissure::host
