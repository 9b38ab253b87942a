#include "fissure/rt_core/safety.hpp"

#include <gtest/gtest.h>

#include <limits>

#include "fissure/rt_core/faults.hpp"

namespace fissure::rt {
namespace {

constexpr double kPeriod_s = 1e-3;

SafetyConfig no_ramp_config() {
  SafetyConfig config;
  config.ramp_in_s = 0.0;
  return config;
}

SafetyInput at_centre(const SafetyConfig& config, const Eigen::Vector3d& force) {
  SafetyInput input;
  input.force_device_n = force;
  input.p_device_m = config.workspace_centre_device_m;
  return input;
}

// Runs ticks with the same input until the rate limiter has caught up; returns the output.
Eigen::Vector3d settle(const SafetyConfig& config, SafetyState& state, const SafetyInput& input, std::uint32_t& flags) {
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  for (int k = 0; k < 100; ++k) out = apply_safety(config, state, input, kPeriod_s, flags);
  return out;
}

TEST(Safety, ClampKeepsTheDirection) {
  const SafetyConfig config = no_ramp_config();
  SafetyState state;
  start_ramp_in(state, 0.0);
  std::uint32_t flags = 0;
  const Eigen::Vector3d huge(30.0, -40.0, 0.0);  // 50 N
  const Eigen::Vector3d out = settle(config, state, at_centre(config, huge), flags);
  EXPECT_NEAR(out.norm(), kFalconMaxForce_n, 1e-12);
  EXPECT_NEAR(out.normalized().dot(huge.normalized()), 1.0, 1e-15);
  EXPECT_NE(flags & kFlagForceClamped, 0u);
}

TEST(Safety, ForceRateIsLimited) {
  const SafetyConfig config = no_ramp_config();
  SafetyState state;
  start_ramp_in(state, 0.0);
  std::uint32_t flags = 0;
  const Eigen::Vector3d out = apply_safety(config, state, at_centre(config, Eigen::Vector3d(0, 6.0, 0)), kPeriod_s, flags);
  EXPECT_NEAR(out.y(), config.max_force_rate_n_per_s * kPeriod_s, 1e-12);  // 4 N in the first tick
  EXPECT_NE(flags & kFlagForceRateLimited, 0u);
  EXPECT_NEAR(apply_safety(config, state, at_centre(config, Eigen::Vector3d(0, 6.0, 0)), kPeriod_s, flags).y(), 6.0,
              1e-12);
}

TEST(Safety, NonFiniteForceOrADeviceFaultGivesZeroAtOnce) {
  const SafetyConfig config = no_ramp_config();
  SafetyState state;
  start_ramp_in(state, 0.0);
  std::uint32_t flags = 0;
  settle(config, state, at_centre(config, Eigen::Vector3d(0, 5.0, 0)), flags);
  SafetyInput input = at_centre(config, Eigen::Vector3d(0, std::numeric_limits<double>::quiet_NaN(), 0));
  flags = 0;
  EXPECT_EQ(apply_safety(config, state, input, kPeriod_s, flags), Eigen::Vector3d::Zero());
  EXPECT_NE(flags & kFaultNonFinite, 0u);
  // Zero at once although the rate limit would allow only 4 N per tick.
  input = at_centre(config, Eigen::Vector3d(0, 5.0, 0));
  input.device_fault = true;
  EXPECT_EQ(apply_safety(config, state, input, kPeriod_s, flags), Eigen::Vector3d::Zero());
  // After the fault the force ramps back in over fault_ramp_in_s, not as a step.
  input.device_fault = false;
  const Eigen::Vector3d first = apply_safety(config, state, input, kPeriod_s, flags);
  EXPECT_NEAR(first.y(), 5.0 * kPeriod_s / config.fault_ramp_in_s, 1e-12);
}

TEST(Safety, SoftWallPushesBackBeyondTheWorkspaceRadius) {
  const SafetyConfig config = no_ramp_config();
  SafetyState state;
  start_ramp_in(state, 0.0);
  std::uint32_t flags = 0;
  SafetyInput input;
  input.p_device_m = config.workspace_centre_device_m + Eigen::Vector3d(0.0, 0.0, config.workspace_radius_m + 0.002);
  const Eigen::Vector3d wall = workspace_soft_wall_n(config, input.p_device_m, flags);
  EXPECT_NEAR(wall.z(), -config.soft_wall_stiffness_n_per_m * 0.002, 1e-9);
  EXPECT_EQ(wall.x(), 0.0);
  EXPECT_NE(flags & kFlagSoftWall, 0u);
  // The tick adds it to the environment force before the passivity controller; apply_safety
  // itself passes it through like any other force (clamp, ramp, rate limit).
  input.force_device_n = wall;
  const Eigen::Vector3d out = settle(config, state, input, flags);
  EXPECT_NEAR(out.z(), wall.z(), 1e-9);
  flags = 0;
  EXPECT_EQ(workspace_soft_wall_n(config, config.workspace_centre_device_m, flags), Eigen::Vector3d::Zero());
  EXPECT_EQ(flags & kFlagSoftWall, 0u);
  input.force_device_n.setZero();
  input.p_device_m = config.workspace_centre_device_m + Eigen::Vector3d(0.0, 0.0, config.workspace_radius_m + 0.01);
  EXPECT_EQ(settle(config, state, input, flags), Eigen::Vector3d::Zero());  // the wall is the tick's, added before the controller
  EXPECT_EQ(flags & kFlagSoftWall, 0u);
}

TEST(Safety, RampsInAtStartAndOutAtStop) {
  SafetyConfig config;  // ramp in 0.5 s, out 0.2 s
  SafetyState state;
  start_ramp_in(state, config.ramp_in_s);
  std::uint32_t flags = 0;
  const SafetyInput input = at_centre(config, Eigen::Vector3d(0, 4.0, 0));
  double previous = 0.0;
  int ticks = 0;
  while (state.phase == RampPhase::kRampIn) {
    const double y = apply_safety(config, state, input, kPeriod_s, flags).y();
    EXPECT_GE(y, previous);
    EXPECT_LE(y - previous, 4.0 * kPeriod_s / config.ramp_in_s + 1e-12);
    previous = y;
    ++ticks;
  }
  EXPECT_NEAR(ticks, 500, 1);
  EXPECT_NEAR(previous, 4.0, 1e-9);

  SafetyInput stopping = input;
  stopping.stop_requested = true;
  ticks = 0;
  while (state.phase != RampPhase::kStopped) {
    const double y = apply_safety(config, state, stopping, kPeriod_s, flags).y();
    EXPECT_LE(y, previous);
    previous = y;
    ++ticks;
  }
  EXPECT_NEAR(ticks, 200, 1);
  EXPECT_EQ(previous, 0.0);
  // Stopped stays stopped, even when the stop request goes away.
  EXPECT_EQ(apply_safety(config, state, input, kPeriod_s, flags), Eigen::Vector3d::Zero());
}

}  // namespace
}  // namespace fissure::rt
