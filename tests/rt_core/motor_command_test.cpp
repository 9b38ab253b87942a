#include "fissure/rt_core/motor_command.hpp"

#include <gtest/gtest.h>

#include <limits>

#include <Eigen/LU>

#include "fissure/falcon_hw/kinematics.hpp"
#include "fissure/falcon_hw/motor_command.hpp"
#include "fissure/rt_core/faults.hpp"

namespace fissure::rt {
namespace {

const Eigen::Vector3d kCentre(0.0, 0.0, 0.125);

TEST(MotorCommand, TorquesDoTheVirtualWorkOfTheForce) {
  const falcon::FalconGeometry geometry;
  falcon::DeviceCommand command;
  std::uint32_t flags = 0;
  const Eigen::Vector3d force(0.5, -1.0, 2.0);
  ASSERT_TRUE(force_to_command(geometry, falcon::kDefaultNewtonMetrePerCount, kCentre, force, command, flags));
  EXPECT_EQ(flags, 0u);
  // Back through the inverse mapping: τ from the counts, F = J⁻ᵀ τ ≈ the requested force
  // (within the rounding of one count per motor).
  const Eigen::Vector3d tau = falcon::motor_counts_to_torque(command.motor_counts, falcon::kDefaultNewtonMetrePerCount);
  Eigen::Matrix3d dp_dtheta;
  ASSERT_TRUE(falcon::jacobian(geometry, kCentre, dp_dtheta));
  const Eigen::Matrix3d jt = dp_dtheta.transpose();
  const Eigen::Vector3d recovered = jt.inverse() * tau;
  EXPECT_LT((recovered - force).norm(), 0.02);
}

TEST(MotorCommand, ZeroForceIsAZeroCommandEvenOffTheWorkspace) {
  falcon::DeviceCommand command;
  command.motor_counts = {1, 2, 3};
  std::uint32_t flags = 0;
  EXPECT_TRUE(force_to_command(falcon::FalconGeometry{}, 1e-4, Eigen::Vector3d(5.0, 5.0, 5.0), Eigen::Vector3d::Zero(),
                               command, flags));
  EXPECT_EQ(command.motor_counts, (std::array<std::int16_t, 3>{0, 0, 0}));
}

TEST(MotorCommand, UnreachablePositionOrNaNGivesZeroAndAFault) {
  falcon::DeviceCommand command;
  std::uint32_t flags = 0;
  EXPECT_FALSE(force_to_command(falcon::FalconGeometry{}, 1e-4, Eigen::Vector3d(5.0, 5.0, 5.0),
                                Eigen::Vector3d(1.0, 0.0, 0.0), command, flags));
  EXPECT_NE(flags & kFaultNonFinite, 0u);
  EXPECT_EQ(command.motor_counts, (std::array<std::int16_t, 3>{0, 0, 0}));
  flags = 0;
  EXPECT_FALSE(force_to_command(falcon::FalconGeometry{}, 1e-4, kCentre,
                                Eigen::Vector3d(std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0), command, flags));
  EXPECT_NE(flags & kFaultNonFinite, 0u);
}

}  // namespace
}  // namespace fissure::rt
