#include "fissure/rt_core/joint_angles.hpp"

#include <gtest/gtest.h>

namespace fissure::rt {
namespace {

TEST(JointAngles, ConvertsCountsWithTheEncoderMapping) {
  const falcon::EncoderMapping mapping;
  JointState state;
  EXPECT_EQ(encoders_to_joint_angles(mapping, FaultConfig{}, state, {100, -200, 0}, 1e-3), JointCheck::kOk);
  EXPECT_DOUBLE_EQ(state.theta_rad[0], mapping.theta_rad(100));
  EXPECT_DOUBLE_EQ(state.theta_rad[1], mapping.theta_rad(-200));
  EXPECT_DOUBLE_EQ(state.theta_rad[2], mapping.theta_rad(0));
}

TEST(JointAngles, AJumpBeyondPhysicalSpeedIsDetectedOnceAndThenJudgedAfresh) {
  const falcon::EncoderMapping mapping;
  const FaultConfig faults;  // 100 rad/s ⇒ 0.1 rad = 157 counts per ms (+1 count)
  JointState state;
  encoders_to_joint_angles(mapping, faults, state, {0, 0, 0}, 1e-3);
  EXPECT_EQ(encoders_to_joint_angles(mapping, faults, state, {150, 0, 0}, 1e-3), JointCheck::kOk);
  EXPECT_EQ(encoders_to_joint_angles(mapping, faults, state, {150, 0, 500}, 1e-3), JointCheck::kJump);
  EXPECT_EQ(encoders_to_joint_angles(mapping, faults, state, {151, 0, 501}, 1e-3), JointCheck::kOk);
  // A longer gap (e.g. after dropped replies) allows proportionally more motion.
  EXPECT_EQ(encoders_to_joint_angles(mapping, faults, state, {151, 0, 1200}, 5e-3), JointCheck::kOk);
}

}  // namespace
}  // namespace fissure::rt
