#include "fissure/rt_core/proxy_blend.hpp"

#include <gtest/gtest.h>

namespace fissure::rt {
namespace {

TEST(ProxyBlend, ASwapChangesTheForceByAtMostTheBoundPerTick) {
  const double max_step_n = 0.05;
  BlendState state;
  const Eigen::Vector3d old_force(0.0, 3.0, 0.0);
  const Eigen::Vector3d new_force(1.0, 1.0, 0.0);
  Eigen::Vector3d previous = old_force;
  begin_swap(state, old_force, new_force);
  int ticks = 0;
  while (blending(state) || ticks == 0) {
    const Eigen::Vector3d rendered = blend(state, new_force, max_step_n);
    EXPECT_LE((rendered - previous).norm(), max_step_n + 1e-12) << "tick " << ticks;
    previous = rendered;
    ASSERT_LT(++ticks, 1000);
  }
  EXPECT_EQ(previous, new_force);
  // |Δ| = √5 ≈ 2.236 N at 0.05 N per tick: 45 ticks.
  EXPECT_EQ(ticks, 45);
}

TEST(ProxyBlend, ASwapDuringABlendStaysContinuous) {
  const double max_step_n = 0.05;
  BlendState state;
  begin_swap(state, Eigen::Vector3d(2.0, 0.0, 0.0), Eigen::Vector3d::Zero());
  Eigen::Vector3d previous(2.0, 0.0, 0.0);
  for (int k = 0; k < 10; ++k) previous = blend(state, Eigen::Vector3d::Zero(), max_step_n);
  // Second swap: the force the old proxy gives is 0 (+ offset); the new proxy gives 5 N.
  begin_swap(state, Eigen::Vector3d::Zero(), Eigen::Vector3d(5.0, 0.0, 0.0));
  const Eigen::Vector3d rendered = blend(state, Eigen::Vector3d(5.0, 0.0, 0.0), max_step_n);
  EXPECT_LE((rendered - previous).norm(), max_step_n + 1e-12);
}

TEST(ProxyBlend, NoSwapMeansNoOffset) {
  BlendState state;
  EXPECT_EQ(blend(state, Eigen::Vector3d(1.0, 2.0, 3.0), 0.05), Eigen::Vector3d(1.0, 2.0, 3.0));
  EXPECT_FALSE(blending(state));
}

}  // namespace
}  // namespace fissure::rt
