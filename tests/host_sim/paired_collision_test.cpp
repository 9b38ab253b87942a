// The paired-node thin-body collision end to end on a real Bullet soft body (BRIEF §3, issue 5):
// no crossed node at any speed, penetration ≤ 0.1 mm, finite forces, nothing done out of
// contact, deterministic, F ∝ dⁿ on a flat slab with area weighting, no allocation per step.
#include "fcl_oracle.hpp"
#include "soft_scene_fixture.hpp"

#include <fissure/host_sim/contact_metrics.hpp>
#include <fissure/host_sim/host_simulation.hpp>
#include <fissure/host_sim/scene_loader.hpp>
#include <fissure/host_sim/thin_body_collision.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <new>
#include <random>
#include <string>

// Counts heap allocations so a test can assert that step() allocates nothing in steady state.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
namespace {
std::atomic<long> g_allocations{0};
}  // namespace
// GCC 12 at -O1 (the sanitizer presets) inlines these replacements into their callers and then
// reports free() on memory from "operator new" as -Wmismatched-new-delete: a false positive for
// a replaced global operator new that itself allocates with malloc.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop

namespace fissure::host {
namespace {

using test_scene::kStep_s;
using test_scene::PlungeOutcome;
using test_scene::PlungeSpec;

enum class Tool { kPlate4mm, kPlate1mm, kBladeEdgeFirst, kConvexSpatula };

std::string tool_name(Tool tool) {
  switch (tool) {
    case Tool::kPlate4mm: return "plate4mm";
    case Tool::kPlate1mm: return "plate1mm";
    case Tool::kBladeEdgeFirst: return "blade_edge_first";
    case Tool::kConvexSpatula: return "convex_spatula";
  }
  return "?";
}

ToolNodes make_tool(Tool tool) {
  switch (tool) {
    case Tool::kPlate4mm: return test_scene::plate_tool(0.004);
    case Tool::kPlate1mm:
    case Tool::kBladeEdgeFirst: return test_scene::plate_tool(0.001);
    case Tool::kConvexSpatula: {
      RoundedSpatulaParams params;  // 40 × 40 × 2 mm, rounded rims
      return ToolNodes::from_convex_mesh(make_rounded_spatula_mesh(params, 3.0 * params.thickness_m));
    }
  }
  return test_scene::plate_tool(0.004);
}

PlungeSpec spec_for(Tool tool, double speed) {
  PlungeSpec spec;
  spec.speed_m_s = speed;
  if (tool == Tool::kBladeEdgeFirst) {
    spec.orientation = test_scene::edge_first_orientation();
    spec.start_height_m = 0.135;  // the blade reaches 20 mm below its origin
    spec.end_height_m = 0.05;
  }
  return spec;
}

struct PlungeCase {
  Tool tool;
  double speed_m_s;
};

class PairedPlunge : public ::testing::TestWithParam<PlungeCase> {};

// Kinematic tool driven down through the paper's sphere at 0.1–50 m/s with a 1 ms step
// (0.1 mm to 50 mm per step — up to 50 plate thicknesses): zero crossed nodes, ≤ 0.1 mm penetration.
TEST_P(PairedPlunge, NoCrossedNodesAndNoPenetrationAtAnySpeed) {
  const PlungeCase c = GetParam();
  const ToolNodes tool = make_tool(c.tool);
  PlungeSpec spec = spec_for(c.tool, c.speed_m_s);
  spec.check_triangles_cut = true;  // reported (a deep plunge wraps the sphere round the tool)
  const PlungeOutcome out = test_scene::run_sphere_plunge(tool, SceneCollisionMethod::kPaired, spec);
  std::printf("[paired] %-17s %5.1f m/s: crossed %d, max penetration %.4f mm, max |F| %.3f N, excluded %d, "
              "contact steps %d, max triangles %d, triangles cut by the tool at end %d (max over run %d)\n",
              tool_name(c.tool).c_str(), c.speed_m_s, out.crossed_nodes, out.max_penetration_m * 1e3, out.max_force_n,
              out.total_excluded, out.steps_in_contact, out.max_contacted_triangles, out.triangles_cut_end, out.max_triangles_cut);
  EXPECT_EQ(out.crossed_nodes, 0);
  EXPECT_LE(out.max_penetration_m, 1e-4);
  EXPECT_TRUE(out.forces_finite);
  EXPECT_TRUE(out.positions_finite);
  // (Without the edge nodes an edge-first blade cuts between the sphere's nodes with no contact
  // and no force; its rim nodes push the surface in like any other tool.)
  EXPECT_GT(out.steps_in_contact, 0) << "the tool must actually hit the sphere";
  EXPECT_GT(out.max_force_n, 0.0);
  EXPECT_EQ(out.max_both_face_contacts, 0) << "pairing leaves at most one face of a pair pushing";
}

INSTANTIATE_TEST_SUITE_P(
    ToolsAndSpeeds, PairedPlunge,
    ::testing::ValuesIn([] {
      std::vector<PlungeCase> cases;
      for (const Tool tool : {Tool::kPlate4mm, Tool::kPlate1mm, Tool::kBladeEdgeFirst, Tool::kConvexSpatula})
        for (const double speed : {0.1, 1.0, 10.0, 50.0}) cases.push_back({tool, speed});
      return cases;
    }()),
    [](const ::testing::TestParamInfo<PlungeCase>& param_info) {
      return tool_name(param_info.param.tool) + "_" + std::to_string(static_cast<int>(param_info.param.speed_m_s * 10)) + "dm_s";
    });

// Edge-first (the thin rim leading, moving along the tool's 40 mm in-plane direction) 5 mm into
// the 128-face sphere: no soft node lies in a 1 mm blade's path, so only the edge nodes on the
// rim faces meet the soft triangles (through their interiors). The rim must push the surface in
// like any indenter: force > 0 at 5 mm, no crossed node, ≤ 0.1 mm penetration, and no soft
// triangle cut by the tool's interior at the end.
class EdgeFirstPlunge : public ::testing::TestWithParam<PlungeCase> {};

// Order statistic of wall-clock samples (for the printed step times).
double percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  return values[static_cast<std::size_t>(q * static_cast<double>(values.size() - 1))];
}


PlungeSpec edge_first_spec(double speed) {
  PlungeSpec spec;
  spec.speed_m_s = speed;
  spec.orientation = test_scene::edge_first_orientation();
  spec.start_height_m = 0.135;          // the rim reaches 20 mm below the origin: starts 15 mm above the sphere
  spec.end_depth_into_soft_m = 0.005;   // stop with the rim 5 mm below the settled sphere's top
  spec.hold_steps = 50;
  spec.check_triangles_cut = true;
  return spec;
}

TEST_P(EdgeFirstPlunge, TheRimPushesTheSurfaceInAtAnySpeed) {
  const PlungeCase c = GetParam();
  const ToolNodes tool = make_tool(c.tool);
  ASSERT_GT(tool.edge_node_count(), 0);
  const PlungeOutcome out = test_scene::run_sphere_plunge(tool, SceneCollisionMethod::kPaired, edge_first_spec(c.speed_m_s));
  std::printf("[edge-first] %-15s %5.1f m/s: crossed %d, max penetration %.4f mm, F_y on arrival at 5 mm %.3f N, max F_y at "
              "5 mm %.3f N (end of hold %.3f N, max |F| over run %.3f N), rim %.2f mm into the soft top, triangles cut at end "
              "%d (max over run %d), step time median %.1f us p99 %.1f us\n",
              tool_name(c.tool).c_str(), c.speed_m_s, out.crossed_nodes, out.max_penetration_m * 1e3, out.force_y_at_arrival_n,
              out.max_force_y_at_end_n, out.final_force_y_n, out.max_force_n, (out.soft_top_start_m - out.tool_bottom_end_m) * 1e3, out.triangles_cut_end,
              out.max_triangles_cut, percentile(out.step_seconds, 0.5) * 1e6,
              percentile(out.step_seconds, 0.99) * 1e6);
  EXPECT_NEAR(out.soft_top_start_m - out.tool_bottom_end_m, 0.005, 1e-9);
  EXPECT_EQ(out.crossed_nodes, 0);
  EXPECT_LE(out.max_penetration_m, 1e-4);
  // The rim held 5 mm into the sphere is pushed back. Slow, already on the arrival step; fast, the
  // nodes the rim displaced left with its velocity (enforced displacement) and the light shell
  // (0.1 kg) flies ahead of the stopped rim for a few steps before springing back onto it, so
  // the force at 5 mm is taken over the arrival step and the 50-step hold.
  EXPECT_GT(out.max_force_y_at_end_n, 0.0) << "the rim 5 mm into the sphere must be pushed back";
  if (c.speed_m_s <= 1.0) {
    EXPECT_GT(out.force_y_at_arrival_n, 0.0);
  }
  EXPECT_EQ(out.triangles_cut_end, 0) << "no soft triangle may be sliced by the tool";
  EXPECT_TRUE(out.forces_finite);
  EXPECT_TRUE(out.positions_finite);
  EXPECT_EQ(out.max_both_face_contacts, 0);
}

INSTANTIATE_TEST_SUITE_P(
    ToolsAndSpeeds, EdgeFirstPlunge,
    ::testing::ValuesIn([] {
      std::vector<PlungeCase> cases;
      for (const Tool tool : {Tool::kBladeEdgeFirst, Tool::kConvexSpatula})
        for (const double speed : {0.1, 1.0, 10.0, 50.0}) cases.push_back({tool, speed});
      return cases;
    }()),
    [](const ::testing::TestParamInfo<PlungeCase>& param_info) {
      return tool_name(param_info.param.tool) + "_" + std::to_string(static_cast<int>(param_info.param.speed_m_s * 10)) + "dm_s";
    });

// Without the edge nodes (the paper's face-only placement) the same blade slices the sphere with
// no force: what the edge nodes fix.
TEST(PairedCollision, WithoutEdgeNodesTheEdgeFirstBladeSlicesTheSphere) {
  BoxToolShape shape;
  shape.half_extents_m = Eigen::Vector3d(0.02, 0.0005, 0.02);
  shape.edge_nodes = false;
  const ToolNodes tool = ToolNodes::from_box(shape);
  ASSERT_EQ(tool.edge_node_count(), 0);
  const PlungeOutcome out = test_scene::run_sphere_plunge(tool, SceneCollisionMethod::kPaired, edge_first_spec(1.0));
  std::printf("[edge-first] no edge nodes 1.0 m/s: F_y at 5 mm %.3f N, triangles cut at end %d\n", out.force_y_at_arrival_n,
              out.triangles_cut_end);
  EXPECT_EQ(out.max_force_n, 0.0);
  EXPECT_GT(out.triangles_cut_end, 0);
}

// The edge nodes must not change what the large faces do face-first: same zero crossings, the
// same force to within 10 % (only the rim rows add contacts, at the plate's sides), never more
// soft triangles cut by the plate's rim. Also prints the collision step time (wall clock,
// in-contact steps; informative, not asserted).
TEST(PairedCollision, EdgeNodesLeaveTheFaceFirstPlungeUnchanged) {
  for (const double thickness : {0.004, 0.001}) {
    BoxToolShape shape;
    shape.half_extents_m = Eigen::Vector3d(0.02, 0.5 * thickness, 0.02);
    const ToolNodes with_edges = ToolNodes::from_box(shape);
    shape.edge_nodes = false;
    const ToolNodes faces_only = ToolNodes::from_box(shape);
    for (const double speed : {0.1, 1.0, 10.0, 50.0}) {
      PlungeSpec spec = spec_for(Tool::kPlate4mm, speed);
      spec.check_triangles_cut = true;
      const PlungeOutcome a = test_scene::run_sphere_plunge(faces_only, SceneCollisionMethod::kPaired, spec);
      const PlungeOutcome b = test_scene::run_sphere_plunge(with_edges, SceneCollisionMethod::kPaired, spec);
      std::printf("[face-first] plate %.0f mm %5.1f m/s: triangles cut at end %d | %d (max over run %d | %d)\n", thickness * 1e3,
                  speed, a.triangles_cut_end, b.triangles_cut_end, a.max_triangles_cut, b.max_triangles_cut);
      std::printf("[face-first] plate %.0f mm %5.1f m/s: faces only | with edge nodes: crossed %d | %d, max pen %.4f | %.4f mm, "
                  "max |F| %.3f | %.3f N, F_y end of hold %.3f | %.3f N, step time median %.1f | %.1f us, p99 %.1f | %.1f us\n",
                  thickness * 1e3, speed, a.crossed_nodes, b.crossed_nodes, a.max_penetration_m * 1e3, b.max_penetration_m * 1e3,
                  a.max_force_n, b.max_force_n, a.final_force_y_n, b.final_force_y_n, percentile(a.step_seconds, 0.5) * 1e6,
                  percentile(b.step_seconds, 0.5) * 1e6, percentile(a.step_seconds, 0.99) * 1e6,
                  percentile(b.step_seconds, 0.99) * 1e6);
      EXPECT_EQ(a.crossed_nodes, 0);
      EXPECT_EQ(b.crossed_nodes, 0);
      EXPECT_LE(b.max_penetration_m, 1e-4);
      EXPECT_LE(b.triangles_cut_end, a.triangles_cut_end) << "edge nodes never leave more triangles cut by the plate's rim";
      if (thickness < 0.002 && speed < 0.5) {
        // The one run that moves: faces only, the slow 1 mm plate holds at 13.6 N, 20–25 % below
        // every other plunge (17–19 N); with the rim rows holding the triangles at its sides it
        // holds at 17.9 N, in line with the others.
        EXPECT_GT(b.final_force_y_n, a.final_force_y_n);
        continue;
      }
      EXPECT_NEAR(b.max_force_n / a.max_force_n, 1.0, 0.1);
      // With the rim rows, triangles at the plate's sides are held on its rim planes and push
      // sideways (normal_displacement measures x along the rim normal): the upward force at the
      // end of the hold is up to ~21 % lower than faces-only (measured 0.79 for the 1 mm plate).
      EXPECT_NEAR(b.final_force_y_n / a.final_force_y_n, 1.0, 0.25);
    }
  }
}

// A soft triangle straddling the blade's edge with no soft node in front of it: 5 cm slab cells,
// the blade pressed edge-first into one triangle's interior. The edge nodes must see the
// triangle (sweeping into it) and put its vertices on the rim plane: the surface goes down with
// the edge, pushes back, and no triangle is cut.
TEST(PairedCollision, EdgeSweepingIntoATriangleInteriorPlacesItsVerticesOnTheRimPlane) {
  test_scene::SoftWorld world(false);
  world.add_slab(0.1, 2);  // 3×3 nodes, 5 cm apart: nothing under the 1 mm × 40 mm edge
  const ToolNodes tool = test_scene::plate_tool(0.001);
  auto collision = make_paired_collision(tool, world.soft(), ThinBodyCollisionParams{});
  CollisionStepResult result;
  result.reserve_for(world.soft().m_faces.size());
  constexpr double kRim_m = 0.02;           // rim below the tool origin (edge-first: tool −x is world −y)
  constexpr double kDepth_m = 0.003;
  const Eigen::Vector3d offset(0.012, 0.0, 0.004);  // inside a triangle, away from every slab node
  ToolPose previous;
  previous.orientation_world = test_scene::edge_first_orientation();
  previous.position_world_m = offset + Eigen::Vector3d(0, kRim_m + 0.0001, 0);  // rim 0.1 mm above the slab
  for (const auto& p : world.node_positions())
    ASSERT_GT((Eigen::Vector2d(p.x(), p.z()) - Eigen::Vector2d(offset.x(), offset.z())).cwiseAbs().minCoeff(), 0.002)
        << "a soft node under the edge would make this the easy case";
  for (int s = 1; s <= 10; ++s) {
    ToolPose current = previous;
    current.position_world_m.y() = kRim_m + 0.0001 - (kDepth_m + 0.0001) * s / 10.0;
    world.step_without_dynamics();
    collision->step(previous, current, kStep_s, world.soft(), result);
    previous = current;
  }
  const double rim_y = previous.position_world_m.y() - kRim_m;
  EXPECT_NEAR(rim_y, -kDepth_m, 1e-12);
  EXPECT_GT(result.force_on_tool_world_n.y(), 0.0);
  ASSERT_FALSE(result.contacts.empty());
  int on_rim = 0;
  for (const ContactRecord& contact : result.contacts) {
    const int plane = contact.tool_plane;
    // Plane 1 = tool −x: the leading rim face (world −y edge-first).
    EXPECT_EQ(plane, 1) << "face " << contact.soft_face;
    on_rim += contact.tool_node >= 0 && tool.edge_node_flags()[static_cast<std::size_t>(contact.tool_node)] != 0 ? 1 : 0;
  }
  EXPECT_GT(on_rim, 0) << "an edge node led the contact";
  int displaced = 0;
  for (const auto& p : world.node_positions()) {
    if (p.y() < -1e-9) {
      ++displaced;
      EXPECT_NEAR(p.y(), rim_y - ThinBodyCollisionParams{}.skin_m, 1e-6) << "vertex placed on the rim plane";
    }
  }
  EXPECT_GE(displaced, 3) << "at least the straddling triangle's vertices";
  EXPECT_EQ(test_scene::triangles_cut_by_tool(tool, world.soft(), previous, 1e-6), 0);
}

// At 50 m/s both faces of the plate sweep through the sphere's top within one step: the pairs
// are both in contact and the trailing face must be excluded.
TEST(PairedCollision, FastPlateExcludesTheTrailingFaceOfItsPairs) {
  const ToolNodes tool = test_scene::plate_tool(0.004);
  const PlungeOutcome out = test_scene::run_sphere_plunge(tool, SceneCollisionMethod::kPaired, spec_for(Tool::kPlate4mm, 50.0));
  EXPECT_GT(out.total_excluded, 0);
  EXPECT_EQ(out.total_both_face_contacts, 0);
  EXPECT_EQ(out.crossed_nodes, 0);
}

TEST(PairedCollision, OutOfContactTheStepDoesNothing) {
  test_scene::SoftWorld world(true);
  world.add_sphere();
  world.step_dynamics();
  const ToolNodes tool = test_scene::plate_tool(0.004);
  auto collision = make_paired_collision(tool, world.soft(), ThinBodyCollisionParams{});
  EXPECT_EQ(collision->method(), SceneCollisionMethod::kPaired);
  CollisionStepResult result;
  ToolPose previous;
  previous.position_world_m = Eigen::Vector3d(0, 0.3, 0);
  ToolPose current = previous;
  current.position_world_m.y() = 0.25;  // moving, but 15 cm above the sphere
  const auto before = world.node_positions();
  std::vector<btVector3> velocities;
  for (int i = 0; i < world.soft().m_nodes.size(); ++i) velocities.push_back(world.soft().m_nodes[i].m_v);
  collision->step(previous, current, kStep_s, world.soft(), result);
  EXPECT_FALSE(result.broad_phase_hit);
  EXPECT_TRUE(result.contacts.empty());
  EXPECT_EQ(result.contacted_triangles, 0);
  EXPECT_EQ(result.displaced_soft_nodes, 0);
  EXPECT_EQ(result.force_on_tool_world_n, Eigen::Vector3d::Zero());
  EXPECT_EQ(result.seconds_narrow + result.seconds_response + result.seconds_force, 0.0) << "no later stage ran";
  EXPECT_EQ(world.node_positions(), before);
  for (int i = 0; i < world.soft().m_nodes.size(); ++i) EXPECT_EQ(world.soft().m_nodes[i].m_v, velocities[static_cast<std::size_t>(i)]);
}

TEST(PairedCollision, StepDoesNotAllocateInContact) {
  test_scene::SoftWorld world(true);
  world.add_sphere();
  for (int i = 0; i < 50; ++i) world.step_dynamics();
  const ToolNodes tool = test_scene::plate_tool(0.004);
  auto collision = make_paired_collision(tool, world.soft(), ThinBodyCollisionParams{});
  CollisionStepResult result;
  result.reserve_for(world.soft().m_faces.size());
  ToolPose previous;
  previous.position_world_m = Eigen::Vector3d(0, 0.115, 0);
  long allocations_in_steps = 0;
  int contact_steps = 0;
  for (int s = 1; s <= 200; ++s) {
    ToolPose current = previous;
    current.position_world_m.y() = std::max(0.04, 0.115 - 0.002 * s);  // 2 m/s down, then hold
    world.step_dynamics();
    const long before = g_allocations.load();
    collision->step(previous, current, kStep_s, world.soft(), result);
    if (s > 1) allocations_in_steps += g_allocations.load() - before;
    contact_steps += result.contacted_triangles > 0 ? 1 : 0;
    previous = current;
  }
  EXPECT_GT(contact_steps, 100);
  EXPECT_EQ(allocations_in_steps, 0);
}

TEST(PairedCollision, EdgeFirstStepDoesNotAllocateInContact) {
  test_scene::SoftWorld world(true);
  world.add_sphere();
  for (int i = 0; i < 50; ++i) world.step_dynamics();
  const ToolNodes tool = test_scene::plate_tool(0.001);
  auto collision = make_paired_collision(tool, world.soft(), ThinBodyCollisionParams{});
  CollisionStepResult result;
  result.reserve_for(world.soft().m_faces.size());
  ToolPose previous;
  previous.orientation_world = test_scene::edge_first_orientation();
  previous.position_world_m = Eigen::Vector3d(0, 0.135, 0);
  long allocations_in_steps = 0;
  int contact_steps = 0;
  for (int s = 1; s <= 200; ++s) {
    ToolPose current = previous;
    current.position_world_m.y() = std::max(0.11, 0.135 - 0.001 * s);  // 1 m/s, rim 10 mm into the top, then hold
    world.step_dynamics();
    const long before = g_allocations.load();
    collision->step(previous, current, kStep_s, world.soft(), result);
    if (s > 1) allocations_in_steps += g_allocations.load() - before;
    contact_steps += result.contacted_triangles > 0 ? 1 : 0;
    previous = current;
  }
  EXPECT_GT(contact_steps, 50);
  EXPECT_EQ(allocations_in_steps, 0);
}

// Invariant fuzz: random tool orientations, approach directions, speeds (0.1–20 m/s) and spins
// (≤ 5 rad/s) through the sphere — no crossed node, no node deeper than 0.1 mm in the tool,
// finite forces and positions. Fixed seed: deterministic.
// On every step the FCL oracle (fcl_oracle.hpp) answers the same two questions independently:
// which soft triangles reach deeper than 0.1 mm into the tool (the project's clip,
// ToolVolume::reaches_inside, triangle by triangle) and which nodes lie deeper than 0.1 mm inside
// (the fixture's tracker's test); the two must agree on every triangle and node, up to the
// oracle's 1 µm depth margin. Cut triangles are not asserted to be zero here: today's design
// leaves some (issue 22); the assertion is that both rulers count the same ones.
TEST(PairedCollision, RandomPosesVelocitiesAndSpinsKeepTheInvariants) {
  std::mt19937 rng(20261121);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> speed_log10(-1.0, std::log10(20.0));
  const ToolNodes plate = test_scene::plate_tool(0.002);
  RoundedSpatulaParams spatula_params;  // make_tool(Tool::kConvexSpatula)'s mesh
  const ConvexMeshToolShape spatula_mesh = make_rounded_spatula_mesh(spatula_params, 3.0 * spatula_params.thickness_m);
  const ToolNodes spatula = ToolNodes::from_convex_mesh(spatula_mesh);
  const Eigen::Vector3d plate_half_m(0.02, 0.001, 0.02);  // test_scene::plate_tool(0.002)
  const ToolVolume plate_volume = ToolVolume::from_box(plate_half_m);
  const ToolVolume spatula_volume = ToolVolume::from_convex_mesh(spatula_mesh.vertices_tool_m, spatula_mesh.triangles);
  const test_oracle::FclToolOracle plate_oracle = test_oracle::FclToolOracle::from_box(plate_half_m, kInsideToleranceM);
  const test_oracle::FclToolOracle spatula_oracle(spatula_mesh.vertices_tool_m, kInsideToleranceM);
  const Eigen::Vector3d centre(0, test_scene::kSphereRadius_m, 0);
  int runs_with_contact = 0;
  test_oracle::RunTally all_runs;
  std::vector<Eigen::Vector3d> clip_scratch;
  for (int run = 0; run < 16; ++run) {
    const ToolNodes& tool = run % 2 == 0 ? plate : spatula;
    const ToolVolume& volume = run % 2 == 0 ? plate_volume : spatula_volume;
    const test_oracle::FclToolOracle& oracle = run % 2 == 0 ? plate_oracle : spatula_oracle;
    Eigen::AlignedBox3d tool_bounds;  // tool frame
    for (const Eigen::Vector3d& v : tool.hull_vertices_tool_m()) tool_bounds.extend(v);
    test_scene::SoftWorld world(true);
    world.add_sphere();
    for (int i = 0; i < 60; ++i) world.step_dynamics();
    std::vector<std::array<int, 3>> faces;
    for (int f = 0; f < world.soft().m_faces.size(); ++f)
      faces.push_back({static_cast<int>(world.soft().m_faces[f].m_n[0] - &world.soft().m_nodes[0]),
                       static_cast<int>(world.soft().m_faces[f].m_n[1] - &world.soft().m_nodes[0]),
                       static_cast<int>(world.soft().m_faces[f].m_n[2] - &world.soft().m_nodes[0])});
    test_oracle::RunTally tally;
    auto collision = make_paired_collision(tool, world.soft(), ThinBodyCollisionParams{});
    CollisionStepResult result;
    Eigen::Vector3d direction(unit(rng), unit(rng) - 1.2, unit(rng));  // mostly downward, never from below the ground
    direction.normalize();
    const double speed = std::pow(10.0, speed_log10(rng));
    const Eigen::Vector3d spin = 5.0 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng)) / std::sqrt(3.0);
    ToolPose previous;
    previous.orientation_world = Eigen::Quaterniond::UnitRandom();
    previous.position_world_m = centre - 0.085 * direction + 0.02 * Eigen::Vector3d(unit(rng), 0.0, unit(rng));
    test_scene::CrossingTracker tracker(tool, world.node_positions(), previous);
    bool finite = true;
    int contact_steps = 0;
    const int steps = std::min(400, static_cast<int>(0.13 / (speed * kStep_s)) + 1);
    for (int s = 0; s < steps; ++s) {
      ToolPose current = previous;
      current.position_world_m += speed * kStep_s * direction;
      current.position_world_m.y() = std::max(current.position_world_m.y(), 0.025);  // stay off the ground
      current.orientation_world =
          (Eigen::Quaterniond(Eigen::AngleAxisd(spin.norm() * kStep_s, spin.normalized())) * previous.orientation_world).normalized();
      world.step_dynamics();
      collision->step(previous, current, kStep_s, world.soft(), result);
      const auto nodes = world.node_positions();
      tracker.update(nodes, current);
      {
        // The project's answers, item by item, and the oracle's.
        const Eigen::Isometry3d tool_to_world = to_isometry(current);
        std::vector<char> cut(faces.size(), 0), inside(nodes.size(), 0);
        // A triangle whose bounds miss the tool's cannot be cut: it is not clipped (the clip over
        // the spatula's 1176 planes is this test's main cost). The count over all faces
        // (triangles_cut_by_volume, through HostSimulation::triangles_cut_by_tool) is checked
        // against the oracle by the plunge sweep (hold_jitter_test.cpp).
        for (std::size_t f = 0; f < faces.size(); ++f) {
          const std::array<Eigen::Vector3d, 3> corner = {current.to_tool(nodes[static_cast<std::size_t>(faces[f][0])]),
                                                         current.to_tool(nodes[static_cast<std::size_t>(faces[f][1])]),
                                                         current.to_tool(nodes[static_cast<std::size_t>(faces[f][2])])};
          Eigen::AlignedBox3d bounds(corner[0]);
          bounds.extend(corner[1]).extend(corner[2]);
          if (!bounds.intersects(tool_bounds)) continue;
          cut[f] = volume.reaches_inside(corner[0], corner[1], corner[2], kInsideToleranceM, clip_scratch) ? 1 : 0;
        }
        for (std::size_t i = 0; i < nodes.size(); ++i)
          inside[i] = -tool.signed_distance_m(current.to_tool(nodes[i])) > test_scene::CrossingTracker::kInsideTolerance_m ? 1 : 0;
        test_oracle::OracleCounts o = oracle.check(nodes, faces, tool_to_world, false);
        if (o.cut != cut || o.inside != inside) {
          o = oracle.check(nodes, faces, tool_to_world, true);  // the answers differ at t: the margins decide
        } else {
          o.cut_loose = o.cut_strict = o.cut;  // identical at t: nothing for the margins to decide
          o.inside_loose = o.inside_strict = o.inside;
        }
        const test_oracle::Agreement triangles = test_oracle::compare(cut, o.cut, o.cut_loose, o.cut_strict);
        tally.add(triangles, test_oracle::compare(inside, o.inside, o.inside_loose, o.inside_strict));
      }
      finite = finite && result.force_on_tool_world_n.allFinite();
      for (const auto& p : nodes) finite = finite && p.allFinite();
      contact_steps += result.contacted_triangles > 0 ? 1 : 0;
      previous = current;
    }
    runs_with_contact += contact_steps > 0 ? 1 : 0;
    std::printf("[fuzz] run %2d %-7s %6.2f m/s, %3d steps: cut triangles project max %d on %d steps, oracle max %d on %d steps, "
                "differ %ld (beyond the margin %ld) | nodes inside project max %d, oracle max %d, differ %ld (beyond %ld)\n",
                run, run % 2 == 0 ? "plate" : "spatula", speed, tally.steps, tally.project_max_cut, tally.project_steps_with_cut,
                tally.oracle_max_cut, tally.oracle_steps_with_cut, tally.triangles_differ, tally.triangles_beyond_margin,
                tally.project_max_inside, tally.oracle_max_inside, tally.nodes_differ, tally.nodes_beyond_margin);
    EXPECT_EQ(tracker.crossed_nodes(), 0) << "run " << run << " speed " << speed;
    EXPECT_LE(tracker.max_penetration_m(), 1e-4) << "run " << run << " speed " << speed;
    EXPECT_TRUE(finite) << "run " << run;
    EXPECT_EQ(tally.triangles_beyond_margin, 0) << "run " << run << ": the oracle and the clip disagree on cut triangles";
    EXPECT_EQ(tally.nodes_beyond_margin, 0) << "run " << run << ": the oracle and the tracker disagree on nodes inside";
    all_runs.triangles_differ += tally.triangles_differ;
    all_runs.project_steps_with_cut += tally.project_steps_with_cut;
    all_runs.oracle_steps_with_cut += tally.oracle_steps_with_cut;
  }
  std::printf("[fuzz] all runs: steps with cut triangles project %d, oracle %d; triangle answers differing within the margin %ld\n",
              all_runs.project_steps_with_cut, all_runs.oracle_steps_with_cut, all_runs.triangles_differ);
  EXPECT_GE(runs_with_contact, 12) << "the random runs must mostly hit the sphere";
}

