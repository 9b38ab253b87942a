#include "fissure/rt_core/velocity_filter.hpp"

#include <cmath>
#include <numbers>

namespace fissure::rt {

VelocityFilterCoefficients design_velocity_filter(double cutoff_hz, double rate_hz) noexcept {
  // Bilinear transform of H(s) = ω²/(s² + √2ωs + ω²) with ω pre-warped so the −3 dB point
  // lands exactly on cutoff_hz in the digital filter.
  const double k = std::tan(std::numbers::pi * cutoff_hz / rate_hz);
  const double k2 = k * k;
  const double norm = 1.0 / (1.0 + std::numbers::sqrt2 * k + k2);
  VelocityFilterCoefficients c;
  c.b0 = k2 * norm;
  c.b1 = 2.0 * c.b0;
  c.b2 = c.b0;
  c.a1 = 2.0 * (k2 - 1.0) * norm;
  c.a2 = (1.0 - std::numbers::sqrt2 * k + k2) * norm;
  return c;
}

double velocity_lag_s(double cutoff_hz, double rate_hz) noexcept {
  // Group delay at DC of the digital filter: Σ n·h[n] = (b1 + 2b2)/B(1) − (a1 + 2a2)/A(1)
  // samples (exact for the discrete filter, ≈ √2/ω_c for f_c ≪ rate), plus half a sample
  // for the backward difference.
  const VelocityFilterCoefficients c = design_velocity_filter(cutoff_hz, rate_hz);
  const double numerator_sum = c.b0 + c.b1 + c.b2;
  const double denominator_sum = 1.0 + c.a1 + c.a2;
  const double delay_samples = (c.b1 + 2.0 * c.b2) / numerator_sum - (c.a1 + 2.0 * c.a2) / denominator_sum;
  return (delay_samples + 0.5) / rate_hz;
}

void reset(VelocityFilterState& state) noexcept { state = VelocityFilterState{}; }

Eigen::Vector3d update_velocity(const VelocityFilterCoefficients& c, VelocityFilterState& state,
                                const Eigen::Vector3d& p_device_m, double period_s) noexcept {
  if (!state.primed) {
    // Start from rest at this sample: a first difference against garbage would inject a
    // velocity spike into the HC damping term and the passivity observer.
    reset(state);
    state.p_prev_device_m = p_device_m;
    state.primed = true;
    return Eigen::Vector3d::Zero();
  }
  const Eigen::Vector3d raw = (p_device_m - state.p_prev_device_m) / period_s;
  state.p_prev_device_m = p_device_m;
  const Eigen::Vector3d y = c.b0 * raw + c.b1 * state.x1 + c.b2 * state.x2 - c.a1 * state.y1 - c.a2 * state.y2;
  state.x2 = state.x1;
  state.x1 = raw;
  state.y2 = state.y1;
  state.y1 = y;
  return y;
}

}  // namespace fissure::rt
