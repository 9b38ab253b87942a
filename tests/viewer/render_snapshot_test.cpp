// RenderModel / capture_snapshot: the picture's model matches the simulation, the snapshot
// carries the state, and it crosses the wait-free exchange whole.
#include "fissure/viewer/render_snapshot.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <memory>
#include <vector>

#include "fissure/host_sim/scene_loader.hpp"

namespace fissure::viewer {
namespace {

host::SceneDescription scene_named(const char* name) { return host::load_scene(host::resolve_scene_path(name)); }

TEST(RenderModel, MatchesTheSettledSimulation) {
  host::HostSimulation sim(scene_named("spatula-sphere"));
  sim.settle(0.05);
  const RenderModel model = make_render_model(sim);
  EXPECT_EQ(static_cast<int>(model.soft_triangles.size()), sim.soft_face_count());
  ASSERT_EQ(static_cast<int>(model.soft_rest_world_m.size()), sim.soft_node_count());
  for (const auto& t : model.soft_triangles) {
    for (int i : t) {
      EXPECT_GE(i, 0);
      EXPECT_LT(i, sim.soft_node_count());
    }
  }
  // The sphere (R 5 cm) is the subject; the box tool is drawn with its real size.
  EXPECT_NEAR(model.focus_radius_m, 0.05F, 0.005F);
  EXPECT_NEAR(model.focus_world_m.y(), 0.052F, 0.006F);
  ASSERT_EQ(model.part_mesh.vertices.size(), 8U);
  EXPECT_NEAR(model.part_mesh.vertices[7].x(), 0.015F, 1e-6F);
  EXPECT_NEAR(model.part_mesh.vertices[7].y(), 0.001F, 1e-6F);
  EXPECT_NEAR(model.part_mesh.vertices[7].z(), 0.03F, 1e-6F);
  EXPECT_FALSE(model.has_handle);
}

std::vector<Eigen::Vector3f> node_positions(const host::HostSimulation& sim) {
  std::vector<Eigen::Vector3f> nodes;
  for (const Eigen::Vector3d& p : sim.node_positions_world_m()) nodes.push_back(p.cast<float>());
  return nodes;
}

// The colour of every node, sorted, with the body's rigid motion fitted to `nodes` taken out.
std::vector<float> sorted_fractions(const RenderModel& model, const std::vector<Eigen::Vector3f>& nodes) {
  const RigidMotion motion = fit_rigid_motion(model, nodes.data(), nodes.size());
  std::vector<float> fractions;
  for (std::size_t i = 0; i < nodes.size(); ++i) fractions.push_back(deformation_fraction(model, motion, i, nodes[i]));
  std::sort(fractions.begin(), fractions.end());
  return fractions;
}

// Presses the tool down at 0.1 m/s from its start pose until the body is dented 3 mm: some node
// 3 mm from where the body's rigid motion carries its settled position.
void press_a_three_millimetre_dent(const RenderModel& model, host::HostSimulation& sim) {
  host::ToolPose pose = host::to_tool_pose(sim.scene().trajectory.start);
  const auto dent_m = [&] { return sorted_fractions(model, node_positions(sim)).back() * model.deformation_full_scale_m; };
  for (int step = 0; step < 1000 && dent_m() < 0.003F; ++step) {
    pose.position_world_m.y() -= 0.0001;  // 0.1 m/s at the 1 kHz host step
    (void)sim.step(pose);
  }
  ASSERT_GE(dent_m(), 0.003F);
  ASSERT_GT(sim.last().contact_count, 0);
}

TEST(RenderModel, AThreeMillimetreDentIsTheStoryNotTheWholeBallsSag) {
  // The case: the colour scale must show a 3 mm dent, not make the whole ball's motion
  // the story.
  host::HostSimulation sim(scene_named("spatula-sphere"));
  sim.settle(1.0);
  const RenderModel model = make_render_model(sim);
  press_a_three_millimetre_dent(model, sim);
  const std::vector<float> fractions = sorted_fractions(model, node_positions(sim));
  EXPECT_GE(fractions.back(), 0.45F) << "a 3 mm dent must read about half-way to red (full scale "
                                     << model.deformation_full_scale_m * 1e3F << " mm)";
  // Pressing the top squashes and pushes the whole ball; with its rigid motion out, the rest of the
  // ball stays blue: the median node reads under a tenth of the dent.
  EXPECT_GE(fractions.back(), 10.0F * fractions[fractions.size() / 2]) << "median " << fractions[fractions.size() / 2];
  EXPECT_LE(model.deformation_full_scale_m, 0.0066F);
}

TEST(RenderModel, ABallThatSlidesAndTurnsAsAWholeStaysBlueAndItsDentStillReads) {
  // The settled paper ball does not stay put on Bullet's ground: untouched it slides a few mm a
  // second and turns about the vertical (docs/decisions.md, "Contact inside the solver",
  // 2026-12-06 evening). Two seconds of that, then the press.
  host::HostSimulation sim(scene_named("spatula-sphere"));
  sim.settle(1.0);
  const RenderModel model = make_render_model(sim);
  const host::ToolPose start = host::to_tool_pose(sim.scene().trajectory.start);
  for (int step = 0; step < 2000; ++step) (void)sim.step(start);
  ASSERT_EQ(sim.last().contact_count, 0);
  std::vector<Eigen::Vector3f> drifted = node_positions(sim);
  float drift_m = 0.0F;
  for (std::size_t i = 0; i < drifted.size(); ++i) drift_m = std::max(drift_m, (drifted[i] - model.soft_rest_world_m[i]).norm());
  ASSERT_GT(drift_m, 0.003F) << "the case needs a body that moved as much as the dent";
  EXPECT_LE(sorted_fractions(model, drifted).back(), 0.15F) << "untouched, nothing is deformed (it moved " << drift_m * 1e3F << " mm)";
  press_a_three_millimetre_dent(model, sim);
  const std::vector<float> fractions = sorted_fractions(model, node_positions(sim));
  EXPECT_GE(fractions.back(), 0.45F);
  EXPECT_GE(fractions.back(), 10.0F * fractions[fractions.size() / 2]) << "median " << fractions[fractions.size() / 2];
}

TEST(RenderModel, TheRigidMotionFitTakesOutATurnAndAShiftExactly) {
  host::HostSimulation sim(scene_named("spatula-sphere"));
  sim.settle(0.05);
  const RenderModel model = make_render_model(sim);
  const Eigen::Matrix3f turn = Eigen::AngleAxisf(0.35F, Eigen::Vector3f(0.3F, 0.9F, -0.2F).normalized()).toRotationMatrix();
  const Eigen::Vector3f shift(0.05F, -0.01F, 0.02F);
  std::vector<Eigen::Vector3f> moved;
  for (const Eigen::Vector3f& p : model.soft_rest_world_m) moved.push_back(turn * p + shift);
  const RigidMotion motion = fit_rigid_motion(model, moved.data(), moved.size());
  EXPECT_TRUE(motion.rotation.isApprox(turn, 1e-4F));
  EXPECT_TRUE(motion.translation.isApprox(shift, 1e-4F));
  EXPECT_LE(sorted_fractions(model, moved).back(), 1e-3F);
  // One node pushed 3 mm further in reads 3 mm on the scale; the fit hardly moves for it.
  moved[0] -= 0.003F * (moved[0] - motion.translation).normalized();
  const RigidMotion dented = fit_rigid_motion(model, moved.data(), moved.size());
  const float node0 = deformation_fraction(model, dented, 0, moved[0]);
  EXPECT_NEAR(node0 * model.deformation_full_scale_m, 0.003F, 0.0003F);
}

TEST(RenderModel, ClampHasTwoJawsAndAHandle) {
  host::HostSimulation sim(scene_named("clamp-vessel"));
  sim.settle(0.02);
  const RenderModel model = make_render_model(sim);
  EXPECT_TRUE(model.has_handle);
  auto snapshot = std::make_unique<RenderSnapshot>();
  (void)sim.step(host::to_tool_pose(sim.scene().trajectory.start), 0.03);
  capture_snapshot(sim, *snapshot);
  ASSERT_EQ(snapshot->part_count, 2);
  // The jaws sit on either side of the tool origin, 0.03 m gap + one jaw thickness apart.
  const auto& a = snapshot->part_poses[0].position_world_m;
  const auto& b = snapshot->part_poses[1].position_world_m;
  const float distance = std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
  EXPECT_NEAR(distance, 0.03F + static_cast<float>(sim.scene().tool.clamp.jaw_size_m[1]), 1e-4F);
}

TEST(CaptureSnapshot, CopiesNodesPoseForceAndOverlay) {
  host::HostSimulation sim(scene_named("spatula-sphere"));
  sim.settle(0.05);
  host::ToolPose pose = host::to_tool_pose(sim.scene().trajectory.start);
  // Press into the sphere's top (0.102 m) at 0.5 m/s to 0.095 m: a force on the tool.
  while (pose.position_world_m.y() > 0.095) {
    pose.position_world_m.y() = std::max(0.095, pose.position_world_m.y() - 0.0005);
    (void)sim.step(pose);
  }
  auto snapshot = std::make_unique<RenderSnapshot>();
  capture_snapshot(sim, *snapshot);
  EXPECT_EQ(snapshot->sequence, 1U);
  ASSERT_EQ(snapshot->node_count, sim.soft_node_count());
  for (int i = 0; i < snapshot->node_count; ++i) {
    const Eigen::Vector3d& p = sim.node_positions_world_m()[static_cast<std::size_t>(i)];
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(snapshot->nodes_world_m[static_cast<std::size_t>(i)][static_cast<std::size_t>(k)], p[k], 1e-6);
  }
  EXPECT_NEAR(snapshot->tool_pose.position_world_m[1], 0.095F, 1e-6F);
  EXPECT_EQ(snapshot->part_count, 1);
  EXPECT_GT(snapshot->overlay.force_n, 0.0);
  EXPECT_NEAR(snapshot->force_on_tool_world_n[1], sim.last().force_on_tool_world_n.y(), 1e-5);
  EXPECT_EQ(snapshot->overlay.contacts, sim.last().contact_count);
  EXPECT_EQ(snapshot->overlay.method, host::SceneCollisionMethod::kPaired);
  capture_snapshot(sim, *snapshot);
  EXPECT_EQ(snapshot->sequence, 2U);
}

TEST(CapturePatches, CopiesTheProxyPatches) {
  ContactProxy proxy{};
  proxy.patch_count = 2;
  proxy.patches[1].plane_point_world_m = {0.01, 0.02, 0.03};
  proxy.patches[1].normal_world = {0.0, 0.0, -1.0};
  auto snapshot = std::make_unique<RenderSnapshot>();
  capture_patches(proxy, *snapshot);
  EXPECT_EQ(snapshot->patch_count, 2);
  EXPECT_FLOAT_EQ(snapshot->patches[1].point_world_m[2], 0.03F);
  EXPECT_FLOAT_EQ(snapshot->patches[1].normal_world[2], -1.0F);
}

TEST(SnapshotExchange, DeliversTheNewestSnapshotWhole) {
  auto exchange = std::make_unique<SnapshotExchange>();
  auto in = std::make_unique<RenderSnapshot>();
  auto out = std::make_unique<RenderSnapshot>();
  EXPECT_FALSE(exchange->try_fetch(*out));
  for (std::uint64_t s = 1; s <= 3; ++s) {
    in->sequence = s;
    in->node_count = kMaxSnapshotNodes;
    in->nodes_world_m[kMaxSnapshotNodes - 1] = {static_cast<float>(s), 0.0F, 0.0F};
    exchange->publish(*in);
  }
  ASSERT_TRUE(exchange->try_fetch(*out));
  EXPECT_EQ(out->sequence, 3U);
  EXPECT_FLOAT_EQ(out->nodes_world_m[kMaxSnapshotNodes - 1][0], 3.0F);
  EXPECT_FALSE(exchange->try_fetch(*out));
}

}  // namespace
}  // namespace fissure::viewer