TEST(PairedCollision, TwoRunsAreIdentical) {
  const ToolNodes tool = test_scene::plate_tool(0.004);
  const PlungeOutcome a = test_scene::run_sphere_plunge(tool, SceneCollisionMethod::kPaired, spec_for(Tool::kPlate4mm, 10.0));
  const PlungeOutcome b = test_scene::run_sphere_plunge(tool, SceneCollisionMethod::kPaired, spec_for(Tool::kPlate4mm, 10.0));
  EXPECT_EQ(a.final_nodes, b.final_nodes);
  EXPECT_EQ(a.final_force_y_n, b.final_force_y_n);
}

// Holding the plate in the squashed sphere: a steady upward force (issue 5: hold jitter ≤ 1 %).
TEST(PairedCollision, HoldGivesASteadyUpwardForce) {
  const ToolNodes tool = test_scene::plate_tool(0.004);
  for (const double speed : {1.0, 10.0}) {
    PlungeSpec spec = spec_for(Tool::kPlate4mm, speed);
    // 1 m/s must be steady to 1 %; after a 10 m/s impact the sphere is still settling and
    // its contact set still changes now and then (one triangle ≈ 0.4 N): reported, bounded looser.
    const double jitter_bound = speed < 5.0 ? 0.01 : 0.05;
    spec.hold_steps = 500;
    const PlungeOutcome out = test_scene::run_sphere_plunge(tool, SceneCollisionMethod::kPaired, spec);
    // Last 0.3 s of the hold (the first 0.2 s let the sphere settle around the plate).
    const std::vector<double> hold(out.force_y_n.end() - 300, out.force_y_n.end());
    double mean = 0.0;
    for (const double f : hold) mean += f;
    mean /= static_cast<double>(hold.size());
    double variance = 0.0;
    for (const double f : hold) variance += (f - mean) * (f - mean);
    const double jitter = std::sqrt(variance / static_cast<double>(hold.size())) / mean;
    std::printf("[paired] hold after %.0f m/s: mean F_y %.4f N, jitter (std/mean) %.5f\n", speed, mean, jitter);
    EXPECT_GT(mean, 0.0) << "the squashed sphere pushes the plate up";
    EXPECT_LE(jitter, jitter_bound);
    EXPECT_EQ(out.crossed_nodes, 0);
  }
}

