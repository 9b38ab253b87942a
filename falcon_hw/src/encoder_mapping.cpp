// Encoder count ↔ arm angle. The only non-trivial part is count(): rounding that can
// never wrap the int16 (saturate) and never turns NaN into garbage (→ 0).
#include "fissure/falcon_hw/encoder_mapping.hpp"

#include <cmath>
#include <limits>

namespace fissure::falcon {

std::int16_t EncoderMapping::count(double theta) const noexcept {
  const double counts = (theta - offset_rad) / radians_per_count;
  if (std::isnan(counts)) return 0;
  constexpr double kLowest = std::numeric_limits<std::int16_t>::lowest();
  constexpr double kHighest = std::numeric_limits<std::int16_t>::max();
  // Compare before converting: casting an out-of-range double to an integer is UB.
  if (counts <= kLowest) return std::numeric_limits<std::int16_t>::lowest();
  if (counts >= kHighest) return std::numeric_limits<std::int16_t>::max();
  return static_cast<std::int16_t>(std::lround(counts));
}

Eigen::Vector3d encoders_to_theta(const EncoderMapping& mapping, const std::array<std::int16_t, 3>& counts) noexcept {
  return {mapping.theta_rad(counts[0]), mapping.theta_rad(counts[1]), mapping.theta_rad(counts[2])};
}

std::array<std::int16_t, 3> theta_to_encoders(const EncoderMapping& mapping, const Eigen::Vector3d& theta_rad) noexcept {
  return {mapping.count(theta_rad[0]), mapping.count(theta_rad[1]), mapping.count(theta_rad[2])};
}

}  // namespace fissure::falcon
