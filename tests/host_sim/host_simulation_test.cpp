// The host step over the paper's scenes: with the paired method every scene runs its
// scripted trajectory with 0 crossed nodes and finite forces; runs are deterministic; the
// clamp reports one force per jaw.
#include "fissure/host_sim/host_simulation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "fissure/host_sim/scene_loader.hpp"

namespace fissure::host {
namespace {

struct RunSummary {
  int crossed_max = 0;
  int contact_steps = 0;
  bool finite = true;
  double force_max_n = 0.0;
  std::vector<double> force_y;
};

RunSummary run_scripted(const SceneDescription& scene, std::optional<SceneCollisionMethod> method = std::nullopt) {
  HostSimulation sim(scene, method);
  sim.settle(0.3);
  RunSummary out;
  const long steps = std::lround(trajectory_duration_s(scene) / scene.simulation.time_step_s);
  for (long i = 0; i < steps; ++i) {
    const TrajectorySample target = sim.scripted_target();
    const HostStepResult& r = sim.step(to_tool_pose(target.pose), target.jaw_gap_m);
    out.crossed_max = std::max(out.crossed_max, r.crossing.crossed_nodes);
    out.contact_steps += r.contact_count > 0 ? 1 : 0;
    out.finite = out.finite && r.force_on_tool_world_n.allFinite();
    out.force_max_n = std::max(out.force_max_n, r.force_on_tool_world_n.norm());
    out.force_y.push_back(r.force_on_tool_world_n.y());
  }
  return out;
}

class PaperScene : public ::testing::TestWithParam<std::string> {};

TEST_P(PaperScene, PairedRunsTheScriptWithNoCrossedNodeAndFiniteForce) {
  const SceneDescription scene = load_scene(resolve_scene_path(GetParam()));
  ASSERT_EQ(scene.simulation.collision_method, SceneCollisionMethod::kPaired);
  const RunSummary run = run_scripted(scene);
  EXPECT_EQ(run.crossed_max, 0);
  EXPECT_TRUE(run.finite);
  EXPECT_GT(run.contact_steps, 20) << "the script must actually bring the tool into contact";
  EXPECT_GT(run.force_max_n, 0.0);
}

INSTANTIATE_TEST_SUITE_P(Scenes, PaperScene, ::testing::Values("spatula-sphere", "convex-spatula-sphere", "clamp-sphere", "clamp-vessel"),
                         [](const ::testing::TestParamInfo<std::string>& param_info) {
                           std::string name = param_info.param;
                           for (char& c : name) c = c == '-' ? '_' : c;
                           return name;
                         });

TEST(HostSimulation, TwoRunsGiveIdenticalForceTraces) {
  const SceneDescription scene = load_scene(resolve_scene_path("spatula-sphere"));
  for (SceneCollisionMethod method : {SceneCollisionMethod::kPaired, SceneCollisionMethod::kBullet}) {
    const RunSummary a = run_scripted(scene, method);
    const RunSummary b = run_scripted(scene, method);
    ASSERT_EQ(a.force_y.size(), b.force_y.size());
    EXPECT_EQ(a.force_y, b.force_y) << to_string(method);
    EXPECT_GT(a.contact_steps, 0) << to_string(method);
  }
}

TEST(HostSimulation, ClampReportsOpposingJawForces) {
  const SceneDescription scene = load_scene(resolve_scene_path("clamp-sphere"));
  HostSimulation sim(scene);
  sim.settle(0.3);
  // Close to the scripted gap and hold (until 0.1 s before the hold ends): jaw A sits on the +z
  // side (tool y → world z).
  const TrajectoryWaypoint& close = scene.trajectory.waypoints.front();
  const double close_s = (scene.tool.clamp.jaw_gap_open_m - close.jaw_gap_m) / close.speed_m_per_s;
  const long steps = std::lround((close_s + close.hold_s - 0.1) / scene.simulation.time_step_s);
  for (long i = 0; i < steps; ++i) {
    const TrajectorySample target = sim.scripted_target();
    (void)sim.step(to_tool_pose(target.pose), target.jaw_gap_m);
  }
  const HostStepResult& r = sim.last();
  EXPECT_EQ(r.part_count, 2);
  EXPECT_NEAR(r.jaw_gap_m, scene.trajectory.waypoints.front().jaw_gap_m, 1e-9);
  EXPECT_GT(r.part_force_world_n[0].z(), 0.0);  // the ball pushes jaw A outwards (+z)
  EXPECT_LT(r.part_force_world_n[1].z(), 0.0);  // and jaw B towards −z
  EXPECT_TRUE(r.force_on_tool_world_n.isApprox(r.part_force_world_n[0] + r.part_force_world_n[1]));
}

TEST(HostSimulation, SpatulaSceneHasNoJawLogic) {
  const SceneDescription scene = load_scene(resolve_scene_path("spatula-sphere"));
  HostSimulation sim(scene);
  const HostStepResult& r = sim.step(to_tool_pose(scene.trajectory.start), 0.123);
  EXPECT_EQ(r.part_count, 1);
  EXPECT_EQ(r.jaw_gap_m, 0.0);
  EXPECT_NE(sim.tool_nodes(0), nullptr);
  EXPECT_EQ(sim.tool_nodes(1), nullptr);
}

TEST(HostSimulation, OutOfContactTheCollisionReportsNothing) {
  const SceneDescription scene = load_scene(resolve_scene_path("spatula-sphere"));
  HostSimulation sim(scene);
  sim.settle(0.1);
  for (int i = 0; i < 50; ++i) {
    const HostStepResult& r = sim.step(to_tool_pose(scene.trajectory.start));
    EXPECT_EQ(r.contact_count, 0);
    EXPECT_EQ(r.force_on_tool_world_n, Eigen::Vector3d::Zero());
    EXPECT_FALSE(r.part_results[0].broad_phase_hit);
  }
}


// Bench collision item 2: the Hunt-Crossley force of a plate held 4 mm into a springy ball
// (pose matching kMT = 0.05, no gravity) converges under mesh refinement in area-weighted mode.
// Before the rim triangles were weighted by their contacted share (and with a pressure-less
// shell whose cap fell away from the plate), 1280 / 5120 faces gave 1.47 / 1.25 N.
double held_plate_force_n(int faces) {
  SceneDescription scene = load_scene(resolve_scene_path("spatula-sphere"));
  SoftSphere sphere = std::get<SoftSphere>(scene.soft_body.shape);
  sphere.faces_count = faces;
  sphere.tessellation = SphereTessellation::kIcosphere;
  scene.soft_body.shape = sphere;
  scene.soft_body.shape_matching_ratio = 0.05;
  scene.simulation.gravity_world_m_per_s2 = {0.0, 0.0, 0.0};
  scene.tool.box_size_m = {0.1, 0.002, 0.1};
  scene.tool.node_spacing_m = 0.002;
  HostSimulation sim(scene, SceneCollisionMethod::kPaired);
  ToolPose pose = to_tool_pose(scene.trajectory.start);
  pose.position_world_m.y() = 0.3;
  (void)sim.step(pose);
  sim.settle(0.3);
  const double top_m = sim.soft_bounds_world_m().max().y();
  constexpr double kHalfThicknessM = 0.001;
  constexpr double kDepthM = 0.004;
  pose.position_world_m.y() = top_m + 0.002 + kHalfThicknessM;
  (void)sim.step(pose);
  const double target_y = top_m - kDepthM + kHalfThicknessM;
  while (pose.position_world_m.y() > target_y) {
    pose.position_world_m.y() = std::max(target_y, pose.position_world_m.y() - 0.01 * scene.simulation.time_step_s);
    (void)sim.step(pose);
  }
  double force_n = 0.0;
  for (int i = 0; i < 200; ++i) force_n = sim.step(pose).force_on_tool_world_n.norm();
  return force_n;
}

TEST(HostSimulation, HeldPlateForceConvergesUnderMeshRefinement) {
  const double coarse_n = held_plate_force_n(1280);
  const double fine_n = held_plate_force_n(5120);
  std::printf("[host] held plate 4 mm: 1280 faces %.4f N, 5120 faces %.4f N\n", coarse_n, fine_n);
  EXPECT_GT(fine_n, 0.5);
  EXPECT_NEAR(coarse_n / fine_n, 1.0, 0.04);
}

// Issue 5 / bench collision item 1: a 40 x 4 x 40 mm plate plunged 20 mm into the settled ball
// through HostSimulation (Bullet step + paired collision per host step, metrics after it). The
// plunge starts 15 mm above the ball; at 50 m/s that is one 35 mm step followed by a hold,
// when the nodes that carry the tool's velocity are left by the stopped tool.
struct PlungeOutcome {
  int crossed_max = 0;
  int contact_steps = 0;
};

PlungeOutcome plunge_plate(double speed_m_s, bool jump_from_settle_pose) {
  SceneDescription scene = load_scene(resolve_scene_path("spatula-sphere"));
  scene.tool.box_size_m = {0.04, 0.004, 0.04};
  constexpr double kHalfThicknessM = 0.002;
  HostSimulation sim(scene, SceneCollisionMethod::kPaired);
  const double dt = scene.simulation.time_step_s;
  ToolPose pose = to_tool_pose(scene.trajectory.start);
  pose.position_world_m.y() = 0.2;
  (void)sim.step(pose);
  sim.settle(0.3);
  const double top_m = sim.soft_bounds_world_m().max().y();
  pose.position_world_m.y() = top_m + 0.015 + kHalfThicknessM;
  const double end_y = top_m - 0.02 + kHalfThicknessM;
  // jump_from_settle_pose: the first step goes from 0.2 m straight to the plunge's first pose
  // (~0.12 m in 1 ms at 50 m/s), the case that found the stale node-tree leaves.
  if (!jump_from_settle_pose) (void)sim.step(pose);
  PlungeOutcome out;
  auto record = [&](const HostStepResult& r) {
    out.crossed_max = std::max(out.crossed_max, r.crossing.crossed_nodes);
    out.contact_steps += r.contact_count > 0 ? 1 : 0;
  };
  while (pose.position_world_m.y() > end_y) {
    pose.position_world_m.y() = std::max(end_y, pose.position_world_m.y() - speed_m_s * dt);
    record(sim.step(pose));
  }
  for (int i = 0; i < 200; ++i) record(sim.step(pose));
  return out;
}

class FastPlunge : public ::testing::TestWithParam<double> {};

TEST_P(FastPlunge, PairedPlateCrossesNoNode) {
  const PlungeOutcome run = plunge_plate(GetParam(), false);
  EXPECT_EQ(run.crossed_max, 0);
  // A 0.1 kg ball hit at 20–50 m/s by a driven plate is knocked away: contact is brief.
  EXPECT_GT(run.contact_steps, 0) << "the plate must hit the ball";
}

TEST_P(FastPlunge, PairedPlateCrossesNoNodeAfterAJumpIntoTheBall) {
  const PlungeOutcome run = plunge_plate(GetParam(), true);
  EXPECT_EQ(run.crossed_max, 0);
  EXPECT_GT(run.contact_steps, 0);
}

INSTANTIATE_TEST_SUITE_P(Speeds, FastPlunge, ::testing::Values(20.0, 50.0),
                         [](const ::testing::TestParamInfo<double>& param_info) {
                           return std::to_string(static_cast<int>(param_info.param)) + "_m_s";
                         });

// ---- Smooth contact force (normal_displacement measure, release ramp) -------------------------
// The spatula scene's plate pressed into the ball at 0.05 m/s (the hand script's speed) to a
// depth below the settled top, then held there while the pose dithers by ±40 µm steps every
// 10 ms (the SimFalcon encoder step seen at the tool; deterministic LCG, seed fixed). The real-time
// session showed the host force jumping between ≈1.5 N / 6 triangles and ≈4 N / 13 triangles at
// such a hold, as single nodes were taken / released and each brought a whole triangle's x.
struct DitheredHold {
  std::vector<double> force_n;      // per step of the dithered hold
  std::vector<double> depth_m;      // plate bottom below the settled top
  double max_step_change_n = 0.0;   // max |ΔF| between consecutive steps
  double mean_n = 0.0;
  double std_n = 0.0;
  int min_contacts = 0;
  int max_contacts = 0;
  int crossed_max = 0;
};

constexpr double kPressSpeedMS = 0.05;   // the scene's hand-script speed
constexpr double kDitherStepM = 40e-6;   // one encoder step at the tool (trace: 40 µm steps of tool y)
constexpr int kDitherPeriodSteps = 10;   // a new dither value every 10 ms

DitheredHold dithered_hold(double depth_m) {
  const SceneDescription scene = load_scene(resolve_scene_path("spatula-sphere"));
  HostSimulation sim(scene);
  sim.settle(0.5);
  const double dt = scene.simulation.time_step_s;
  const double half_thickness_m = 0.5 * scene.tool.box_size_m[1];
  const double top_m = sim.soft_bounds_world_m().max().y();
  ToolPose pose = to_tool_pose(scene.trajectory.start);
  const double hold_y = top_m - depth_m + half_thickness_m;
  while (pose.position_world_m.y() > hold_y) {
    pose.position_world_m.y() = std::max(hold_y, pose.position_world_m.y() - kPressSpeedMS * dt);
    (void)sim.step(pose);
  }
  for (int i = 0; i < 200; ++i) (void)sim.step(pose);  // let the ball settle under the plate
  DitheredHold out;
  out.min_contacts = 1 << 30;
  std::uint32_t lcg = 12345u;
  double previous_n = sim.last().force_on_tool_world_n.norm();
  for (int i = 0; i < 800; ++i) {
    if (i % kDitherPeriodSteps == 0) {
      lcg = lcg * 1664525u + 1013904223u;
      const int level = static_cast<int>((lcg >> 16) % 3u) - 1;  // −1, 0, +1 encoder steps
      pose.position_world_m.y() = hold_y + level * kDitherStepM;
    }
    const HostStepResult& r = sim.step(pose);
    const double f = r.force_on_tool_world_n.norm();
    out.force_n.push_back(f);
    out.depth_m.push_back(top_m - (pose.position_world_m.y() - half_thickness_m));
    out.max_step_change_n = std::max(out.max_step_change_n, std::abs(f - previous_n));
    previous_n = f;
    out.min_contacts = std::min(out.min_contacts, r.contact_count);
    out.max_contacts = std::max(out.max_contacts, r.contact_count);
    out.crossed_max = std::max(out.crossed_max, r.crossing.crossed_nodes);
  }
  double sum = 0.0;
  for (double f : out.force_n) sum += f;
  out.mean_n = sum / static_cast<double>(out.force_n.size());
  double sq = 0.0;
  for (double f : out.force_n) sq += (f - out.mean_n) * (f - out.mean_n);
  out.std_n = std::sqrt(sq / static_cast<double>(out.force_n.size()));
  return out;
}

class HeldDepth : public ::testing::TestWithParam<double> {};

TEST_P(HeldDepth, DitheredHoldHasNoForceLevelJumps) {
  const DitheredHold hold = dithered_hold(GetParam());
  std::printf("[host] dithered hold at %.1f mm: mean %.3f N, std/mean %.4f, max |dF| per step %.4f N, contacts %d..%d\n",
              GetParam() * 1e3, hold.mean_n, hold.std_n / hold.mean_n, hold.max_step_change_n, hold.min_contacts, hold.max_contacts);
  ASSERT_GT(hold.mean_n, 0.1) << "the plate must press the ball";
  EXPECT_EQ(hold.crossed_max, 0);
  // ±40 µm at a few mm of depth changes k·xⁿ by n·Δx/x ≈ 1–2 %, plus the slope of the release
  // ramp of nodes hovering in front of the face (a few %); a node taken or released must not add
  // a level of its own (the old measure jumped by 100–200 %): bound the per-step change and the
  // spread over the hold.
  EXPECT_LT(hold.max_step_change_n, 0.12 * hold.mean_n);
  EXPECT_LT(hold.std_n / hold.mean_n, 0.05);
}

INSTANTIATE_TEST_SUITE_P(Depths, HeldDepth, ::testing::Values(0.0035, 0.0045, 0.0055),
                         [](const ::testing::TestParamInfo<double>& param_info) {
                           return std::to_string(static_cast<int>(std::lround(param_info.param * 1e4))) + "_tenths_mm";
                         });

// First contact at the hand script's 0.05 m/s, pressing to 8 mm and pulling back out: once the
// plate touches the ball, pressing deeper never empties the contact set (lockstep sessions showed
// the set dropping to 0 for tens of ms while the plate went deeper, then coming back with a 5.5 N
// spike), and the force follows the depth without jumps as nodes are taken and released (the
// centroid measure stepped by 1–2 N at 50 µm when a node joined or left).
TEST(HostSimulation, PressAndReleaseAtHandSpeedKeepTheContactAndAContinuousForce) {
  const SceneDescription scene = load_scene(resolve_scene_path("spatula-sphere"));
  HostSimulation sim(scene);
  sim.settle(0.5);
  const double dt = scene.simulation.time_step_s;
  const double half_thickness_m = 0.5 * scene.tool.box_size_m[1];
  const double top_m = sim.soft_bounds_world_m().max().y();
  ToolPose pose = to_tool_pose(scene.trajectory.start);
  const double start_y = pose.position_world_m.y();
  const double end_y = top_m - 0.008 + half_thickness_m;  // 8 mm deep, as the hand script presses
  double shallowest_contact_y = -std::numeric_limits<double>::infinity();  // highest tool y that had contact
  int lost_steps = 0;
  double max_step_change_n = 0.0;
  double previous_n = 0.0;
  double peak_n = 0.0;
  auto record = [&](const HostStepResult& r) {
    const double f = r.force_on_tool_world_n.norm();
    max_step_change_n = std::max(max_step_change_n, std::abs(f - previous_n));
    previous_n = f;
    peak_n = std::max(peak_n, f);
  };
  while (pose.position_world_m.y() > end_y) {
    pose.position_world_m.y() = std::max(end_y, pose.position_world_m.y() - kPressSpeedMS * dt);
    const HostStepResult& r = sim.step(pose);
    if (r.contact_count > 0) {
      shallowest_contact_y = std::max(shallowest_contact_y, pose.position_world_m.y());
    } else if (pose.position_world_m.y() < shallowest_contact_y) {
      ++lost_steps;  // no contact although deeper than a step that had contact
    }
    record(r);
  }
  while (pose.position_world_m.y() < start_y) {
    pose.position_world_m.y() = std::min(start_y, pose.position_world_m.y() + kPressSpeedMS * dt);
    record(sim.step(pose));
  }
  std::printf("[host] press/release 0.05 m/s to 8 mm: peak %.3f N, steps without contact after first contact %d, max |dF| per step %.4f N\n",
              peak_n, lost_steps, max_step_change_n);
  EXPECT_GT(peak_n, 0.5);
  EXPECT_EQ(lost_steps, 0);
  // 50 µm per step at up to 8 mm with n = 1.5: the smooth increment is ≲ 1–2 % of the peak.
  EXPECT_LT(max_step_change_n, 0.05 * peak_n);
  EXPECT_LT(previous_n, 1e-9) << "pulled back out, nothing may hold the plate";
}

// The clamp squeezes the ball and opens again along its script: once the jaws are fully open
// (gap 0.12 m > the ball's 0.10 m) nothing may hold on to them. With the paper's centroid
// distance a node that had wrapped round jaw A's rim was dragged along and kept ≈ 13–16 N on the
// jaw all the way open (x counted the ball's sideways travel as indentation).
TEST(HostSimulation, ClampOpeningReleasesTheBall) {
  const SceneDescription scene = load_scene(resolve_scene_path("clamp-sphere"));
  HostSimulation sim(scene);
  sim.settle(0.3);
  const long steps = std::lround(trajectory_duration_s(scene) / scene.simulation.time_step_s);
  double squeeze_max_n = 0.0;
  int open_steps = 0;
  double open_force_max_n = 0.0;
  for (long i = 0; i < steps; ++i) {
    const TrajectorySample target = sim.scripted_target();
    const HostStepResult& r = sim.step(to_tool_pose(target.pose), target.jaw_gap_m);
    const double f = std::max(r.part_force_world_n[0].norm(), r.part_force_world_n[1].norm());
    squeeze_max_n = std::max(squeeze_max_n, f);
    // Fully open for 5 ms: the release must be over.
    if (r.jaw_gap_m >= scene.tool.clamp.jaw_gap_open_m - 1e-9 && ++open_steps > 5) open_force_max_n = std::max(open_force_max_n, f);
  }
  std::printf("[host] clamp: squeeze max %.3f N per jaw, after opening %.4f N\n", squeeze_max_n, open_force_max_n);
  EXPECT_GT(squeeze_max_n, 0.5) << "the clamp must grab the ball";
  EXPECT_GT(open_steps, 5) << "the script must open the clamp fully";
  EXPECT_LT(open_force_max_n, 0.01);
}

}  // namespace
}  // namespace fissure::host
