// eval/src/tissue_punch.cpp: the flat punch on the coarsest meshes a test can afford. Issue 24's
// bound (slope within 15 % of Sneddon) is checked by `fissure bench tissue` at its finest mesh;
// it is NOT met at 1 cell per radius (docs/decisions.md, "Tissue (issue 24)": on this ±8 a
// block the default smoothed-strain model is +20.2 % at 1 cell per radius and +2.5 % at 2;
// Bullet's one-strain element +69 % / +28 %), so this test holds what is true of them: the
// force is linear in the depth, every mesh is stiffer than Sneddon (the discrete footprint and the finite block both
// stiffen it), and refining moves the slope towards Sneddon.
#include <cmath>

#include <gtest/gtest.h>

#include "fissure/eval/tissue_validation.hpp"

namespace fissure::eval {
namespace {

TEST(TissuePunch, ForceLinearInDepthAndConvergingTowardsSneddonFromAbove) {
  FlatPunchOptions coarse;
  coarse.cells_per_radius = 1;
  coarse.block_half_width_radii = 8.0;  // half the bench's block: the run stays a few seconds
  FlatPunchOptions finer = coarse;
  finer.cells_per_radius = 2;
  const FlatPunchResult a = run_flat_punch(coarse), b = run_flat_punch(finer);
  for (const FlatPunchResult* r : {&a, &b}) {
    ASSERT_EQ(r->forces_n.size(), 2u);
    EXPECT_NEAR(r->forces_n[1], 2.0 * r->forces_n[0], 0.01 * r->forces_n[1]);  // depths 0.1, 0.2 mm
    EXPECT_GT(r->relative_error, 0.0);
    EXPECT_LT(r->max_speed_m_per_s, 1e-6);
  }
  EXPECT_LT(b.relative_error, a.relative_error);
  EXPECT_NEAR(a.expected_slope_n_per_m, 2.0 * 0.005 * 5000.0 / (1.0 - 0.45 * 0.45), 1e-9);
}

}  // namespace
}  // namespace fissure::eval
