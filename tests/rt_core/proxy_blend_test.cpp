#include "fissure/rt_core/proxy_blend.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

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
    EXPECT_LE((rendered - previous).norm(), max_step_n) << "tick " << ticks;
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
  EXPECT_LE((rendered - previous).norm(), max_step_n);
}

TEST(ProxyBlend, NoSwapMeansNoOffset) {
  BlendState state;
  EXPECT_EQ(blend(state, Eigen::Vector3d(1.0, 2.0, 3.0), 0.05), Eigen::Vector3d(1.0, 2.0, 3.0));
  EXPECT_FALSE(blending(state));
}

// A swap while the tool moves: the motion under the proxy in use changes the force by m per
// tick, and the walk may only take what m leaves of the bound. A walk taking the full bound on
// top of m would step by 0.05 + 0.03 = 0.08 N here.
TEST(ProxyBlend, TheWalkSharesTheBoundWithTheToolsMotion) {
  const double max_step_n = 0.05;
  const Eigen::Vector3d motion_per_tick_n(0.0, 0.03, 0.0);  // pressing in: the force grows
  BlendState state;
  Eigen::Vector3d old_force(0.0, 1.0, 0.0);
  Eigen::Vector3d new_force(0.0, 3.0, 0.0);  // the new proxy gives 2 N more here: offset −2 N
  Eigen::Vector3d previous = blend(state, old_force, max_step_n);  // the old proxy, rendered
  old_force += motion_per_tick_n;
  new_force += motion_per_tick_n;
  begin_swap(state, old_force, new_force);
  double max_step = 0.0;
  int ticks = 0;
  while (blending(state)) {
    const Eigen::Vector3d rendered = blend(state, new_force, max_step_n);
    max_step = std::max(max_step, (rendered - previous).norm());
    previous = rendered;
    new_force += motion_per_tick_n;
    ASSERT_LT(++ticks, 1000);
  }
  EXPECT_LE(max_step, max_step_n);
  EXPECT_GT(max_step, max_step_n - 1e-12);  // the walk was not starved: it took what was left
  // 2 N at the 0.02 N the motion leaves per tick: 100 ticks (±1 for the rounding of the sum).
  EXPECT_NEAR(ticks, 100, 1);
  EXPECT_EQ(previous, new_force - motion_per_tick_n);  // the new proxy's own force, no offset left
}

// Motion beyond the bound in the walk's direction: the walk waits (the step is the motion's
// own, not more) and resumes at the full rate once the tool stops.
TEST(ProxyBlend, FastMotionHoldsTheOffsetAndTheStepIsTheMotionsOwn) {
  const double max_step_n = 0.05;
  const Eigen::Vector3d motion_per_tick_n(0.0, 0.08, 0.0);
  BlendState state;
  Eigen::Vector3d new_force(0.0, 3.0, 0.0);
  Eigen::Vector3d previous = blend(state, Eigen::Vector3d(0.0, 1.0, 0.0), max_step_n);
  begin_swap(state, Eigen::Vector3d(0.0, 1.0, 0.0) + motion_per_tick_n, new_force + motion_per_tick_n);
  new_force += motion_per_tick_n;
  for (int k = 0; k < 10; ++k) {
    const Eigen::Vector3d rendered = blend(state, new_force, max_step_n);
    EXPECT_NEAR((rendered - previous).norm(), motion_per_tick_n.norm(), 1e-12) << "tick " << k;
    previous = rendered;
    new_force += motion_per_tick_n;
  }
  EXPECT_NEAR(state.offset_device_n.y(), -2.0, 1e-12);  // held, not walked
  new_force -= motion_per_tick_n;                         // the tool stops
  const Eigen::Vector3d rendered = blend(state, new_force, max_step_n);
  EXPECT_NEAR((rendered - previous).norm(), max_step_n, 1e-12);
  EXPECT_NEAR(state.offset_device_n.y(), -2.0 + max_step_n, 1e-12);
}

// Motion against the walk's direction: the walk cancels part of it and runs at the full rate.
TEST(ProxyBlend, MotionAgainstTheWalkLetsItRunAtTheFullRate) {
  const double max_step_n = 0.05;
  BlendState state;
  const Eigen::Vector3d previous = blend(state, Eigen::Vector3d(0.0, 3.0, 0.0), max_step_n);
  // The old proxy moved +0.03 N (3.03 N here); the new one gives 2 N less: offset +2 N,
  // walked along −y while the motion goes +y.
  begin_swap(state, Eigen::Vector3d(0.0, 3.03, 0.0), Eigen::Vector3d(0.0, 1.03, 0.0));
  const Eigen::Vector3d rendered = blend(state, Eigen::Vector3d(0.0, 1.03, 0.0), max_step_n);
  EXPECT_NEAR(state.offset_device_n.y(), 2.0 - max_step_n, 1e-12);
  EXPECT_NEAR((rendered - previous).y(), 0.03 - max_step_n, 1e-12);
}

// A non-finite force for one tick (safety faults on it) leaves the offset walking as before.
TEST(ProxyBlend, ANonFiniteForceDoesNotPoisonTheOffset) {
  const double max_step_n = 0.05;
  BlendState state;
  (void)blend(state, Eigen::Vector3d(0.0, 1.0, 0.0), max_step_n);
  begin_swap(state, Eigen::Vector3d(0.0, 1.0, 0.0), Eigen::Vector3d(0.0, 3.0, 0.0));
  (void)blend(state, Eigen::Vector3d(0.0, std::numeric_limits<double>::quiet_NaN(), 0.0), max_step_n);
  ASSERT_TRUE(state.offset_device_n.allFinite());
  const Eigen::Vector3d rendered = blend(state, Eigen::Vector3d(0.0, 3.0, 0.0), max_step_n);
  EXPECT_NEAR(state.offset_device_n.y(), -2.0 + 2.0 * max_step_n, 1e-12);
  EXPECT_NEAR(rendered.y(), 1.0 + 2.0 * max_step_n, 1e-12);
}

// blend_walk_n over random motion steps and offset directions: the step it allows stays
// within max(bound, |m|), and it is the largest such walk (or the cap).
TEST(ProxyBlend, TheWalkIsTheLargestThatKeepsTheStepWithinItsLimit) {
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_real_distribution<double> scale(0.0, 0.12);
  const double max_step_n = 0.05;
  for (int i = 0; i < 10000; ++i) {
    const Eigen::Vector3d m = Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized() * scale(rng);
    const Eigen::Vector3d u = Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized();
    const double offset_norm = 3.0 * scale(rng);
    const double s = blend_walk_n(m, u, offset_norm, max_step_n);
    const double limit = std::max(max_step_n, m.norm());
    const double cap = std::min(offset_norm, max_step_n);
    ASSERT_GE(s, 0.0);
    ASSERT_LE(s, cap + 1e-15);
    ASSERT_LE((m - s * u).norm(), limit + 1e-12) << "case " << i;
    if (s < cap - 1e-9) {
      ASSERT_GT((m - (s + 1e-6) * u).norm(), limit) << "case " << i << ": could walk further";
    }
  }
}

}  // namespace
}  // namespace fissure::rt