// Press a plate (smaller than the slab) quasi-statically into a flat soft slab (the slab's own
// dynamics frozen so only the collision moves it). The contact set does not grow with depth, so
// with k, λ per unit area the force must follow k·A·dⁿ exactly: fit the exponent.
struct PressResult {
  std::vector<double> depth_m;
  std::vector<double> force_n;
};

PressResult press_slab(int cells, const HuntCrossleyParams& hc, double max_depth_m, int steps_to_max,
                       double onset_ramp_s = ThinBodyCollisionParams{}.contact_onset_ramp_s, int hold_steps = 0) {
  test_scene::SoftWorld world(false);
  world.add_slab(0.1, cells);
  BoxToolShape shape;
  shape.half_extents_m = Eigen::Vector3d(0.0199, 0.002, 0.0199);  // just inside a 40 mm square of cells
  shape.nodes_u = shape.nodes_v = 11;
  const ToolNodes tool = ToolNodes::from_box(shape);
  ThinBodyCollisionParams params;
  params.hunt_crossley = hc;
  params.contact_onset_ramp_s = onset_ramp_s;
  auto collision = make_paired_collision(tool, world.soft(), params);
  CollisionStepResult result;
  ToolPose previous;
  previous.position_world_m = Eigen::Vector3d(0, 0.0021, 0);  // bottom face 0.1 mm above the slab
  PressResult press;
  for (int s = 1; s <= steps_to_max + hold_steps; ++s) {
    ToolPose current = previous;
    const double depth = max_depth_m * std::min(s, steps_to_max) / steps_to_max;
    current.position_world_m.y() = 0.002 - depth;
    world.step_without_dynamics();
    collision->step(previous, current, kStep_s, world.soft(), result);
    press.depth_m.push_back(depth);
    press.force_n.push_back(result.force_on_tool_world_n.y());
    previous = current;
  }
  return press;
}

