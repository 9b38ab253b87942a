// HandScriptPlayer: the target follows the waypoints at their speeds, holds, releases, and the
// buttons change at the scripted times. (Closed-loop behaviour — the grip actually reaching
// the waypoints through the spring-damper — is tested in sim_falcon_test.cpp.)
#include "fissure/falcon_hw/hand_script_player.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace fissure::falcon {
namespace {

// "Down at 0.5 m/s to 2 cm depth, hold 1 s, back up at 0.1 m/s, hold 0.5 s, release".
HandScript press_and_release_script() {
  HandScript script;
  script.start_position_device_m = {0.0, 0.0, 0.11};
  script.waypoints = {
      HandWaypoint{{0.0, -0.02, 0.11}, 0.5, 1.0},
      HandWaypoint{{0.0, 0.0, 0.11}, 0.1, 0.5},
  };
  script.button_events = {ButtonEvent{0.5, 0x1}, ButtonEvent{0.01, 0x4}, ButtonEvent{1.2, 0x0}};
  script.grip_stiffness_n_per_m = 300.0;
  script.grip_damping_n_s_per_m = 5.0;
  script.release_at_end = true;
  return script;
}

TEST(HandScriptPlayer, LegTimesFollowDistanceOverSpeedPlusHold) {
  const HandScriptPlayer player(press_and_release_script());
  ASSERT_EQ(player.leg_count(), 2u);
  EXPECT_NEAR(player.leg_arrival_s(0), 0.02 / 0.5, 1e-12);
  EXPECT_NEAR(player.leg_departure_s(0), 0.04 + 1.0, 1e-12);
  EXPECT_NEAR(player.leg_arrival_s(1), 1.04 + 0.02 / 0.1, 1e-12);
  EXPECT_NEAR(player.script_end_s(), 1.24 + 0.5, 1e-12);
}

TEST(HandScriptPlayer, TargetMovesInAStraightLineAtTheScriptedSpeed) {
  const HandScriptPlayer player(press_and_release_script());
  const HandTarget halfway = player.target_at(0.02);
  EXPECT_NEAR(halfway.position_device_m.y(), -0.01, 1e-12);
  EXPECT_NEAR(halfway.position_device_m.x(), 0.0, 1e-15);
  EXPECT_NEAR(halfway.position_device_m.z(), 0.11, 1e-15);
  EXPECT_NEAR(halfway.velocity_device_m_per_s.y(), -0.5, 1e-12);
  EXPECT_NEAR(halfway.velocity_device_m_per_s.norm(), 0.5, 1e-12);
  EXPECT_TRUE(halfway.holding_grip);

  const HandTarget rising = player.target_at(1.14);  // halfway up the second leg
  EXPECT_NEAR(rising.position_device_m.y(), -0.01, 1e-12);
  EXPECT_NEAR(rising.velocity_device_m_per_s.y(), 0.1, 1e-12);
}

TEST(HandScriptPlayer, HoldsAtTheWaypointWithZeroTargetVelocity) {
  const HandScriptPlayer player(press_and_release_script());
  for (const double t_s : {0.04, 0.3, 1.0, 1.039}) {
    const HandTarget hold = player.target_at(t_s);
    EXPECT_NEAR(hold.position_device_m.y(), -0.02, 1e-12) << "t = " << t_s;
    EXPECT_EQ(hold.velocity_device_m_per_s, Eigen::Vector3d::Zero()) << "t = " << t_s;
    EXPECT_TRUE(hold.holding_grip);
  }
}

TEST(HandScriptPlayer, BeforeTheSessionTheTargetIsTheStart) {
  const HandScriptPlayer player(press_and_release_script());
  EXPECT_EQ(player.target_at(-1.0).position_device_m, Eigen::Vector3d(0.0, 0.0, 0.11));
  EXPECT_EQ(player.target_at(0.0).position_device_m, Eigen::Vector3d(0.0, 0.0, 0.11));
}

TEST(HandScriptPlayer, ReleasesAfterTheLastHoldAndAppliesNoForce) {
  const HandScriptPlayer player(press_and_release_script());
  const Eigen::Vector3d far_away(0.03, 0.03, 0.08);
  EXPECT_TRUE(player.target_at(1.7399).holding_grip);
  EXPECT_GT(player.force_on_grip_device_n(1.7399, far_away, Eigen::Vector3d::Zero()).norm(), 1.0);
  EXPECT_FALSE(player.target_at(1.7401).holding_grip);
  EXPECT_EQ(player.force_on_grip_device_n(1.7401, far_away, Eigen::Vector3d::Zero()), Eigen::Vector3d::Zero());
  EXPECT_EQ(player.force_on_grip_device_n(100.0, far_away, Eigen::Vector3d(1.0, 0.0, 0.0)), Eigen::Vector3d::Zero());
}

TEST(HandScriptPlayer, WithoutReleaseKeepsHoldingTheLastWaypoint) {
  HandScript script = press_and_release_script();
  script.release_at_end = false;
  const HandScriptPlayer player(script);
  const HandTarget late = player.target_at(50.0);
  EXPECT_TRUE(late.holding_grip);
  EXPECT_EQ(late.position_device_m, Eigen::Vector3d(0.0, 0.0, 0.11));
}

TEST(HandScriptPlayer, ForceIsTheGripSpringDamperAgainstTheMovingTarget) {
  const HandScriptPlayer player(press_and_release_script());
  const double t_s = 0.02;  // target at y = −0.01 m moving at −0.5 m/s
  const Eigen::Vector3d p(0.001, -0.005, 0.11);
  const Eigen::Vector3d v(0.0, -0.2, 0.1);
  const Eigen::Vector3d expected =
      300.0 * (Eigen::Vector3d(0.0, -0.01, 0.11) - p) + 5.0 * (Eigen::Vector3d(0.0, -0.5, 0.0) - v);
  EXPECT_TRUE(player.force_on_grip_device_n(t_s, p, v).isApprox(expected, 1e-12));
}

TEST(HandScriptPlayer, ButtonsChangeAtTheScriptedTimesInTimeOrder) {
  const HandScriptPlayer player(press_and_release_script());
  EXPECT_EQ(player.buttons_at(0.0), 0u);
  EXPECT_EQ(player.buttons_at(0.0099), 0u);
  EXPECT_EQ(player.buttons_at(0.01), 0x4u);  // events were given out of order; sorted at load
  EXPECT_EQ(player.buttons_at(0.4999), 0x4u);
  EXPECT_EQ(player.buttons_at(0.5), 0x1u);
  EXPECT_EQ(player.buttons_at(1.2), 0x0u);
  EXPECT_EQ(player.buttons_at(99.0), 0x0u);
}

TEST(HandScriptPlayer, EmptyScriptHoldsTheStartUnlessReleased) {
  HandScript script;
  script.release_at_end = false;
  const HandScriptPlayer holding(script);
  EXPECT_TRUE(holding.target_at(3.0).holding_grip);
  EXPECT_EQ(holding.target_at(3.0).position_device_m, as_eigen(script.start_position_device_m));
  script.release_at_end = true;
  const HandScriptPlayer released(script);
  EXPECT_FALSE(released.target_at(0.0).holding_grip);
}

TEST(HandScriptPlayer, ZeroLengthLegIsJustAHold) {
  HandScript script;
  script.waypoints = {HandWaypoint{script.start_position_device_m, 0.2, 0.3}};
  const HandScriptPlayer player(script);
  EXPECT_DOUBLE_EQ(player.leg_arrival_s(0), 0.0);
  EXPECT_DOUBLE_EQ(player.script_end_s(), 0.3);
  EXPECT_EQ(player.target_at(0.1).velocity_device_m_per_s, Eigen::Vector3d::Zero());
}

void expect_rejected(const HandScript& script, const std::string& field) {
  try {
    const HandScriptPlayer player(script);
    FAIL() << "accepted a script with a bad " << field;
  } catch (const std::invalid_argument& error) {
    EXPECT_THAT(error.what(), ::testing::HasSubstr(field));
  }
}

TEST(HandScriptPlayer, RejectsBadScriptsNamingTheField) {
  HandScript script = press_and_release_script();
  script.waypoints[1].speed_m_per_s = 0.0;
  expect_rejected(script, "waypoints[1].speed_m_per_s");

  script = press_and_release_script();
  script.waypoints[0].hold_s = -1.0;
  expect_rejected(script, "waypoints[0].hold_s");

  script = press_and_release_script();
  script.waypoints[0].position_device_m[2] = std::nan("");
  expect_rejected(script, "waypoints[0].position_device_m[2]");

  script = press_and_release_script();
  script.grip_stiffness_n_per_m = -5.0;
  expect_rejected(script, "grip_stiffness_n_per_m");

  script = press_and_release_script();
  script.button_events[2].time_s = std::numeric_limits<double>::infinity();
  expect_rejected(script, "button_events[2].time_s");
}

}  // namespace
}  // namespace fissure::falcon
