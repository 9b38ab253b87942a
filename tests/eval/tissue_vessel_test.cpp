// eval/src/tissue_vessel.cpp: a vessel resting on the ground, on coarse meshes (`fissure bench
// tissue` runs the finer ones, where the default smoothed-strain model comes within Roark's
// bound). One cell through the 2 mm wall is far too coarse for its bending (docs/decisions.md,
// "Tissue (issue 24)": −79 % / −54 % of Roark's flattening at 16 / 32 cells around, Bullet's own
// element −85 % at 32), so this test holds what is true of these meshes: the section flattens
// and spreads, less than Roark's ring, more as the mesh is refined, and the anchor itself is
// Roark's.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "fissure/eval/tissue_validation.hpp"

namespace fissure::eval {
namespace {

TEST(TissueVessel, FlattensAndSpreadsBelowRoarksRingAndMoreWhenRefined) {
  VesselOptions coarse;
  coarse.cells_through = 1;
  coarse.cells_around = 16;
  coarse.cells_along = 6;
  VesselOptions finer = coarse;
  finer.cells_around = 32;
  const VesselResult a = run_vessel_on_ground(coarse), b = run_vessel_on_ground(finer);
  // w R⁴ / (E I): w = 1040 · 9.81 · 0.002 N/m², R = 14 mm, E I = 5e5 · 0.002³ / (12 (1 − 0.45²)).
  const double scale = 1040.0 * 9.81 * 0.002 * std::pow(0.014, 4) / (5.0e5 * 8e-9 / (12.0 * (1.0 - 0.45 * 0.45)));
  EXPECT_NEAR(a.expected_vertical_change_m, -0.4674 * scale, 1e-12);
  EXPECT_NEAR(a.expected_horizontal_change_m, 0.4292 * scale, 1e-12);
  for (const VesselResult* r : {&a, &b}) {
    EXPECT_LT(r->vertical_change_m, 0.0);    // flattened ...
    EXPECT_GT(r->horizontal_change_m, 0.0);  // ... and spread
    EXPECT_GT(r->vertical_change_m, r->expected_vertical_change_m);  // stiffer than the ring at this coarseness
    EXPECT_LT(r->horizontal_change_m, r->expected_horizontal_change_m);
    EXPECT_GT(r->ovalisation, 0.0);
    EXPECT_LT(r->max_speed_m_per_s, 1e-6);
  }
  EXPECT_LT(b.vertical_change_m, 1.2 * a.vertical_change_m);  // refining lets it flatten more
  EXPECT_THROW((void)run_vessel_on_ground([] {
                 VesselOptions o;
                 o.cells_around = 30;
                 return o;
               }()),
               std::invalid_argument);
}

}  // namespace
}  // namespace fissure::eval
