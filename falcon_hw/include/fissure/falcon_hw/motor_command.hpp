#pragma once
// Force → motor command (BRIEF §6). τ = Jᵀ F with J = ∂p/∂θ1 (virtual work: F·δp = τ·δθ),
// then int16 counts through a calibration gain, clamped to ±kMaxMotorCount by scaling all
// three together so the force direction is kept. No input — NaN, ±inf, 1e308 — can wrap.
#include <array>
#include <cstdint>

#include <Eigen/Core>

namespace fissure::falcon {

/// Largest motor command magnitude the firmware takes (12-bit DAC; libnifalcon promises
/// ±4096 in comments but never clamps — its int16 cast wraps instead).
inline constexpr std::int16_t kMaxMotorCount = 4095;

/// Default gain: libnifalcon's getForces multiplies the torque in N·m by an uncalibrated
/// 10000, i.e. 1e-4 N·m per count. NOT a measured calibration — a placeholder to replace.
inline constexpr double kDefaultNewtonMetrePerCount = 1e-4;

/// Sign between arm torque and motor command: libnifalcon's getForces sends −τ·10000, i.e.
/// a positive count turns the arm toward smaller θ1. Applied in both directions below.
inline constexpr double kMotorCountSignPerTorque = -1.0;

struct MotorCommandResult {
  std::array<std::int16_t, 3> counts{};
  bool saturated = false;   ///< the ±kMaxMotorCount clamp scaled the command down
  bool non_finite = false;  ///< NaN/inf in J, F or gain, gain ≤ 0, or unrepresentable: counts are zero
};

/// counts = sign · τ / newton_metre_per_count, τ = dp_dthetaᵀ · force_device_n; if any
/// |count| would exceed kMaxMotorCount all three are scaled by the same factor (the
/// largest becomes ±4095). Rounded to nearest. Never allocates, never wraps.
MotorCommandResult force_to_motor_counts(const Eigen::Matrix3d& dp_dtheta, const Eigen::Vector3d& force_device_n,
                                         double newton_metre_per_count) noexcept;

/// The arm torques (N·m, about θ1) a motor command produces — the inverse mapping, used
/// by SimFalcon. Non-finite or non-positive gain → zero torque.
Eigen::Vector3d motor_counts_to_torque(const std::array<std::int16_t, 3>& counts,
                                       double newton_metre_per_count) noexcept;

}  // namespace fissure::falcon
