// Closed-form inverse kinematics, its analytic derivative, the Jacobian and the workspace
// test. The per-arm algebra lives in arm_inverse_kinematics.hpp (shared with FK).
#include "fissure/falcon_hw/kinematics.hpp"

#include <cmath>

#include <Eigen/LU>

#include "arm_inverse_kinematics.hpp"

namespace fissure::falcon {

bool arm_angles(const FalconGeometry& geometry, const Eigen::Vector3d& p_device_m,
                std::array<ArmAngles, 3>& arms) noexcept {
  const detail::ArmFrames frames = detail::make_arm_frames(geometry);
  std::array<detail::ArmSolution, 3> solutions;
  for (int i = 0; i < 3; ++i) {
    if (!detail::solve_arm(geometry, frames, i, p_device_m, solutions[i])) return false;
  }
  for (int i = 0; i < 3; ++i) {
    arms[i].theta1_rad = 2.0 * std::atan(solutions[i].tan_half_theta1);
    arms[i].theta2_rad = std::atan2(solutions[i].sin2, solutions[i].cos2);
    arms[i].theta3_rad = std::atan2(solutions[i].sin3, solutions[i].cos3);
  }
  return true;
}

bool inverse_kinematics(const FalconGeometry& geometry, const Eigen::Vector3d& p_device_m,
                        Eigen::Vector3d& theta_rad) noexcept {
  return detail::solve_all(geometry, detail::make_arm_frames(geometry), p_device_m, theta_rad, nullptr);
}

bool inverse_kinematics_with_derivative(const FalconGeometry& geometry, const Eigen::Vector3d& p_device_m,
                                        Eigen::Vector3d& theta_rad, Eigen::Matrix3d& dtheta_dp) noexcept {
  return detail::solve_all(geometry, detail::make_arm_frames(geometry), p_device_m, theta_rad, &dtheta_dp);
}

namespace detail {

/// Relative determinant below which ∂θ/∂p counts as singular: |det M| < ε ‖M‖³ means the
/// rows are (nearly) dependent; ε leaves ~10 significant digits in the inverse.
inline constexpr double kSingularRelativeDeterminant = 1e-6;

bool invert_derivative(const Eigen::Matrix3d& dtheta_dp, Eigen::Matrix3d& dp_dtheta) noexcept {
  const double determinant = dtheta_dp.determinant();
  const double scale = dtheta_dp.cwiseAbs().maxCoeff();
  if (!std::isfinite(determinant) || !(std::abs(determinant) > kSingularRelativeDeterminant * scale * scale * scale)) {
    return false;
  }
  dp_dtheta = dtheta_dp.inverse();
  return dp_dtheta.allFinite();
}

}  // namespace detail

bool jacobian(const FalconGeometry& geometry, const Eigen::Vector3d& p_device_m, Eigen::Matrix3d& dp_dtheta) noexcept {
  Eigen::Vector3d theta_rad;
  Eigen::Matrix3d dtheta_dp;
  if (!inverse_kinematics_with_derivative(geometry, p_device_m, theta_rad, dtheta_dp)) return false;
  return detail::invert_derivative(dtheta_dp, dp_dtheta);
}

bool in_workspace(const FalconGeometry& geometry, const Eigen::Vector3d& p_device_m) noexcept {
  const Eigen::Vector3d centre{kWorkspaceCentre_device_m[0], kWorkspaceCentre_device_m[1],
                               kWorkspaceCentre_device_m[2]};
  // Negated so NaN fails.
  if (!((p_device_m - centre).squaredNorm() <= kWorkspaceRadius_m * kWorkspaceRadius_m)) return false;
  Eigen::Vector3d theta_rad;
  return inverse_kinematics(geometry, p_device_m, theta_rad);
}

}  // namespace fissure::falcon
