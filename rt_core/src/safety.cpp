#include "fissure/rt_core/safety.hpp"

#include <algorithm>
#include <cmath>

#include "fissure/rt_core/faults.hpp"

namespace fissure::rt {

void start_ramp_in(SafetyState& state, double ramp_in_s) noexcept {
  state.phase = RampPhase::kRampIn;
  state.ramp_gain = 0.0;
  state.ramp_in_s = ramp_in_s;
}

namespace {

void advance_ramp(const SafetyConfig& config, SafetyState& state, bool stop_requested, double period_s) noexcept {
  if (stop_requested && state.phase != RampPhase::kStopped) state.phase = RampPhase::kRampOut;
  switch (state.phase) {
    case RampPhase::kRampIn:
      state.ramp_gain = state.ramp_in_s > 0.0 ? std::min(1.0, state.ramp_gain + period_s / state.ramp_in_s) : 1.0;
      if (state.ramp_gain >= 1.0) state.phase = RampPhase::kRunning;
      break;
    case RampPhase::kRunning:
      state.ramp_gain = 1.0;
      break;
    case RampPhase::kRampOut:
      state.ramp_gain =
          config.ramp_out_s > 0.0 ? std::max(0.0, state.ramp_gain - period_s / config.ramp_out_s) : 0.0;
      if (state.ramp_gain <= 0.0) state.phase = RampPhase::kStopped;
      break;
    case RampPhase::kStopped:
      state.ramp_gain = 0.0;
      break;
  }
}

}  // namespace

Eigen::Vector3d workspace_soft_wall_n(const SafetyConfig& config, const Eigen::Vector3d& p_device_m,
                                      std::uint32_t& flags) noexcept {
  const Eigen::Vector3d from_centre = p_device_m - config.workspace_centre_device_m;
  const double distance = from_centre.norm();
  if (!(distance > config.workspace_radius_m)) return Eigen::Vector3d::Zero();
  flags |= kFlagSoftWall;
  return -config.soft_wall_stiffness_n_per_m * (distance - config.workspace_radius_m) * (from_centre / distance);
}

Eigen::Vector3d clamp_force_magnitude(const Eigen::Vector3d& force_n, double max_force_n) noexcept {
  const double magnitude = force_n.norm();
  return magnitude > max_force_n ? Eigen::Vector3d(force_n * (max_force_n / magnitude)) : force_n;
}

Eigen::Vector3d apply_safety(const SafetyConfig& config, SafetyState& state, const SafetyInput& input,
                             double period_s, std::uint32_t& flags) noexcept {
  const bool finite = input.force_device_n.allFinite() && input.p_device_m.allFinite();
  if (!finite) flags |= kFaultNonFinite;
  if (input.device_fault || !finite) {
    // Zero now, not rate-limited. Whatever cleared the fault restarts the ramp-in, so the
    // force never returns as a step.
    state.last_force_device_n.setZero();
    if (state.phase != RampPhase::kStopped) {
      state.phase = input.stop_requested ? RampPhase::kStopped : RampPhase::kRampIn;
      state.ramp_gain = 0.0;
      state.ramp_in_s = config.fault_ramp_in_s;
    }
    return Eigen::Vector3d::Zero();
  }

  if (input.force_device_n.norm() > config.max_force_n) flags |= kFlagForceClamped;
  Eigen::Vector3d force = clamp_force_magnitude(input.force_device_n, config.max_force_n);

  advance_ramp(config, state, input.stop_requested, period_s);
  if (state.phase == RampPhase::kStopped) {
    // Stopped means zero, exactly, whatever the rate limiter still remembers.
    state.last_force_device_n.setZero();
    return Eigen::Vector3d::Zero();
  }
  force *= state.ramp_gain;

  const double max_step = config.max_force_rate_n_per_s * period_s;
  const Eigen::Vector3d step = force - state.last_force_device_n;
  const double step_norm = step.norm();
  if (step_norm > max_step) {
    force = state.last_force_device_n + step * (max_step / step_norm);
    flags |= kFlagForceRateLimited;
  }
  state.last_force_device_n = force;
  return force;
}

}  // namespace fissure::rt