double fitted_exponent(const PressResult& press, double from_m) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int count = 0;
  for (std::size_t i = 0; i < press.depth_m.size(); ++i) {
    if (press.depth_m[i] < from_m) continue;
    const double x = std::log(press.depth_m[i]);
    const double y = std::log(press.force_n[i]);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
    ++count;
  }
  return (count * sxy - sx * sy) / (count * sxx - sx * sx);
}

TEST(PairedCollision, FlatSlabForceFollowsTheConfiguredExponent) {
  for (const double n : {1.0, 1.5, 2.0}) {
    HuntCrossleyParams hc;
    hc.k = 1.0e6;
    hc.lambda = 0.0;  // quasi-static: the elastic term alone
    hc.n = n;
    const PressResult press = press_slab(20, hc, 0.005, 100);
    const double fitted = fitted_exponent(press, 0.0005);
    std::printf("[paired] slab press n = %.2f: fitted exponent %.4f, F(5 mm) = %.4f N\n", n, fitted, press.force_n.back());
    EXPECT_NEAR(fitted, n, 0.02);
    for (const double f : press.force_n) EXPECT_GT(f, 0.0);
  }
}

// A node joining the contact brings its force in over contact_onset_ramp_s (hunt_crossley_force.cpp):
// pressed onto the slab in one step, every corner joins at once and the first step renders h/ramp of
// the force without the ramp, each step after it h/ramp more, and from the ramp/h-th step on the
// two are the same force.
TEST(PairedCollision, AJoiningNodesForceRampsInOverTheOnsetTime) {
  HuntCrossleyParams hc;
  hc.k = 1.0e6;
  hc.lambda = 0.0;
  const double ramp_s = 0.010;
  const int ramp_steps = static_cast<int>(std::lround(ramp_s / kStep_s));
  const PressResult at_once = press_slab(10, hc, 0.002, 1, 0.0, 2 * ramp_steps);
  const PressResult ramped = press_slab(10, hc, 0.002, 1, ramp_s, 2 * ramp_steps);
  ASSERT_GT(at_once.force_n.front(), 0.0) << "the plate presses the slab in its first step";
  EXPECT_NEAR(ramped.force_n.front() / at_once.force_n.front(), kStep_s / ramp_s, 1e-9);
  for (int s = 1; s < ramp_steps - 1; ++s) {
    EXPECT_LT(ramped.force_n[static_cast<std::size_t>(s)], at_once.force_n[static_cast<std::size_t>(s)]) << "step " << s;
    EXPECT_GT(ramped.force_n[static_cast<std::size_t>(s)], ramped.force_n[static_cast<std::size_t>(s - 1)]) << "step " << s;
  }
  for (std::size_t s = static_cast<std::size_t>(ramp_steps - 1); s < at_once.force_n.size(); ++s)
    EXPECT_NEAR(ramped.force_n[s], at_once.force_n[s], 1e-6 * at_once.force_n[s]) << "step " << s;
}

