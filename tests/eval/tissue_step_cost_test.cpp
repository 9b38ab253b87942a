// eval/src/tissue_step_cost.cpp: the timed run itself (not its time, which is the bench's): a
// small tissue block on the ground steps stably at a symplectic substep below h_min / c_p and
// stays finite; and the host step is split into the requested substeps.
#include <gtest/gtest.h>

#include "fissure/eval/tissue_validation.hpp"

namespace fissure::eval {
namespace {

TEST(TissueStepCost, SmallBlockStepsFiniteAndSettling) {
  StepCostOptions o;
  o.cells_per_edge = 4;  // 10 mm cells of a 40 mm block: c_p · h_min ≈ 2.3 ms, 4 substeps of 0.25 ms
  o.substeps = 4;
  o.warmup_steps = 50;
  o.timed_steps = 50;
  o.material.mass_damping_per_s = 20.0;
  const StepCostResult r = time_fem_steps(o);
  EXPECT_EQ(r.nodes_count, 125);
  EXPECT_EQ(r.tetrahedra_count, 384);
  EXPECT_TRUE(r.finite);
  EXPECT_GT(r.median_ms, 0.0);
  EXPECT_LT(r.max_speed_m_per_s, 1.0);  // resting on the ground, not blown up
}

}  // namespace
}  // namespace fissure::eval
