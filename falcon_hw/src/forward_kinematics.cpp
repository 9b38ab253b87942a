// Forward kinematics: damped Newton on r(p) = IK(p) − θ = 0 with the analytic ∂θ/∂p.
//
// Why Newton with a warm start: at 1 kHz the hand moves ≤ 0.5 mm between ticks, so the
// previous solution is already within Newton's quadratic-convergence basin and 2–3 steps
// reach 1e-9 rad. Why the line search and step limit: from far away (cold start) a full
// Newton step can leave the reachable region (IK fails) or overshoot; halving the step
// until ‖r‖ decreases makes the iteration monotone, so it cannot diverge the way
// libnifalcon's fixed-gain scheme does from the origin.
#include <cmath>
#include <limits>
#include <numbers>

#include <Eigen/LU>

#include "arm_inverse_kinematics.hpp"
#include "fissure/falcon_hw/kinematics.hpp"

namespace fissure::falcon {
namespace {

/// Longest Newton step accepted (m). Larger than any warm-start correction (≤ 0.5 mm per
/// tick, ≈ 0.35 mm after the first step) and than half the workspace, so it only bites on
/// wild first steps from a cold start far from the answer.
constexpr double kMaxNewtonStep_m = 0.03;
/// Step halvings tried before giving up on a direction: 2⁻²⁰ of 3 cm is 30 nm.
constexpr int kMaxStepHalvings = 20;

double max_abs(const Eigen::Vector3d& v) noexcept { return v.cwiseAbs().maxCoeff(); }

Eigen::Vector3d workspace_centre() noexcept {
  return {kWorkspaceCentre_device_m[0], kWorkspaceCentre_device_m[1], kWorkspaceCentre_device_m[2]};
}

FkResult failed_result() noexcept {
  FkResult failed;
  failed.residual_rad = std::numeric_limits<double>::infinity();
  return failed;
}

/// When dp_dtheta_out is given, it receives J = (∂θ/∂p)⁻¹ at the returned p — the derivative
/// the last evaluation already computed — and *dp_dtheta_valid says whether that worked.
FkResult newton(const FalconGeometry& geometry, const detail::ArmFrames& frames, const Eigen::Vector3d& theta_target,
                Eigen::Vector3d& p, const FkOptions& options, Eigen::Matrix3d* dp_dtheta_out = nullptr,
                bool* dp_dtheta_valid = nullptr) noexcept {
  if (dp_dtheta_valid != nullptr) *dp_dtheta_valid = false;
  // IK only ever yields |θ1| < 90°, so a target outside that is unreachable; inside it the
  // residual can be formed in tan(θ1/2) without an atan per evaluation (solve_residual).
  if (!(theta_target.cwiseAbs().maxCoeff() < std::numbers::pi / 2.0)) return failed_result();
  const Eigen::Vector3d tan_half_target{std::tan(0.5 * theta_target[0]), std::tan(0.5 * theta_target[1]),
                                        std::tan(0.5 * theta_target[2])};
  Eigen::Vector3d residual;
  Eigen::Matrix3d dtheta_dp;
  if (!detail::solve_residual(geometry, frames, p, tan_half_target, residual, dtheta_dp)) {
    // A start that is not reachable (first tick, after a fault) falls back to the centre.
    p = workspace_centre();
    if (!detail::solve_residual(geometry, frames, p, tan_half_target, residual, dtheta_dp)) return failed_result();
  }
  FkResult result;
  double residual_norm_squared = residual.squaredNorm();
  result.residual_rad = max_abs(residual);

  while (!(result.residual_rad < options.tolerance_rad) && result.iterations < options.max_iterations) {
    Eigen::Matrix3d dp_dtheta;
    if (!detail::invert_derivative(dtheta_dp, dp_dtheta)) break;
    Eigen::Vector3d step = -(dp_dtheta * residual);
    const double step_length = step.norm();
    if (!std::isfinite(step_length)) break;
    if (step_length > kMaxNewtonStep_m) step *= kMaxNewtonStep_m / step_length;

    // Backtracking: accept the first fraction of the step that lowers ‖r‖₂ (the Newton
    // direction is a descent direction of ‖r‖₂², so a small enough fraction always does).
    bool accepted = false;
    for (int halving = 0; halving <= kMaxStepHalvings; ++halving) {
      const Eigen::Vector3d p_trial = p + step;
      Eigen::Vector3d residual_trial;
      Eigen::Matrix3d dtheta_dp_trial;
      if (detail::solve_residual(geometry, frames, p_trial, tan_half_target, residual_trial, dtheta_dp_trial)) {
        const double norm_squared_trial = residual_trial.squaredNorm();
        if (norm_squared_trial < residual_norm_squared) {
          p = p_trial;
          dtheta_dp = dtheta_dp_trial;
          residual = residual_trial;
          residual_norm_squared = norm_squared_trial;
          accepted = true;
          break;
        }
      }
      step *= 0.5;
    }
    ++result.iterations;
    if (!accepted) break;  // at the floor of double precision, or θ not reachable
    result.residual_rad = max_abs(residual);
  }
  result.converged = result.residual_rad < options.tolerance_rad;
  if (dp_dtheta_out != nullptr) *dp_dtheta_valid = detail::invert_derivative(dtheta_dp, *dp_dtheta_out);
  return result;
}

}  // namespace

FkResult forward_kinematics(const FalconGeometry& geometry, const Eigen::Vector3d& theta_rad,
                            Eigen::Vector3d& p_device_m, const FkOptions& options) noexcept {
  return newton(geometry, detail::make_arm_frames(geometry), theta_rad, p_device_m, options);
}

FkResult forward_kinematics_with_jacobian(const FalconGeometry& geometry, const Eigen::Vector3d& theta_rad,
                                          Eigen::Vector3d& p_device_m, const FkOptions& options,
                                          Eigen::Matrix3d& dp_dtheta, bool& dp_dtheta_valid) noexcept {
  return newton(geometry, detail::make_arm_frames(geometry), theta_rad, p_device_m, options, &dp_dtheta,
                &dp_dtheta_valid);
}

FkResult forward_kinematics_cold(const FalconGeometry& geometry, const Eigen::Vector3d& theta_rad,
                                 Eigen::Vector3d& p_device_m, const FkOptions& options) noexcept {
  p_device_m = workspace_centre();
  return newton(geometry, detail::make_arm_frames(geometry), theta_rad, p_device_m, options);
}

}  // namespace fissure::falcon
