// Tests for falcon_hw/src/kinematics.cpp and forward_kinematics.cpp (IK, Jacobian, FK, workspace).
#include "fissure/falcon_hw/kinematics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <limits>
#include <numbers>
#include <random>

#include <Eigen/LU>

#include "fissure/falcon_hw/libnifalcon_reference.hpp"
#include "workspace_sampling.hpp"

namespace fissure::falcon {
namespace {

using testing::sample_workspace;
using testing::sample_workspace_surface;
using testing::workspace_centre;

const FalconGeometry kGeometry{};

std::string format_g(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", value);
  return text;
}

/// Rebuild p from all joint angles with the forward chain of each arm (the equations IK
/// inverts), rotating the arm frame back to the device frame. Independent of IK's algebra.
Eigen::Vector3d position_from_arm(const FalconGeometry& g, int i, const ArmAngles& arm) {
  const double link = g.d_m + g.e_m + g.b_m * std::sin(arm.theta3_rad);
  const double u = g.a_m * std::cos(arm.theta1_rad) - g.c_m + link * std::cos(arm.theta2_rad) + g.r_m;
  const double v = g.b_m * std::cos(arm.theta3_rad) - g.f_m + g.s_m;
  const double w = g.a_m * std::sin(arm.theta1_rad) + link * std::sin(arm.theta2_rad);
  const double c = std::cos(g.phi_rad[i]);
  const double s = std::sin(g.phi_rad[i]);
  return {c * u - s * v, s * u + c * v, w};
}

/// Row-wise relative error of an analytic ∂θ/∂p against central differences of IK.
double max_row_relative_error(const Eigen::Matrix3d& analytic, const Eigen::Vector3d& p) {
  constexpr double kStep_m = 1e-6;
  Eigen::Matrix3d numeric;
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d plus = p;
    Eigen::Vector3d minus = p;
    plus[k] += kStep_m;
    minus[k] -= kStep_m;
    Eigen::Vector3d theta_plus;
    Eigen::Vector3d theta_minus;
    EXPECT_TRUE(inverse_kinematics(kGeometry, plus, theta_plus));
    EXPECT_TRUE(inverse_kinematics(kGeometry, minus, theta_minus));
    numeric.col(k) = (theta_plus - theta_minus) / (2.0 * kStep_m);
  }
  double worst = 0.0;
  for (int i = 0; i < 3; ++i) {
    worst = std::max(worst, (analytic.row(i) - numeric.row(i)).norm() / numeric.row(i).norm());
  }
  return worst;
}

TEST(InverseKinematics, ArmChainsReproduceThePosition) {
  for (const Eigen::Vector3d& p : sample_workspace(2000, 11)) {
    std::array<ArmAngles, 3> arms;
    ASSERT_TRUE(arm_angles(kGeometry, p, arms));
    for (int i = 0; i < 3; ++i) {
      EXPECT_LT((position_from_arm(kGeometry, i, arms[i]) - p).norm(), 1e-12) << "arm " << i << " at " << p.transpose();
    }
  }
}

TEST(InverseKinematics, AxisPointsGiveEqualAnglesAndTheCentreMatchesTheEncoderRange) {
  Eigen::Vector3d theta;
  ASSERT_TRUE(inverse_kinematics(kGeometry, workspace_centre(), theta));
  EXPECT_NEAR(theta[0], theta[1], 1e-12);
  EXPECT_NEAR(theta[0], theta[2], 1e-12);
  // Pushing the grip toward the device (smaller z) lowers every arm.
  Eigen::Vector3d theta_in;
  ASSERT_TRUE(inverse_kinematics(kGeometry, workspace_centre() - Eigen::Vector3d{0, 0, 0.02}, theta_in));
  EXPECT_LT(theta_in[0], theta[0]);
  // Centre angle is within ±20° of the 35° homing offset, i.e. a few hundred counts.
  EXPECT_NEAR(theta[0], 35.0 * std::numbers::pi / 180.0, 20.0 * std::numbers::pi / 180.0);
}

TEST(InverseKinematics, OtherArmAnglesAreHonoured) {
  // The stock φ uses precomputed sines; an equivalent φ (+2π) takes the general path and
  // must agree, and a genuinely different φ must change the answer.
  FalconGeometry wrapped;
  for (double& phi : wrapped.phi_rad) phi += 2.0 * std::numbers::pi;
  FalconGeometry rotated;
  rotated.phi_rad[0] += 0.1;
  for (const Eigen::Vector3d& p : sample_workspace(200, 23)) {
    Eigen::Vector3d theta_stock;
    Eigen::Vector3d theta_wrapped;
    Eigen::Vector3d theta_rotated;
    ASSERT_TRUE(inverse_kinematics(kGeometry, p, theta_stock));
    ASSERT_TRUE(inverse_kinematics(wrapped, p, theta_wrapped));
    EXPECT_LT((theta_stock - theta_wrapped).cwiseAbs().maxCoeff(), 1e-12);
    if (inverse_kinematics(rotated, p, theta_rotated)) {
      EXPECT_GT(std::abs(theta_rotated[0] - theta_stock[0]), 1e-6);
      EXPECT_EQ(theta_rotated[1], theta_stock[1]);
    }
  }
}

TEST(Workspace, WholeBallIsReachableWithConditioningMargins) {
  auto points = sample_workspace(20000, 12);
  const auto surface = sample_workspace_surface(20000, 13, 1.0 - 1e-9);
  points.insert(points.end(), surface.begin(), surface.end());
  double min_sin3 = 1.0;
  double min_sin_knee = 1.0;
  double min_theta1 = 10.0;
  double max_theta1 = -10.0;
  for (const Eigen::Vector3d& p : points) {
    ASSERT_TRUE(in_workspace(kGeometry, p)) << p.transpose();
    std::array<ArmAngles, 3> arms;
    ASSERT_TRUE(arm_angles(kGeometry, p, arms));
    for (const ArmAngles& arm : arms) {
      min_sin3 = std::min(min_sin3, std::sin(arm.theta3_rad));
      min_sin_knee = std::min(min_sin_knee, std::sin(arm.theta2_rad - arm.theta1_rad));
      min_theta1 = std::min(min_theta1, arm.theta1_rad);
      max_theta1 = std::max(max_theta1, arm.theta1_rad);
    }
  }
  RecordProperty("min_sin_theta3", format_g(min_sin3));
  RecordProperty("min_sin_knee", format_g(min_sin_knee));
  RecordProperty("theta1_range_deg", format_g(min_theta1 * 180 / std::numbers::pi) + " .. " +
                                         format_g(max_theta1 * 180 / std::numbers::pi));
  EXPECT_GE(min_theta1, -35.0 * std::numbers::pi / 180.0);  // documented in kinematics.hpp
  EXPECT_LE(max_theta1, 82.0 * std::numbers::pi / 180.0);
  EXPECT_GE(min_sin3, 0.85);      // documented in kinematics.hpp
  EXPECT_GE(min_sin_knee, 0.45);  // documented in kinematics.hpp
}

TEST(Workspace, OutsideTheBallIsNotInTheWorkspace) {
  for (const Eigen::Vector3d& p : sample_workspace_surface(1000, 14, 1.001)) EXPECT_FALSE(in_workspace(kGeometry, p));
  constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(in_workspace(kGeometry, {kNan, 0.0, 0.125}));
  EXPECT_FALSE(in_workspace(kGeometry, {0.0, 0.0, std::numeric_limits<double>::infinity()}));
}

TEST(InverseKinematics, FailsWithoutNanOutsideTheReachableRegion) {
  constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const Eigen::Vector3d sentinel{7.0, 8.0, 9.0};
  for (const Eigen::Vector3d& p : {Eigen::Vector3d{0, 0, 0}, Eigen::Vector3d{0, 0, 0.3}, Eigen::Vector3d{0.2, 0, 0.1},
                                   Eigen::Vector3d{0, -0.2, 0.1}, Eigen::Vector3d{0, 0, -0.1},
                                   Eigen::Vector3d{kNan, 0, 0.1}, Eigen::Vector3d{0, kInf, 0.1},
                                   Eigen::Vector3d{0, 0, -kInf}, Eigen::Vector3d{1e300, 1e300, 1e300}}) {
    Eigen::Vector3d theta = sentinel;
    Eigen::Matrix3d jac = Eigen::Matrix3d::Constant(5.0);
    EXPECT_FALSE(inverse_kinematics(kGeometry, p, theta)) << p.transpose();
    EXPECT_EQ(theta, sentinel);
    EXPECT_FALSE(jacobian(kGeometry, p, jac)) << p.transpose();
    EXPECT_EQ(jac, Eigen::Matrix3d::Constant(5.0));
  }
  // A dense sweep of a box far larger than the device: success always means finite output.
  int reachable = 0;
  int unreachable = 0;
  for (double x = -0.15; x <= 0.15; x += 0.005) {
    for (double y = -0.15; y <= 0.15; y += 0.005) {
      for (double z = -0.05; z <= 0.30; z += 0.005) {
        Eigen::Vector3d theta = sentinel;
        if (inverse_kinematics(kGeometry, {x, y, z}, theta)) {
          ++reachable;
          ASSERT_TRUE(theta.allFinite());
          Eigen::Matrix3d jac;
          if (jacobian(kGeometry, {x, y, z}, jac)) {
            ASSERT_TRUE(jac.allFinite());
          }
        } else {
          ++unreachable;
          ASSERT_EQ(theta, sentinel);
        }
      }
    }
  }
  EXPECT_GT(reachable, 1000);
  EXPECT_GT(unreachable, 1000);
}

TEST(Jacobian, AnalyticDerivativeMatchesCentralDifferences) {
  double worst = 0.0;
  for (const Eigen::Vector3d& p : sample_workspace(5000, 15, 0.999)) {
    Eigen::Vector3d theta;
    Eigen::Matrix3d dtheta_dp;
    ASSERT_TRUE(inverse_kinematics_with_derivative(kGeometry, p, theta, dtheta_dp));
    worst = std::max(worst, max_row_relative_error(dtheta_dp, p));
  }
  RecordProperty("jacobian_max_rel_error", format_g(worst));
  EXPECT_LE(worst, 1e-6);
}

TEST(Jacobian, TheLibnifalconIssue66JacobianFailsTheSameCheck) {
  // The check above must be able to fail: libnifalcon's sin²θ2 z entry is caught by it.
  double best = std::numeric_limits<double>::infinity();
  double worst = 0.0;
  for (const Eigen::Vector3d& p : sample_workspace(500, 16, 0.999)) {
    std::array<ArmAngles, 3> arms;
    ASSERT_TRUE(arm_angles(kGeometry, p, arms));
    const double error = max_row_relative_error(libnifalcon_reference::dtheta_dp_issue66(kGeometry, arms), p);
    best = std::min(best, error);
    worst = std::max(worst, error);
  }
  RecordProperty("issue66_min_rel_error", format_g(best));
  EXPECT_GT(worst, 1e-2);
  EXPECT_GT(best, 1e-6);  // wrong everywhere in the workspace, not only somewhere
}

TEST(Jacobian, Issue66OverstatesZForceAtTheCentre) {
  // BRIEF §6: with the bug, z forces at the centre are ~34 % too large. The torque a z force
  // needs is Jᵀ F; compare the z force the buggy torque would actually produce.
  std::array<ArmAngles, 3> arms;
  ASSERT_TRUE(arm_angles(kGeometry, workspace_centre(), arms));
  Eigen::Matrix3d dp_dtheta_true;
  ASSERT_TRUE(jacobian(kGeometry, workspace_centre(), dp_dtheta_true));
  const Eigen::Matrix3d dp_dtheta_bug = libnifalcon_reference::dtheta_dp_issue66(kGeometry, arms).inverse();
  const Eigen::Vector3d force{0.0, 0.0, 1.0};
  const Eigen::Vector3d torque_bug = dp_dtheta_bug.transpose() * force;
  // Force actually produced: F = J⁻ᵀ τ with the true J.
  const Eigen::Vector3d produced = dp_dtheta_true.transpose().inverse() * torque_bug;
  RecordProperty("issue66_z_force_ratio", format_g(produced.z()));
  EXPECT_GT(produced.z(), 1.2);
  EXPECT_LT(produced.z(), 1.5);
  EXPECT_NEAR(produced.x(), 0.0, 1e-9);
  EXPECT_NEAR(produced.y(), 0.0, 1e-9);
}

TEST(Jacobian, IsTheInverseOfTheDerivative) {
  for (const Eigen::Vector3d& p : sample_workspace(1000, 17)) {
    Eigen::Vector3d theta;
    Eigen::Matrix3d dtheta_dp;
    Eigen::Matrix3d dp_dtheta;
    ASSERT_TRUE(inverse_kinematics_with_derivative(kGeometry, p, theta, dtheta_dp));
    ASSERT_TRUE(jacobian(kGeometry, p, dp_dtheta));
    EXPECT_LT((dp_dtheta * dtheta_dp - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-12);
  }
}

TEST(ForwardKinematics, ColdRoundTripOverTheWorkspaceIsBelowOneMicrometre) {
  double worst_m = 0.0;
  int worst_iterations = 0;
  for (const Eigen::Vector3d& p : sample_workspace(10000, 18)) {
    Eigen::Vector3d theta;
    ASSERT_TRUE(inverse_kinematics(kGeometry, p, theta));
    Eigen::Vector3d solved{-1.0, -1.0, -1.0};
    const FkResult result = forward_kinematics_cold(kGeometry, theta, solved, FkOptions{});
    ASSERT_TRUE(result.converged) << p.transpose() << " residual " << result.residual_rad;
    EXPECT_LT(result.residual_rad, kDefaultFkTolerance_rad);
    worst_m = std::max(worst_m, (solved - p).norm());
    worst_iterations = std::max(worst_iterations, result.iterations);
  }
  RecordProperty("fk_cold_roundtrip_max_error_m", format_g(worst_m));
  RecordProperty("fk_cold_max_iterations", worst_iterations);
  EXPECT_LE(worst_m, 1e-6);
  EXPECT_LE(worst_iterations, kDefaultFkMaxIterations);
}

TEST(ForwardKinematics, ColdStartConvergesOnTheWorkspaceSurface) {
  for (const Eigen::Vector3d& p : sample_workspace_surface(5000, 19, 1.0 - 1e-9)) {
    Eigen::Vector3d theta;
    ASSERT_TRUE(inverse_kinematics(kGeometry, p, theta));
    Eigen::Vector3d solved;
    const FkResult result = forward_kinematics_cold(kGeometry, theta, solved, FkOptions{});
    ASSERT_TRUE(result.converged) << p.transpose();
    EXPECT_LE((solved - p).norm(), 1e-6);
  }
}

TEST(ForwardKinematics, WarmStartFromAnyWorkspacePointConverges) {
  // The warm start may be anywhere (e.g. after a fault): start → target both random.
  const auto starts = sample_workspace(3000, 20);
  const auto targets = sample_workspace(3000, 21);
  for (std::size_t k = 0; k < starts.size(); ++k) {
    Eigen::Vector3d theta;
    ASSERT_TRUE(inverse_kinematics(kGeometry, targets[k], theta));
    Eigen::Vector3d p = starts[k];
    const FkResult result = forward_kinematics(kGeometry, theta, p, FkOptions{});
    ASSERT_TRUE(result.converged);
    EXPECT_LE((p - targets[k]).norm(), 1e-6);
  }
}

TEST(ForwardKinematics, WarmStartAlongATrajectoryTakesFewIterations) {
  // A 1 kHz trajectory at 0.5 m/s: 0.5 mm between samples, warm-started from the previous
  // sample's solution (never from the answer).
  Eigen::Vector3d p_solved = workspace_centre();
  int worst_iterations = 0;
  constexpr int kTicks = 4000;
  for (int tick = 0; tick < kTicks; ++tick) {
    const double t = tick * 1e-3;
    // Circle of radius 4 cm at 12.5 rad/s → 0.5 m/s, tilted through all three axes.
    const double angle = 12.5 * t;
    const Eigen::Vector3d p = workspace_centre() +
                              0.04 * Eigen::Vector3d{std::cos(angle), 0.6 * std::sin(angle), 0.8 * std::sin(angle)};
    Eigen::Vector3d theta;
    ASSERT_TRUE(inverse_kinematics(kGeometry, p, theta));
    const FkResult result = forward_kinematics(kGeometry, theta, p_solved, FkOptions{});
    ASSERT_TRUE(result.converged);
    EXPECT_LE((p_solved - p).norm(), 1e-6);
    if (tick > 0) worst_iterations = std::max(worst_iterations, result.iterations);
  }
  RecordProperty("fk_warm_max_iterations", worst_iterations);
  EXPECT_LE(worst_iterations, 4);
}

TEST(ForwardKinematics, WithJacobianReturnsTheJacobianAtTheSolution) {
  const auto starts = sample_workspace(500, 26);
  const auto targets = sample_workspace(500, 27);
  for (std::size_t k = 0; k < starts.size(); ++k) {
    Eigen::Vector3d theta;
    ASSERT_TRUE(inverse_kinematics(kGeometry, targets[k], theta));
    Eigen::Vector3d p_plain = starts[k];
    Eigen::Vector3d p_with = starts[k];
    Eigen::Matrix3d dp_dtheta;
    bool valid = false;
    const FkResult plain = forward_kinematics(kGeometry, theta, p_plain, FkOptions{});
    const FkResult with = forward_kinematics_with_jacobian(kGeometry, theta, p_with, FkOptions{}, dp_dtheta, valid);
    ASSERT_TRUE(valid);
    EXPECT_EQ(p_plain, p_with);
    EXPECT_EQ(plain.iterations, with.iterations);
    Eigen::Matrix3d expected;
    ASSERT_TRUE(jacobian(kGeometry, p_with, expected));
    EXPECT_LT((dp_dtheta - expected).cwiseAbs().maxCoeff(), 1e-12 * expected.cwiseAbs().maxCoeff());
  }
  // Failure before any evaluation: flag false, matrix untouched.
  Eigen::Vector3d p = workspace_centre();
  Eigen::Matrix3d untouched = Eigen::Matrix3d::Constant(3.0);
  bool valid = true;
  const FkResult failed = forward_kinematics_with_jacobian(
      kGeometry, Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()), p, FkOptions{}, untouched, valid);
  EXPECT_FALSE(failed.converged);
  EXPECT_FALSE(valid);
  EXPECT_EQ(untouched, Eigen::Matrix3d::Constant(3.0));
}

TEST(ForwardKinematics, ToleranceAndIterationLimitAreHonoured) {
  const Eigen::Vector3d p = workspace_centre() + Eigen::Vector3d{0.03, -0.02, 0.01};
  Eigen::Vector3d theta;
  ASSERT_TRUE(inverse_kinematics(kGeometry, p, theta));
  Eigen::Vector3d solved;
  const FkResult loose = forward_kinematics_cold(kGeometry, theta, solved, FkOptions{1e-2, 30});
  const FkResult tight = forward_kinematics_cold(kGeometry, theta, solved, FkOptions{1e-12, 30});
  EXPECT_TRUE(loose.converged);
  EXPECT_TRUE(tight.converged);
  EXPECT_LT(loose.iterations, tight.iterations);
  EXPECT_LT(tight.residual_rad, 1e-12);
  const FkResult capped = forward_kinematics_cold(kGeometry, theta, solved, FkOptions{1e-12, 1});
  EXPECT_FALSE(capped.converged);
  EXPECT_EQ(capped.iterations, 1);
  EXPECT_TRUE(solved.allFinite());
}

TEST(ForwardKinematics, ReportedResidualIsTheTrueAngleError) {
  // FK forms its residual in tan(θ/2) with a series atan; it must equal IK(p) − θ exactly
  // (to rounding) for residuals from 1e-12 to 1 rad. max_iterations = 0: no step taken.
  std::mt19937_64 rng(24);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<int> decade(-12, 0);
  for (const Eigen::Vector3d& p : sample_workspace(3000, 25, 0.9)) {
    Eigen::Vector3d theta;
    ASSERT_TRUE(inverse_kinematics(kGeometry, p, theta));
    const Eigen::Vector3d offset = std::pow(10.0, decade(rng)) * Eigen::Vector3d{unit(rng), unit(rng), unit(rng)};
    const Eigen::Vector3d target = theta + offset;
    if (target.cwiseAbs().maxCoeff() >= 0.5 * std::numbers::pi) continue;
    Eigen::Vector3d p_start = p;
    const FkResult result = forward_kinematics(kGeometry, target, p_start, FkOptions{1e-300, 0});
    EXPECT_EQ(result.iterations, 0);
    EXPECT_EQ(p_start, p);
    const double expected = offset.cwiseAbs().maxCoeff();
    EXPECT_NEAR(result.residual_rad, expected, 1e-15 + 1e-13 * expected);
  }
}

TEST(ForwardKinematics, UnreachableOrNonFiniteAnglesFailWithoutNan) {
  constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
  for (const Eigen::Vector3d& theta : {Eigen::Vector3d{-1.5, -1.5, -1.5}, Eigen::Vector3d{3.0, 3.0, 3.0},
                                       Eigen::Vector3d{1.57, 1.57, -0.5}, Eigen::Vector3d{kNan, 0.3, 0.3},
                                       Eigen::Vector3d{0.3, std::numeric_limits<double>::infinity(), 0.3}}) {
    Eigen::Vector3d p = workspace_centre();
    const FkResult warm = forward_kinematics(kGeometry, theta, p, FkOptions{});
    EXPECT_FALSE(warm.converged) << theta.transpose();
    EXPECT_TRUE(p.allFinite());
    EXPECT_LE(warm.iterations, kDefaultFkMaxIterations);
    const FkResult cold = forward_kinematics_cold(kGeometry, theta, p, FkOptions{});
    EXPECT_FALSE(cold.converged);
    EXPECT_TRUE(p.allFinite());
  }
}

TEST(ForwardKinematics, UnreachableWarmStartFallsBackToTheCentre) {
  const Eigen::Vector3d target = workspace_centre() + Eigen::Vector3d{-0.01, 0.02, -0.03};
  Eigen::Vector3d theta;
  ASSERT_TRUE(inverse_kinematics(kGeometry, target, theta));
  for (const Eigen::Vector3d& start : {Eigen::Vector3d{0, 0, 0}, Eigen::Vector3d{1.0, 1.0, 1.0},
                                       Eigen::Vector3d(Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()))}) {
    Eigen::Vector3d p = start;
    const FkResult result = forward_kinematics(kGeometry, theta, p, FkOptions{});
    EXPECT_TRUE(result.converged);
    EXPECT_LE((p - target).norm(), 1e-6);
  }
}

TEST(LibnifalconReference, PublishedSchemeConvergesOnlyToItsLooseTolerance) {
  // Sanity of the benchmark baseline: from (0, 0, 0.08) it reaches 0.01 rad, not 1 µm.
  double worst_m = 0.0;
  int converged = 0;
  const auto points = sample_workspace(500, 22);
  for (const Eigen::Vector3d& p : points) {
    Eigen::Vector3d theta;
    ASSERT_TRUE(inverse_kinematics(kGeometry, p, theta));
    Eigen::Vector3d solved{libnifalcon_reference::kFirstGuess_device_m[0], libnifalcon_reference::kFirstGuess_device_m[1],
                           libnifalcon_reference::kFirstGuess_device_m[2]};
    const FkResult result = libnifalcon_reference::forward_kinematics(
        kGeometry, theta, solved, libnifalcon_reference::JacobianVariant::kIssue66);
    if (result.converged) {
      ++converged;
      worst_m = std::max(worst_m, (solved - p).norm());
    }
  }
  EXPECT_GT(converged, 0);
  EXPECT_GT(worst_m, 1e-5);
}

}  // namespace
}  // namespace fissure::falcon
