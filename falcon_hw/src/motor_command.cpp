// Force → motor counts with a direction-keeping clamp that no input can overflow.
#include "fissure/falcon_hw/motor_command.hpp"

#include <cmath>

namespace fissure::falcon {

MotorCommandResult force_to_motor_counts(const Eigen::Matrix3d& dp_dtheta, const Eigen::Vector3d& force_device_n,
                                         double newton_metre_per_count) noexcept {
  MotorCommandResult result;
  if (!dp_dtheta.allFinite() || !force_device_n.allFinite() || !std::isfinite(newton_metre_per_count) ||
      !(newton_metre_per_count > 0.0)) {
    result.non_finite = true;
    return result;
  }
  // Normalise F first so τ cannot overflow to inf for huge finite forces (1e308 N): the
  // direction comes from the unit force, the magnitude is applied only when it is known
  // not to saturate.
  const double force_scale_n = force_device_n.cwiseAbs().maxCoeff();
  if (force_scale_n == 0.0) return result;
  const Eigen::Vector3d unit_force = force_device_n / force_scale_n;
  const Eigen::Vector3d torque_per_unit = dp_dtheta.transpose() * unit_force;  // N·m per N of force_scale
  const Eigen::Vector3d counts_per_unit = kMotorCountSignPerTorque * torque_per_unit / newton_metre_per_count;
  if (!counts_per_unit.allFinite()) {  // J huge and gain tiny: cannot represent, refuse
    result.non_finite = true;
    return result;
  }
  const double largest_per_unit = counts_per_unit.cwiseAbs().maxCoeff();
  if (largest_per_unit == 0.0) return result;

  Eigen::Vector3d counts;
  // largest_per_unit · force_scale > 4095, written so the product cannot overflow.
  if (force_scale_n > static_cast<double>(kMaxMotorCount) / largest_per_unit) {
    counts = counts_per_unit * (static_cast<double>(kMaxMotorCount) / largest_per_unit);
    result.saturated = true;
  } else {
    counts = counts_per_unit * force_scale_n;
  }
  for (int i = 0; i < 3; ++i) {
    // |counts[i]| ≤ 4095 here by construction; the clamp is belt and braces against rounding.
    const double clamped = std::fmin(std::fmax(std::round(counts[i]), -static_cast<double>(kMaxMotorCount)),
                                     static_cast<double>(kMaxMotorCount));
    result.counts[i] = static_cast<std::int16_t>(clamped);
  }
  return result;
}

Eigen::Vector3d motor_counts_to_torque(const std::array<std::int16_t, 3>& counts, double newton_metre_per_count) noexcept {
  if (!std::isfinite(newton_metre_per_count) || !(newton_metre_per_count > 0.0)) return Eigen::Vector3d::Zero();
  return Eigen::Vector3d{static_cast<double>(counts[0]), static_cast<double>(counts[1]), static_cast<double>(counts[2])} *
         (newton_metre_per_count / kMotorCountSignPerTorque);
}

}  // namespace fissure::falcon
