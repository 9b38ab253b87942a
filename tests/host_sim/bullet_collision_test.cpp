// The `bullet` baseline: the probe does not change Bullet's result, its force is right,
// and the baseline shows the known failure (a 4 mm plate tunnels at ≥ 10 m/s at 1 kHz,
// not at 0.1 m/s — BRIEF §3).
#include "fissure/host_sim/bullet_collision.hpp"

#include <gtest/gtest.h>

#include <BulletSoftBody/btSoftBody.h>

#include "fissure/host_sim/host_simulation.hpp"
#include "fissure/host_sim/scene_loader.hpp"
#include "fissure/host_sim/soft_world.hpp"

namespace fissure::host {
namespace {

// The paper's sphere under BRIEF §3's measurement plate: 40 × 4 × 40 mm, 1 kHz.
SceneDescription plate_scene(double thickness_m) {
  SceneDescription s = load_scene("scenes/spatula-sphere.toml");
  s.tool.box_size_m = {0.04, thickness_m, 0.04};
  s.simulation.collision_method = SceneCollisionMethod::kBullet;
  s.trajectory.start.position_world_m = {0.0, 0.115, 0.0};
  return s;
}

// Drives the plate straight down at `speed` from 1.5 cm above the sphere to 3 cm into it,
// then holds 50 ms; returns the worst crossed-node count seen.
int plunge_crossed_nodes(double speed_m_s, SceneCollisionMethod method, double shape_matching_ratio = -1.0) {
  SceneDescription scene = plate_scene(0.004);
  if (shape_matching_ratio >= 0.0) scene.soft_bodies.front().shape_matching_ratio = shape_matching_ratio;
  HostSimulation sim(scene, method);
  sim.settle(0.3);
  const double dt = sim.scene().simulation.time_step_s;
  ToolPose pose = to_tool_pose(sim.scene().trajectory.start);
  const double bottom_y = 0.072;
  int worst = 0;
  for (int i = 0; i < 100000 && pose.position_world_m.y() > bottom_y; ++i) {
    pose.position_world_m.y() = std::max(bottom_y, pose.position_world_m.y() - speed_m_s * dt);
    worst = std::max(worst, sim.step(pose).crossing.crossed_nodes);
  }
  for (int i = 0; i < 50; ++i) worst = std::max(worst, sim.step(pose).crossing.crossed_nodes);
  return worst;
}

TEST(BulletCollision, KnownFailureTunnelsAtTenMetresPerSecond) {
  EXPECT_GT(plunge_crossed_nodes(10.0, SceneCollisionMethod::kBullet), 0);
  EXPECT_GT(plunge_crossed_nodes(50.0, SceneCollisionMethod::kBullet), 0);
}

// A slow plunge into the shell WITHOUT pose matching (kMT = 0, the paper's plain
// edge-link shell, as spatula-sphere was before it gained kMT = 0.05): Bullet's SDF contact
// holds every node at 0.1 m/s there. With kMT = 0.05 it leaks one node at 0.1 m/s, which the
// collision bench's sweep also shows — the stiffened dent pushes back harder than the SDF
// margin absorbs. Both are recorded rather than tuned away: this test pins the fair set-up of
// the baseline (voxel, margin, hardness) on the body it was tuned on.
TEST(BulletCollision, NoCrossingAtATenthOfAMetrePerSecond) {
  EXPECT_EQ(plunge_crossed_nodes(0.1, SceneCollisionMethod::kBullet, 0.0), 0);
}

TEST(ContactProbeSolver, ReproducesBulletsOwnSolverExactly) {
  // Same scene, same tool motion: the probing solver vs Bullet's stock solver.
  const SceneDescription scene = plate_scene(0.004);
  SoftWorld probed(scene, true, true);
  SoftWorld stock(scene, true, false);
  ASSERT_NE(probed.probe(), nullptr);
  ASSERT_EQ(stock.probe(), nullptr);
  ToolPose pose = to_tool_pose(scene.trajectory.start);
  int contact_steps = 0;
  for (int i = 0; i < 600; ++i) {
    pose.position_world_m.y() = std::max(0.085, pose.position_world_m.y() - 0.05 * 0.001);
    probed.set_part_pose(0, pose);
    stock.set_part_pose(0, pose);
    probed.step(0.001);
    stock.step(0.001);
    contact_steps += probed.probe()->momentum_displacement(0).norm() > 0.0 ? 1 : 0;
  }
  EXPECT_GT(contact_steps, 100);  // the comparison covered contact
  for (int i = 0; i < probed.soft().m_nodes.size(); ++i) {
    const btVector3 d = probed.soft().m_nodes[i].m_x - stock.soft().m_nodes[i].m_x;
    EXPECT_LT(d.length(), 1e-6f) << "node " << i;
  }
}

TEST(BulletCollision, MeasuredForceBalancesTheSoftBodysMomentum) {
  // The plate is the floor (the ground is 1 m below) and the ball drops onto it: the only
  // external forces on the ball are gravity and the tool, so over any window
  //   F_on_tool = −(Δp/T − M·g)   exactly (kDP = 0: no velocity damping; kPR = 0: Bullet's
  //   per-node pressure force n̂ᵢ·Aᵢ·P does not sum to zero on a real mesh — measured
  //   ~0.6 N of net "self-propulsion" on this ball at kPR = 1 — so it is switched off here).
  SceneDescription s = plate_scene(0.004);
  s.ground.top_height_m = -1.0;
  s.tool.box_size_m = {0.2, 0.004, 0.2};
  s.soft_bodies.front().damping_ratio = 0.0;
  s.soft_bodies.front().pressure_kpr = 0.0;
  s.trajectory.start.position_world_m = {0.0, 0.02, 0.0};
  std::get<SoftSphere>(s.soft_bodies.front().shape).center_world_m = {0.0, 0.022 + 0.05 + 0.004, 0.0};
  HostSimulation sim(s);
  const ToolPose pose = to_tool_pose(s.trajectory.start);
  const btSoftBody& soft = sim.world().soft();
  auto momentum = [&soft] {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (int i = 0; i < soft.m_nodes.size(); ++i) {
      const btVector3& v = soft.m_nodes[i].m_v;
      p += Eigen::Vector3d(v.x(), v.y(), v.z()) / static_cast<double>(soft.m_nodes[i].m_im);
    }
    return p;
  };
  double mass_kg = 0.0;
  for (int i = 0; i < soft.m_nodes.size(); ++i) mass_kg += 1.0 / static_cast<double>(soft.m_nodes[i].m_im);
  const Eigen::Vector3d p0 = momentum();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  constexpr int kSteps = 1000;
  int contact_steps = 0;
  for (int i = 0; i < kSteps; ++i) {
    const HostStepResult& r = sim.step(pose);
    sum += r.force_on_tool_world_n;
    contact_steps += r.contact_count > 0 ? 1 : 0;
  }
  const double window_s = kSteps * s.simulation.time_step_s;
  const Eigen::Vector3d gravity(0.0, -9.81, 0.0);
  const Eigen::Vector3d expected = -((momentum() - p0) / window_s - mass_kg * gravity);
  const Eigen::Vector3d measured = sum / kSteps;
  EXPECT_GT(contact_steps, kSteps / 2);
  EXPECT_NEAR(measured.y(), expected.y(), 0.01 * mass_kg * 9.81) << measured.transpose() << " vs " << expected.transpose();
  EXPECT_NEAR(measured.x(), expected.x(), 0.01 * mass_kg * 9.81);
  EXPECT_NEAR(measured.z(), expected.z(), 0.01 * mass_kg * 9.81);
  EXPECT_LT(measured.y(), 0.0);  // the ball pushes the floor down
}

}  // namespace
}  // namespace fissure::host
