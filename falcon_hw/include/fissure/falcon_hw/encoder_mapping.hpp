#pragma once
// Encoder count ↔ motor-arm angle θ1 (BRIEF §6). Pure, noexcept, no allocation.
#include <array>
#include <cstdint>
#include <numbers>

#include <Eigen/Core>

namespace fissure::falcon {

/// Slots on the motor's encoder wheel (libnifalcon WHEEL_SLOTS_NUMBER).
inline constexpr double kEncoderWheelSlots = 320.0;
/// Quadrature decoding: four counts per slot ⇒ 1280 counts per motor revolution.
inline constexpr double kEncoderCountsPerMotorRev = 4.0 * kEncoderWheelSlots;
/// Capstan drive: motor shaft diameter and the arm's drum diameter (libnifalcon
/// SHAFT_DIAMETER, SMALL_ARM_DIAMETER); the arm turns 0.01425/0.110 rev per motor rev.
inline constexpr double kMotorShaftDiameter_m = 0.01425;
inline constexpr double kArmDrumDiameter_m = 0.110;
/// ≈ 6.3592e-4 rad ≈ 0.036435° of arm angle per count.
inline constexpr double kDefaultRadiansPerCount =
    2.0 * std::numbers::pi / kEncoderCountsPerMotorRev * (kMotorShaftDiameter_m / kArmDrumDiameter_m);
/// Arm angle at count 0 after homing (libnifalcon THETA_OFFSET_ANGLE = 35°).
inline constexpr double kDefaultThetaOffset_rad = 35.0 * std::numbers::pi / 180.0;

/// θ1 = count · radians_per_count + offset_rad. Same mapping for all three arms.
struct EncoderMapping {
  double radians_per_count = kDefaultRadiansPerCount;
  double offset_rad = kDefaultThetaOffset_rad;

  [[nodiscard]] double theta_rad(std::int16_t count) const noexcept {
    return static_cast<double>(count) * radians_per_count + offset_rad;
  }
  /// Nearest count (ties away from zero), saturated to the int16 range; NaN → 0.
  [[nodiscard]] std::int16_t count(double theta_rad) const noexcept;
};

[[nodiscard]] Eigen::Vector3d encoders_to_theta(const EncoderMapping& mapping,
                                                const std::array<std::int16_t, 3>& counts) noexcept;
[[nodiscard]] std::array<std::int16_t, 3> theta_to_encoders(const EncoderMapping& mapping,
                                                            const Eigen::Vector3d& theta_rad) noexcept;

}  // namespace fissure::falcon