TEST(PairedCollision, AreaWeightingConvergesWhereThePapersSumScalesWithTheMesh) {
  HuntCrossleyParams hc;
  hc.k = 1.0e6;
  hc.lambda = 0.0;
  hc.n = 1.5;
  hc.per_unit_area = true;
  const double coarse_area = press_slab(20, hc, 0.003, 30).force_n.back();
  const double fine_area = press_slab(40, hc, 0.003, 30).force_n.back();
  hc.per_unit_area = false;
  const double coarse_sum = press_slab(20, hc, 0.003, 30).force_n.back();
  const double fine_sum = press_slab(40, hc, 0.003, 30).force_n.back();
  std::printf("[paired] slab F(3 mm): area-weighted %.4f → %.4f N, per-triangle sum %.2f → %.2f N (cells 20 → 40)\n",
              coarse_area, fine_area, coarse_sum, fine_sum);
  // normal_displacement (default) is a nodal quadrature: every colliding node carries its third
  // of each adjacent triangle. Here the plate's edges lie exactly on grid lines, so the ring of
  // triangles just outside the plate has two colliding vertices: a ring half a cell wide too
  // many (O(h); measured 0.892 at 20 → 40 cells; the paper's centroid measure tapered that ring
  // with the smaller x of its outer vertex). On the sphere (no aligned edges) the held plate
  // converges to 1.5 % (host_simulation_test HeldPlateForceConvergesUnderMeshRefinement).
  EXPECT_NEAR(fine_area / coarse_area, 1.0, 0.12);
  EXPECT_GT(fine_sum / coarse_sum, 3.0) << "4× the triangles under the plate";
}

