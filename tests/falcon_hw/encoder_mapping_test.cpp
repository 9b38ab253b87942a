// Tests for falcon_hw/src/encoder_mapping.cpp, including the position error encoder
// quantisation causes over the workspace.
#include "fissure/falcon_hw/encoder_mapping.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "fissure/falcon_hw/kinematics.hpp"
#include "workspace_sampling.hpp"

namespace fissure::falcon {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

TEST(EncoderMapping, DefaultsMatchTheFalconDrive) {
  const EncoderMapping mapping;
  // BRIEF §6: ≈ 0.036435° per count, 35° at count 0.
  EXPECT_NEAR(mapping.radians_per_count / kDegree, 0.036435, 5e-7);
  EXPECT_DOUBLE_EQ(mapping.theta_rad(0), 35.0 * kDegree);
  EXPECT_NEAR(mapping.theta_rad(1000) - mapping.theta_rad(0), 36.435 * kDegree, 5e-4 * kDegree);
  EXPECT_LT(mapping.theta_rad(-1), mapping.theta_rad(0));
}

TEST(EncoderMapping, CountInvertsThetaForEveryCount) {
  const EncoderMapping mapping;
  for (int c = std::numeric_limits<std::int16_t>::lowest(); c <= std::numeric_limits<std::int16_t>::max(); ++c) {
    const auto count = static_cast<std::int16_t>(c);
    ASSERT_EQ(mapping.count(mapping.theta_rad(count)), count);
    // Anything within just under half a count rounds back to the same count.
    ASSERT_EQ(mapping.count(mapping.theta_rad(count) + 0.49 * mapping.radians_per_count), count);
    ASSERT_EQ(mapping.count(mapping.theta_rad(count) - 0.49 * mapping.radians_per_count), count);
  }
}

TEST(EncoderMapping, CountSaturatesAndMapsNanToZero) {
  const EncoderMapping mapping;
  EXPECT_EQ(mapping.count(std::numeric_limits<double>::quiet_NaN()), 0);
  EXPECT_EQ(mapping.count(1e6), std::numeric_limits<std::int16_t>::max());
  EXPECT_EQ(mapping.count(-1e6), std::numeric_limits<std::int16_t>::lowest());
  EXPECT_EQ(mapping.count(std::numeric_limits<double>::infinity()), std::numeric_limits<std::int16_t>::max());
  EXPECT_EQ(mapping.count(-std::numeric_limits<double>::infinity()), std::numeric_limits<std::int16_t>::lowest());
  EXPECT_EQ(mapping.count(std::numeric_limits<double>::max()), std::numeric_limits<std::int16_t>::max());
  // Just past the ends: saturate, never wrap to the other sign.
  EXPECT_EQ(mapping.count(mapping.theta_rad(32767) + 3.0 * mapping.radians_per_count), 32767);
  EXPECT_EQ(mapping.count(mapping.theta_rad(-32768) - 3.0 * mapping.radians_per_count), -32768);
  const EncoderMapping degenerate{0.0, 0.0};  // zero gain: ±inf or NaN quotient, still no UB
  EXPECT_EQ(degenerate.count(1.0), std::numeric_limits<std::int16_t>::max());
  EXPECT_EQ(degenerate.count(0.0), 0);
}

TEST(EncoderMapping, VectorFormsApplyPerArm) {
  const EncoderMapping mapping;
  const std::array<std::int16_t, 3> counts{-200, 0, 1234};
  const Eigen::Vector3d theta = encoders_to_theta(mapping, counts);
  EXPECT_DOUBLE_EQ(theta[0], mapping.theta_rad(-200));
  EXPECT_DOUBLE_EQ(theta[2], mapping.theta_rad(1234));
  EXPECT_EQ(theta_to_encoders(mapping, theta), counts);
}

TEST(EncoderMapping, QuantisationPositionErrorOverTheWorkspaceIsBounded) {
  // The position error of reading a pose through the encoders: p → θ → counts → θq → FK.
  // Bounded per point by ‖∂p/∂θ‖∞ · ½ count; report the worst case and the centre figure.
  const FalconGeometry geometry;
  const EncoderMapping mapping;
  double worst_error_m = 0.0;
  double worst_bound_m = 0.0;
  for (const Eigen::Vector3d& p : testing::sample_workspace(10000, 31)) {
    Eigen::Vector3d theta;
    ASSERT_TRUE(inverse_kinematics(geometry, p, theta));
    const Eigen::Vector3d theta_quantised = encoders_to_theta(mapping, theta_to_encoders(mapping, theta));
    EXPECT_LE((theta_quantised - theta).cwiseAbs().maxCoeff(), 0.5 * mapping.radians_per_count * (1.0 + 1e-9));
    Eigen::Vector3d p_read = p;
    ASSERT_TRUE(forward_kinematics(geometry, theta_quantised, p_read, FkOptions{}).converged);
    Eigen::Matrix3d dp_dtheta;
    ASSERT_TRUE(jacobian(geometry, p, dp_dtheta));
    // ‖J δθ‖₂ ≤ ‖J‖₂ ‖δθ‖₂ ≤ ‖J‖_F · √3 · ½ count (plus a curvature allowance of 1 %).
    const double bound_m = dp_dtheta.norm() * std::sqrt(3.0) * 0.5 * mapping.radians_per_count * 1.01;
    const double error_m = (p_read - p).norm();
    EXPECT_LE(error_m, bound_m);
    worst_error_m = std::max(worst_error_m, error_m);
    worst_bound_m = std::max(worst_bound_m, bound_m);
  }
  Eigen::Matrix3d dp_dtheta_centre;
  ASSERT_TRUE(jacobian(geometry, testing::workspace_centre(), dp_dtheta_centre));
  const double per_count_centre_m = (dp_dtheta_centre * Eigen::Vector3d::Constant(mapping.radians_per_count)).norm();
    std::printf("encoder quantisation: worst position error %.2f um over the workspace (bound %.2f um); "
              "one count on all arms at the centre moves %.2f um\n",
              worst_error_m * 1e6, worst_bound_m * 1e6, per_count_centre_m * 1e6);
  // BRIEF §6: ≈ 0.05 mm per count at the centre; the half-count error stays below 0.1 mm.
  EXPECT_GT(per_count_centre_m, 0.02e-3);
  EXPECT_LT(per_count_centre_m, 0.1e-3);
  EXPECT_LT(worst_error_m, 0.1e-3);
}

}  // namespace
}  // namespace fissure::falcon
