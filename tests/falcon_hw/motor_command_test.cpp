// Tests for falcon_hw/src/motor_command.cpp: τ = Jᵀ F, the direction-keeping clamp, no wrap.
#include "fissure/falcon_hw/motor_command.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "fissure/falcon_hw/kinematics.hpp"
#include "workspace_sampling.hpp"

namespace fissure::falcon {
namespace {

const FalconGeometry kGeometry{};

Eigen::Vector3d as_vector(const std::array<std::int16_t, 3>& counts) {
  return {static_cast<double>(counts[0]), static_cast<double>(counts[1]), static_cast<double>(counts[2])};
}

TEST(MotorCommand, VirtualWorkForceTimesDisplacementEqualsTorqueTimesAngle) {
  // F·δp = τ·δθ for a small motion δθ with δp = J δθ — checked against IK differences,
  // not against J itself, so a wrong J would fail it.
  std::mt19937_64 rng(41);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (const Eigen::Vector3d& p : testing::sample_workspace(2000, 42)) {
    Eigen::Matrix3d dp_dtheta;
    ASSERT_TRUE(jacobian(kGeometry, p, dp_dtheta));
    const Eigen::Vector3d force{unit(rng), unit(rng), unit(rng)};
    const Eigen::Vector3d torque = dp_dtheta.transpose() * force;
    const Eigen::Vector3d dp = 1e-7 * Eigen::Vector3d{unit(rng), unit(rng), unit(rng)};
    Eigen::Vector3d theta_plus;
    Eigen::Vector3d theta_minus;
    ASSERT_TRUE(inverse_kinematics(kGeometry, p + dp, theta_plus));
    ASSERT_TRUE(inverse_kinematics(kGeometry, p - dp, theta_minus));
    const Eigen::Vector3d dtheta = 0.5 * (theta_plus - theta_minus);
    const double work_cartesian = force.dot(dp);
    const double work_joint = torque.dot(dtheta);
    EXPECT_NEAR(work_joint, work_cartesian, 1e-6 * force.norm() * dp.norm());
    // And the command carries exactly that torque (before rounding) through the gain.
    const MotorCommandResult command = force_to_motor_counts(dp_dtheta, 1000.0 * force, kDefaultNewtonMetrePerCount);
    ASSERT_FALSE(command.non_finite);
    if (!command.saturated) {
      const Eigen::Vector3d produced = motor_counts_to_torque(command.counts, kDefaultNewtonMetrePerCount);
      EXPECT_LE((produced - 1000.0 * torque).cwiseAbs().maxCoeff(), 0.5 * kDefaultNewtonMetrePerCount + 1e-15);
    }
  }
}

TEST(MotorCommand, SignFollowsLibnifalcon) {
  // Positive count turns the arm toward smaller θ1 (libnifalcon sends −τ·10000).
  const Eigen::Matrix3d identity = Eigen::Matrix3d::Identity();
  const MotorCommandResult command = force_to_motor_counts(identity, {0.1, 0.0, -0.2}, 1e-4);
  EXPECT_EQ(command.counts, (std::array<std::int16_t, 3>{-1000, 0, 2000}));
  EXPECT_FALSE(command.saturated);
  const Eigen::Vector3d torque = motor_counts_to_torque(command.counts, 1e-4);
  EXPECT_NEAR(torque.x(), 0.1, 1e-12);
  EXPECT_NEAR(torque.z(), -0.2, 1e-12);
}

TEST(MotorCommand, ClampKeepsDirectionForHugeForces) {
  Eigen::Matrix3d dp_dtheta;
  ASSERT_TRUE(jacobian(kGeometry, testing::workspace_centre() + Eigen::Vector3d{0.01, -0.02, 0.015}, dp_dtheta));
  const Eigen::Vector3d direction = Eigen::Vector3d{0.3, -0.5, 0.8}.normalized();
  const Eigen::Vector3d torque_direction = kMotorCountSignPerTorque * dp_dtheta.transpose() * direction;
  for (const double magnitude_n : {50.0, 1e3, 1e6, 1e12, 1e200, std::numeric_limits<double>::max()}) {
    const MotorCommandResult command = force_to_motor_counts(dp_dtheta, magnitude_n * direction, 1e-4);
    ASSERT_FALSE(command.non_finite) << magnitude_n;
    EXPECT_TRUE(command.saturated) << magnitude_n;
    const Eigen::Vector3d counts = as_vector(command.counts);
    EXPECT_EQ(counts.cwiseAbs().maxCoeff(), kMaxMotorCount) << magnitude_n;
    // Same direction as the unclamped torque, to within one count of rounding per axis.
    const Eigen::Vector3d expected = torque_direction * (kMaxMotorCount / torque_direction.cwiseAbs().maxCoeff());
    EXPECT_LE((counts - expected).cwiseAbs().maxCoeff(), 0.5 + 1e-9) << magnitude_n;
    EXPECT_GT(counts.normalized().dot(torque_direction.normalized()), 1.0 - 1e-6);
  }
}

TEST(MotorCommand, NonFiniteInputGivesZeroAndAFlag) {
  constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const Eigen::Matrix3d good = Eigen::Matrix3d::Identity() * 0.08;
  Eigen::Matrix3d bad_j = good;
  bad_j(1, 2) = kNan;
  const struct {
    Eigen::Matrix3d j;
    Eigen::Vector3d f;
    double gain;
  } cases[] = {{good, {kNan, 0, 0}, 1e-4},  {good, {0, kInf, 0}, 1e-4},  {good, {0, 0, -kInf}, 1e-4},
               {bad_j, {1, 1, 1}, 1e-4},    {good, {1, 1, 1}, kNan},     {good, {1, 1, 1}, kInf},
               {good, {1, 1, 1}, 0.0},      {good, {1, 1, 1}, -1e-4},    {good * 1e300, {1, 1, 1}, 1e-300}};
  for (const auto& c : cases) {
    const MotorCommandResult command = force_to_motor_counts(c.j, c.f, c.gain);
    EXPECT_TRUE(command.non_finite);
    EXPECT_EQ(command.counts, (std::array<std::int16_t, 3>{0, 0, 0}));
  }
  EXPECT_EQ(motor_counts_to_torque({100, 200, 300}, kNan), Eigen::Vector3d::Zero());
  EXPECT_EQ(motor_counts_to_torque({100, 200, 300}, 0.0), Eigen::Vector3d::Zero());
}

TEST(MotorCommand, NoWrapAroundForAnyInput) {
  // Random matrices, forces and gains spanning 600 orders of magnitude, plus zero.
  std::mt19937_64 rng(43);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-300, 300);
  auto wild = [&] { return mantissa(rng) * std::pow(10.0, exponent(rng)); };
  for (int trial = 0; trial < 200000; ++trial) {
    Eigen::Matrix3d j;
    for (int k = 0; k < 9; ++k) j(k / 3, k % 3) = wild();
    const Eigen::Vector3d f{wild(), wild(), trial % 7 == 0 ? 0.0 : wild()};
    const double gain = std::abs(wild());
    const MotorCommandResult command = force_to_motor_counts(j, f, gain);
    for (const std::int16_t count : command.counts) {
      ASSERT_LE(count, kMaxMotorCount);
      ASSERT_GE(count, -kMaxMotorCount);
    }
    if (command.non_finite) {
      ASSERT_EQ(command.counts, (std::array<std::int16_t, 3>{0, 0, 0}));
      continue;
    }
    // Never a sign flip (the mark of a wrap): each count has τ's sign or is zero.
    const Eigen::Vector3d torque_unit = j.transpose() * (f / std::max(f.cwiseAbs().maxCoeff(), 1e-300));
    for (int i = 0; i < 3; ++i) {
      if (command.counts[i] != 0 && std::isfinite(torque_unit[i])) {
        ASSERT_EQ(command.counts[i] > 0, kMotorCountSignPerTorque * torque_unit[i] > 0) << trial;
      }
    }
  }
}

TEST(MotorCommand, ZeroForceIsZeroCommand) {
  const MotorCommandResult command = force_to_motor_counts(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), 1e-4);
  EXPECT_EQ(command.counts, (std::array<std::int16_t, 3>{0, 0, 0}));
  EXPECT_FALSE(command.saturated);
  EXPECT_FALSE(command.non_finite);
}

}  // namespace
}  // namespace fissure::falcon