TEST(PairedCollision, DampingAddsForceWhilePressingAndTheForceNeverGoesNegative) {
  HuntCrossleyParams hc;
  hc.k = 1.0e6;
  hc.lambda = 1.0e4;
  hc.n = 1.5;
  const PressResult with_damping = press_slab(20, hc, 0.003, 30);
  hc.lambda = 0.0;
  const PressResult elastic = press_slab(20, hc, 0.003, 30);
  EXPECT_GT(with_damping.force_n.back(), elastic.force_n.back());
}

TEST(PairedCollision, FixedSoftNodesAreNeverMoved) {
  test_scene::SoftWorld world(false);
  world.add_slab(0.1, 20);
  const int centre = 10 * 21 + 10;  // the node at the slab's centre, under the plate
  world.soft().setMass(centre, 0);  // Bullet: mass 0 = fixed (m_im = 0)
  const btVector3 fixed_position = world.soft().m_nodes[centre].m_x;
  const ToolNodes tool = test_scene::plate_tool(0.004);
  auto collision = make_paired_collision(tool, world.soft(), ThinBodyCollisionParams{});
  CollisionStepResult result;
  ToolPose previous;
  previous.position_world_m = Eigen::Vector3d(0, 0.0025, 0);
  for (int s = 1; s <= 10; ++s) {
    ToolPose current = previous;
    current.position_world_m.y() = 0.0025 - 0.0003 * s;  // bottom face ends 2.5 mm below the slab
    world.step_without_dynamics();
    collision->step(previous, current, kStep_s, world.soft(), result);
    previous = current;
  }
  EXPECT_EQ(world.soft().m_nodes[centre].m_x, fixed_position);
  EXPECT_LT(world.soft().m_nodes[centre + 1].m_x.y(), -0.0024) << "its free neighbour went down with the plate";
  EXPECT_GT(result.displaced_soft_nodes, 0);
}

