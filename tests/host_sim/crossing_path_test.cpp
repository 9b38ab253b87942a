// The crossing ruler judges each node's PATH between two updates, not only where it ends
// (contact_metrics.hpp): regressions found by `fissure stress` (device_dropped_torn_replies).
#include "fissure/host_sim/contact_metrics.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "fissure/host_sim/host_simulation.hpp"
#include "fissure/host_sim/scene_loader.hpp"

namespace fissure::host {
namespace {

// scenes/spatula-sphere.toml's spatula: 30 × 2 × 60 mm, thin axis y.
const Eigen::Vector3d kSpatulaHalf_m(0.015, 0.001, 0.03);

Eigen::Isometry3d at(const Eigen::Vector3d& p) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = p;
  return t;
}

// `fissure stress --profile ci --seed 25 --case device_dropped_torn_replies`, t = 5.701 s: after a
// window of dropped device replies the host's tool pose jumped (24 mm in one 1 ms step). Node 47,
// in the spatula's frame, went from beside it (x = 27.6 mm, past the 15 mm rim, 4.4 mm above) to
// under its footprint (6.5 mm in, 8 mm below). Its straight relative path crosses the mid-plane
// at x = 20.1 mm: 5.1 mm beside the rim, so the rim passed it; nothing went through the tool.
// The end-point-only memory read it as crossed (the stress failure).
TEST(CrossingPath, ToolTeleportPastANodeBesideTheRimIsNotCrossed) {
  CrossingTracker tracker(ToolVolume::from_box(kSpatulaHalf_m), 1);
  const Eigen::Vector3d tool_before_m(0.0, 0.11, 0.0);
  const Eigen::Vector3d tool_jump_m(0.02111, 0.01234, 0.00100);
  std::vector<Eigen::Vector3d> node = {tool_before_m + Eigen::Vector3d(0.02755, 0.00436, 0.02074)};
  tracker.reset(node, at(tool_before_m));
  ASSERT_EQ(tracker.update(node, at(tool_before_m)).crossed_nodes, 0);
  ASSERT_EQ(tracker.sides()[0], 1);
  // The node itself barely moved; the tool jumped.
  const Eigen::Vector3d tool_after_m = tool_before_m + tool_jump_m;
  node[0] = tool_after_m + Eigen::Vector3d(0.00646, -0.00799, 0.01975);
  const CrossingSnapshot s = tracker.update(node, at(tool_after_m));
  EXPECT_EQ(s.crossed_nodes, 0);
  EXPECT_EQ(s.wrong_side_nodes, 0);
  EXPECT_EQ(s.through_nodes, 0);
  EXPECT_EQ(s.rim_passes, 1);
  EXPECT_EQ(s.endpoint_crossed_nodes, 1);  // the previous rule's misreading, kept visible
  EXPECT_EQ(tracker.sides()[0], -1);
  // It stays on its (new, right) side under the tool.
  EXPECT_EQ(tracker.update(node, at(tool_after_m)).crossed_nodes, 0);
}

// The converse the end-point rule missed: through the tool and out beyond its rim in one update.
TEST(CrossingPath, ThroughTheToolAndOutBeyondTheRimIsCrossed) {
  CrossingTracker tracker(ToolVolume::from_box(kSpatulaHalf_m), 1);
  std::vector<Eigen::Vector3d> node = {{0.010, 0.004, 0.0}};  // above the spatula, in its footprint
  tracker.reset(node, at(Eigen::Vector3d::Zero()));
  // Crosses the mid-plane at x = 14 mm (1 mm inside the rim), ends 2 mm beside the rim below it.
  node[0] = {0.018, -0.004, 0.0};
  const CrossingSnapshot s = tracker.update(node, at(Eigen::Vector3d::Zero()));
  EXPECT_EQ(s.through_nodes, 1);
  EXPECT_EQ(s.crossed_nodes, 1);
  EXPECT_EQ(s.rim_passes, 0);
  EXPECT_EQ(s.endpoint_crossed_nodes, 0);  // outside the footprint at the end: the end-point-only rule misses it
}

// A rim pass is decided per update: a path that crosses the mid-plane exactly on a side face
// (a node held there by the paired method) counts as round the rim, one just inside as through.
TEST(CrossingPath, MidPlaneCrossingOnTheSideFaceIsRoundTheRim) {
  CrossingTracker tracker(ToolVolume::from_box(kSpatulaHalf_m), 2);
  std::vector<Eigen::Vector3d> nodes = {{0.015, 0.0005, 0.0}, {0.0148, 0.0005, 0.0}};
  tracker.reset(nodes, at(Eigen::Vector3d::Zero()));
  nodes[0] = {0.015, -0.0005, 0.0};
  nodes[1] = {0.0148, -0.0005, 0.0};  // 0.2 mm inside the side face: through (> 0.1 mm tolerance)
  const CrossingSnapshot s = tracker.update(nodes, at(Eigen::Vector3d::Zero()));
  EXPECT_EQ(s.rim_passes, 1);
  EXPECT_EQ(s.through_nodes, 1);
  EXPECT_EQ(s.crossed_nodes, 1);
}

// The same mechanism end to end, in HostSimulation (spatula-sphere, paired): the spatula waits
// beside the settled sphere's top node, its mid-plane 2 mm below it, then jumps in ONE 1 ms step
// (60 mm sideways, 8 mm up: 61 m/s, as a pose after dropped device replies) to 5 mm above the
// node. Its straight path clears the sphere (the rim passes 30 mm beside the top node at its
// height), so no node touches it — yet every node the spatula ends over went, in its frame, from
// above its mid-plane to below it. The end-point-only memory read them as crossed.
TEST(CrossingPath, HostSimulationToolJumpOverTheSphereTopCrossesNothing) {
  const SceneDescription scene = load_scene("scenes/spatula-sphere.toml");
  HostSimulation sim(scene, SceneCollisionMethod::kPaired);
  sim.settle(0.5);
  const std::vector<Eigen::Vector3d>& nodes = sim.node_positions_world_m();
  Eigen::Vector3d top = nodes.front();
  for (const Eigen::Vector3d& p : nodes)
    if (p.y() > top.y()) top = p;
  ToolPose pose = sim.tool_pose();
  // Beside the sphere, out of contact: 60 mm to −x (the rim 45 mm from the top node), mid-plane 2 mm below it.
  pose.position_world_m = top + Eigen::Vector3d(-0.06, -0.002, 0.0);
  for (int i = 0; i < 50; ++i) {
    const HostStepResult& r = sim.step(pose);
    ASSERT_EQ(r.crossing.crossed_nodes, 0) << "step " << i;
  }
  ASSERT_EQ(sim.step(pose).contact_count, 0);
  // The jump: over the top node, 5 mm above it (its bottom face 4 mm above).
  pose.position_world_m = top + Eigen::Vector3d(0.0, 0.005, 0.0);
  const HostStepResult& jump = sim.step(pose);
  EXPECT_EQ(jump.contact_count, 0);
  EXPECT_GE(jump.crossing.rim_passes, 1);
  EXPECT_GE(jump.crossing.endpoint_crossed_nodes, 1);  // what the previous rule reported
  EXPECT_EQ(jump.crossing.through_nodes, 0);
  EXPECT_EQ(jump.crossing.crossed_nodes, 0);
  // Held there, still nothing crossed.
  for (int i = 0; i < 20; ++i) EXPECT_EQ(sim.step(pose).crossing.crossed_nodes, 0) << "step " << i;
}

}  // namespace
}  // namespace fissure::host
