#pragma once
// libnifalcon's published kinematic schemes, re-implemented from their description (BRIEF §6,
// issue 3) for COMPARISON ONLY: the benchmark's baseline row and the test that proves the
// finite-difference check can catch the issue-66 Jacobian. Never used on the RT path.
#include <array>

#include <Eigen/Core>

#include "fissure/falcon_hw/falcon_geometry.hpp"
#include "fissure/falcon_hw/kinematics.hpp"

namespace fissure::falcon::libnifalcon_reference {

/// ∂θ1/∂p as libnifalcon's FalconKinematicStamper::jacobian builds it before inverting:
/// identical to ours except the z entry of each row, sin² θ2 / den instead of
/// sin θ2 sin θ3 / den (libnifalcon issue #66).
Eigen::Matrix3d dtheta_dp_issue66(const FalconGeometry& geometry, const std::array<ArmAngles, 3>& arms) noexcept;

/// libnifalcon's first guess: "if the initial position is the origin ... everything explodes".
inline constexpr std::array<double, 3> kFirstGuess_device_m{0.0, 0.0, 0.08};
/// Its stopping rule: Euclidean norm of θ − IK(p) below 0.01 rad, at most 15 iterations.
inline constexpr double kTargetError_rad = 0.01;
inline constexpr int kMaxTries = 15;
/// Its step gain, halved whenever the error grows.
inline constexpr double kInitialStepGain = 0.5;

enum class JacobianVariant { kIssue66, kCorrected };

/// libnifalcon's FK: p ← p + gain · J · (θ − IK(p)) with J = (∂θ/∂p)⁻¹, gain 0.5 halved when
/// the error grows, stop when the error (measured BEFORE the step) is < 0.01 rad or after
/// 15 tries; on failure libnifalcon leaves the position at its input, and so do we. Starts
/// from p_device_m (pass kFirstGuess_device_m for the published cold scheme). Where
/// libnifalcon would produce NaN (IK outside its domain) this stops and reports failure.
FkResult forward_kinematics(const FalconGeometry& geometry, const Eigen::Vector3d& theta_rad,
                            Eigen::Vector3d& p_device_m, JacobianVariant variant) noexcept;

}  // namespace fissure::falcon::libnifalcon_reference