TEST(PairedCollision, RejectsAnotherSoftBodyAndBadParameters) {
  test_scene::SoftWorld world(true);
  world.add_sphere();
  test_scene::SoftWorld other(true);
  other.add_sphere();
  const ToolNodes tool = test_scene::plate_tool(0.004);
  auto collision = make_paired_collision(tool, world.soft(), ThinBodyCollisionParams{});
  CollisionStepResult result;
  EXPECT_THROW(collision->step(ToolPose{}, ToolPose{}, kStep_s, other.soft(), result), std::invalid_argument);
  EXPECT_THROW(collision->step(ToolPose{}, ToolPose{}, 0.0, world.soft(), result), std::invalid_argument);
  ThinBodyCollisionParams bad;
  bad.hunt_crossley.n = 0.0;
  EXPECT_THROW((void)make_paired_collision(tool, world.soft(), bad), std::invalid_argument);
  ThinBodyCollisionParams bad_onset;
  bad_onset.contact_onset_ramp_s = -1e-3;
  EXPECT_THROW((void)make_paired_collision(tool, world.soft(), bad_onset), std::invalid_argument);
  bad_onset.contact_onset_ramp_s = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)make_paired_collision(tool, world.soft(), bad_onset), std::invalid_argument);
}

}  // namespace
}  // namespace fissure::host

