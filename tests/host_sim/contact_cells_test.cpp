// Issue 22's motion cells end to end (host_sim/contact_cells.hpp, shared with `fissure bench
// collision`): the blade levering in the ball, and the clamp that must let go once open.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "fissure/host_sim/contact_cells.hpp"
#include "fissure/host_sim/scene_loader.hpp"

namespace fissure::host {
namespace {

// Targets (issue 22).
constexpr double kMaxPenetrationM = 1.0e-4;
constexpr double kMaxHoldJitter = 0.01;
constexpr double kHoldS = 0.5;
// An opened jaw carries nothing: below this the force is float noise of an empty contact set.
constexpr double kOpenForceMaxN = 0.01;

// The mandatory invariants of the levering cell on the paper's 128-face ball: no crossed node,
// penetration ≤ 0.1 mm, a finite force, and the turned blade still presses the ball.
TEST(LeverCell, PairedCrossesNoNodeAndKeepsContactThroughTheTurn) {
  const LeverResult r = run_lever_hold(plunge_scene(plunge_tools()[2]), SceneCollisionMethod::kPaired, kHoldS);
  std::printf("[lever] 128 faces, paired: crossed %d, inside %d, penetration %.4f mm, cut max %d on %d of %d steps, F_hold %.3f N, "
              "jitter %.3f %%, step noise %.3f %%\n",
              r.crossed_nodes, r.inside_nodes, r.max_penetration_m * 1e3, r.max_cut_triangles, r.steps_with_cut_triangles, r.steps, r.hold.mean_n,
              100.0 * r.hold.jitter, 100.0 * r.hold.step_noise);
  EXPECT_EQ(r.crossed_nodes, 0);
  EXPECT_LE(r.max_penetration_m, kMaxPenetrationM);
  EXPECT_TRUE(std::isfinite(r.hold.mean_n));
  EXPECT_GT(r.hold.mean_n, 0.0) << "the turned blade lost the ball";
}

// Bullet's soft-rigid collision, the baseline: it keeps the nodes out of the blade but not its
// triangles — the blade passes through the coarse shell between the nodes (the cell is a real
// test of the method, not of the scene).
TEST(LeverCell, BulletLetsTheBladeThroughTheTriangles) {
  const LeverResult r = run_lever_hold(plunge_scene(plunge_tools()[2]), SceneCollisionMethod::kBullet, kHoldS);
  std::printf("[lever] 128 faces, bullet: crossed %d, penetration %.4f mm, cut max %d on %d of %d steps\n", r.crossed_nodes,
              r.max_penetration_m * 1e3, r.max_cut_triangles, r.steps_with_cut_triangles, r.steps);
  EXPECT_GT(r.max_cut_triangles, 0);
  EXPECT_GT(r.steps_with_cut_triangles, r.steps / 2);
}

// The levering targets (issue 22): no triangle cut deeper than 0.1 mm on any step, hold jitter
// ≤ 1 %. NOT MET on main (disabled so that they stay visible; the figures are in the bench and
// the note).
TEST(LeverCell, DISABLED_NoCutTriangleAndAQuietHold) {
  const LeverResult r = run_lever_hold(plunge_scene(plunge_tools()[2]), SceneCollisionMethod::kPaired, kHoldS);
  EXPECT_EQ(r.max_cut_triangles, 0);
  EXPECT_LE(r.hold.jitter, kMaxHoldJitter);
}

// The clamp squeezes the ball and opens along clamp-sphere's script: once the jaws are fully open
// (gap 0.12 m > the ball's 0.10 m) nothing may hold on to them, after every settling time of issue
// 22's clamp cell, with the after_step response too (frictionless jaws: it has no friction), the
// ball on its bed (host::clamp_cell_scene). On a free ball (clamp-sphere as shipped) this response does not let go after 0.1,
// 0.2 and 0.5 s (9.98 / 9.59 / 11.59 N open, docs/decisions.md): the squeezed ball bulges under jaw
// A's tip, a soft node goes round the tip onto the jaw's outer face and is carried outwards as the
// jaw opens. The bed holds the ball's bottom, so it neither bulges under the tip nor rolls.
TEST(ClampReleaseCell, OpeningReleasesTheBeddedBallAfterAnySettlingTime) {
  const SceneDescription scene = clamp_cell_scene(ContactResponse::kAfterStep, false);
  for (const double settle_s : {0.1, 0.2, 0.3, 0.5}) {
    const ClampReleaseResult c = run_clamp_release(scene, SceneCollisionMethod::kPaired, settle_s);
    std::printf("[clamp] after_step, settled %.2f s: max %.3f N per jaw over the script, after opening %.4f N\n", settle_s, c.script_max_force_n,
                c.open_force_max_n);
    EXPECT_GT(c.script_max_force_n, 0.5) << "settled " << settle_s << " s: the clamp must grab the ball";
    EXPECT_GT(c.open_steps, kClampOpenGraceSteps) << "settled " << settle_s << " s: the script must open the clamp fully";
    EXPECT_LT(c.open_force_max_n, kOpenForceMaxN) << "settled " << settle_s << " s";
    EXPECT_EQ(c.crossed_nodes, 0) << "settled " << settle_s << " s";
  }
}

// In-solver response (issue 22, contact_response = "in_solver"): the levering blade (the in-solver
// cells' scene, host::in_solver_plunge_scene) on the paper's 128-face ball and on a 1280-face one
// keeps the paired guarantees, cuts no soft triangle on any step and holds the turned blade with
// ≤ 1 % jitter; the opened clamp (the clamp cell's bedded ball, with and without jaw friction) lets go
// after every settling time, cutting none either.

TEST(LeverCell, InSolverCrossesNoNodeCutsNoTriangleAndKeepsContactThroughTheTurn) {
  for (const int faces : {128, 1280}) {
    const SceneDescription scene = in_solver_plunge_scene(plunge_scene(plunge_tools()[2], faces == 128 ? 0 : faces));
    const LeverResult r = run_lever_hold(scene, SceneCollisionMethod::kPaired, kHoldS);
    std::printf("[lever] %d faces, paired in_solver: crossed %d, inside %d, penetration %.4f mm, cut max %d on %d of %d steps, "
                "F_hold %.3f N, jitter %.3f %%, step noise %.3f %%\n",
                faces, r.crossed_nodes, r.inside_nodes, r.max_penetration_m * 1e3, r.max_cut_triangles, r.steps_with_cut_triangles, r.steps,
                r.hold.mean_n, 100.0 * r.hold.jitter, 100.0 * r.hold.step_noise);
    EXPECT_EQ(r.crossed_nodes, 0) << faces;
    EXPECT_LE(r.max_penetration_m, kMaxPenetrationM) << faces;
    EXPECT_TRUE(std::isfinite(r.hold.mean_n)) << faces;
    EXPECT_GT(r.hold.mean_n, 0.0) << faces << " faces: the turned blade lost the ball";
    EXPECT_EQ(r.max_cut_triangles, 0) << faces << " faces";
    // The rim's push stays a position correction (rim_projection.cpp, inelastic_rim_velocities):
    // the blade draped in the coarse shell holds still instead of cycling on and off its edge.
    EXPECT_LE(r.hold.jitter, kMaxHoldJitter) << faces << " faces";
  }
}

TEST(ClampReleaseCell, InSolverOpeningReleasesTheBallAfterAnySettlingTime) {
  for (const bool friction : {true, false}) {
    const SceneDescription scene = clamp_cell_scene(ContactResponse::kInSolver, friction);
    for (const double settle_s : {0.1, 0.2, 0.3, 0.5}) {
      const ClampReleaseResult c = run_clamp_release(scene, SceneCollisionMethod::kPaired, settle_s);
      std::printf("[clamp] in_solver, jaw friction %s, settled %.2f s: max %.3f N per jaw over the script, after opening %.4f N, cut max %d\n",
                  friction ? "0.5 / 0.4" : "off", settle_s, c.script_max_force_n, c.open_force_max_n, c.max_cut_triangles);
      const std::string cell = std::string(friction ? "with" : "without") + " friction, settled " + std::to_string(settle_s) + " s";
      EXPECT_GT(c.script_max_force_n, 0.5) << cell << ": the clamp must grab the ball";
      EXPECT_GT(c.open_steps, kClampOpenGraceSteps) << cell;
      EXPECT_LT(c.open_force_max_n, kOpenForceMaxN) << cell;
      EXPECT_EQ(c.crossed_nodes, 0) << cell;
      EXPECT_EQ(c.max_cut_triangles, 0) << cell;
    }
  }
}

}  // namespace
}  // namespace fissure::host
