// libnifalcon's FK scheme and its issue-66 Jacobian, for the benchmark baseline and tests.
#include "fissure/falcon_hw/libnifalcon_reference.hpp"

#include <cmath>
#include <limits>

#include <Eigen/LU>

namespace fissure::falcon::libnifalcon_reference {

Eigen::Matrix3d dtheta_dp_issue66(const FalconGeometry& geometry, const std::array<ArmAngles, 3>& arms) noexcept {
  Eigen::Matrix3d rows;
  for (int i = 0; i < 3; ++i) {
    const double t1 = arms[i].theta1_rad;
    const double t2 = arms[i].theta2_rad;
    const double t3 = arms[i].theta3_rad;
    const double phi = geometry.phi_rad[i];
    const double den = -geometry.a_m * std::sin(t3) * (std::sin(t1) * std::cos(t2) - std::sin(t2) * std::cos(t1));
    rows(i, 0) = (std::cos(phi) * std::cos(t2) * std::sin(t3) - std::sin(phi) * std::cos(t3)) / den;
    rows(i, 1) = (std::sin(phi) * std::cos(t2) * std::sin(t3) + std::cos(phi) * std::cos(t3)) / den;
    rows(i, 2) = std::sin(t2) * std::sin(t2) / den;  // the bug: should be sin(t2) * sin(t3)
  }
  return rows;
}

namespace {

bool derivative(const FalconGeometry& geometry, const Eigen::Vector3d& p, JacobianVariant variant,
                Eigen::Vector3d& theta, Eigen::Matrix3d& dtheta_dp) noexcept {
  if (variant == JacobianVariant::kCorrected) {
    return inverse_kinematics_with_derivative(geometry, p, theta, dtheta_dp);
  }
  std::array<ArmAngles, 3> arms;
  if (!arm_angles(geometry, p, arms)) return false;
  theta = {arms[0].theta1_rad, arms[1].theta1_rad, arms[2].theta1_rad};
  dtheta_dp = dtheta_dp_issue66(geometry, arms);
  return true;
}

}  // namespace

FkResult forward_kinematics(const FalconGeometry& geometry, const Eigen::Vector3d& theta_rad,
                            Eigen::Vector3d& p_device_m, JacobianVariant variant) noexcept {
  FkResult result;
  result.residual_rad = std::numeric_limits<double>::infinity();
  Eigen::Vector3d previous = p_device_m;
  double previous_error = 10000.0;  // libnifalcon's initial "previousError"
  double gain = kInitialStepGain;
  for (int attempt = 0; attempt < kMaxTries; ++attempt) {
    Eigen::Vector3d theta;
    Eigen::Matrix3d dtheta_dp;
    if (!derivative(geometry, previous, variant, theta, dtheta_dp)) return result;
    const Eigen::Vector3d delta = theta_rad - theta;
    const Eigen::Vector3d current = previous + gain * (dtheta_dp.inverse() * delta);
    const double error = delta.norm();
    previous = current;
    result.iterations = attempt + 1;
    if (!current.allFinite()) return result;
    if (error < kTargetError_rad) {
      p_device_m = current;
      result.converged = true;
      result.residual_rad = error;  // libnifalcon's own measure: before its last step
      return result;
    }
    if (error > previous_error) gain /= 2.0;
    previous_error = error;
  }
  return result;
}

}  // namespace fissure::falcon::libnifalcon_reference
