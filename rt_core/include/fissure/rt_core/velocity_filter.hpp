#pragma once
// Pipeline stage: end-effector velocity estimate.
//
// Differenced encoder positions are noisy (≈ 0.05 mm per count, BRIEF §6: one count per
// 1 ms tick reads as 0.05 m/s), so the backward difference (p_k − p_{k−1})/T goes through
// a 2nd-order Butterworth low-pass (bilinear transform, cutoff pre-warped), per axis.
// Why Butterworth: flat pass band (no overshoot in the HC damping term or the passivity
// observer's prediction) and −40 dB/decade against quantisation noise, at the cost of a
// known, small lag. Lag at low frequency (group delay at DC):
//     lag ≈ √2 / (2π f_c)  (the filter)  +  T/2  (the backward difference)
// e.g. f_c = 100 Hz at 1 kHz: 2.25 ms + 0.5 ms ≈ 2.75 ms. velocity_lag_s() computes it.
#include <Eigen/Core>

namespace fissure::rt {

struct VelocityFilterConfig {
  /// Low-pass cutoff [Hz]. 100 Hz keeps hand motion (< 10 Hz, voluntary) and contact
  /// transients up to tens of Hz while cutting the quantisation noise near Nyquist.
  double cutoff_hz = 100.0;
};

/// Difference-equation coefficients, computed once from (cutoff, rate) when the model is
/// built: y = b0·x + b1·x₁ + b2·x₂ − a1·y₁ − a2·y₂.
struct VelocityFilterCoefficients {
  double b0 = 1.0, b1 = 0.0, b2 = 0.0, a1 = 0.0, a2 = 0.0;
};

struct VelocityFilterState {
  Eigen::Vector3d p_prev_device_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d x1 = Eigen::Vector3d::Zero(), x2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d y1 = Eigen::Vector3d::Zero(), y2 = Eigen::Vector3d::Zero();
  bool primed = false;  ///< false: the next sample only sets p_prev (velocity 0)
};

/// Butterworth low-pass coefficients; requires 0 < cutoff_hz < rate_hz / 2.
VelocityFilterCoefficients design_velocity_filter(double cutoff_hz, double rate_hz) noexcept;

/// Low-frequency lag of the whole estimate (filter group delay at DC + T/2) [s].
double velocity_lag_s(double cutoff_hz, double rate_hz) noexcept;

/// Forgets the history: the next update starts from rest at the given sample.
void reset(VelocityFilterState& state) noexcept;

/// Feeds one position sample, returns the filtered velocity [m/s], device frame.
Eigen::Vector3d update_velocity(const VelocityFilterCoefficients& coefficients, VelocityFilterState& state,
                                const Eigen::Vector3d& p_device_m, double period_s) noexcept;

}  // namespace fissure::rt