namespace fissure::host {
namespace {

// Hunt-Crossley's ẋ in the paper's scenes, whose tools only translate (and the clamp's jaws slide along
// the grip axis): each record's x is offset + n·(t − rest) along its triangle's plane, so its ẋ
// can never be faster than the part moves, |Δp|/dt + |Δgap|/(2·dt). A triangle whose force plane
// changes from one step to the next (its first colliding corner found now held on another plane,
// round a rim) would give ẋ = Δx/dt across the switch if its filter were not restarted
// (hunt_crossley_force.cpp): in clamp-sphere ~0.4 m/s of filtered ẋ on a jaw moving at cm/s.
TEST(PairedCollision, NoRecordIndentsFasterThanItsPartMoves) {
  for (const char* name : {"spatula-sphere", "convex-spatula-sphere", "clamp-sphere", "clamp-vessel"}) {
    const SceneDescription scene = load_scene(resolve_scene_path(name));
    HostSimulation sim(scene, SceneCollisionMethod::kPaired);
    sim.settle(0.2);
    const double dt = scene.simulation.time_step_s;
    const int steps = static_cast<int>(std::floor(trajectory_duration_s(scene) / dt + 1e-9));
    TrajectorySample previous = sample_trajectory(scene, 0.0);
    double worst_ratio = 0.0, worst_rate_m_s = 0.0, worst_bound_m_s = 0.0;
    int records = 0;
    for (int i = 1; i <= steps; ++i) {
      const TrajectorySample target = sample_trajectory(scene, i * dt);
      const HostStepResult& r = sim.step(to_tool_pose(target.pose), target.jaw_gap_m);
      const Eigen::Vector3d dp(target.pose.position_world_m[0] - previous.pose.position_world_m[0],
                               target.pose.position_world_m[1] - previous.pose.position_world_m[1],
                               target.pose.position_world_m[2] - previous.pose.position_world_m[2]);
      // The filter is a low-pass of the per-step rates, so the speed bound of the last few steps.
      const double bound_m_s = dp.norm() / dt + 0.5 * std::abs(target.jaw_gap_m - previous.jaw_gap_m) / dt;
      worst_bound_m_s = std::max(worst_bound_m_s, bound_m_s);
      for (int p = 0; p < r.part_count; ++p)
        for (const ContactRecord& c : r.part_results[static_cast<std::size_t>(p)].contacts) {
          ++records;
          worst_rate_m_s = std::max(worst_rate_m_s, std::abs(c.penetration_rate_m_s));
        }
      previous = target;
    }
    worst_ratio = worst_rate_m_s / std::max(worst_bound_m_s, 1e-12);
    std::printf("[hc rate] %-22s %6d records: max |xdot| %.4f m/s, fastest part %.4f m/s\n", name, records, worst_rate_m_s,
                worst_bound_m_s);
    EXPECT_GT(records, 0) << name;
    EXPECT_LE(worst_ratio, 1.0 + 1e-6) << name << ": a record indented faster than its part moved";
  }
}

}  // namespace
}  // namespace fissure::host
