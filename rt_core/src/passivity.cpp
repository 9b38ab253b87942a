#include "fissure/rt_core/passivity.hpp"

#include <algorithm>
#include <cmath>

namespace fissure::rt {
namespace {

/// Moves `value` towards `target` by at most `max_step`.
double slew(double value, double target, double max_step) noexcept {
  return value + std::clamp(target - value, -max_step, max_step);
}

}  // namespace

void observe_energy(PassivityState& state, const Eigen::Vector3d& p_device_m) noexcept {
  if (state.primed) {
    const double work_j = state.force_acting_device_n.dot(p_device_m - state.p_prev_device_m);
    state.energy_j += work_j;
    if (state.recovery_window_left_s > 0.0) state.recovery_energy_j += work_j;
  }
  state.p_prev_device_m = p_device_m;
  state.primed = true;
  // From this exchange on, the force computed last tick is the one acting.
  state.force_acting_device_n = state.force_sent_last_device_n;
}

Eigen::Vector3d passivity_control(const PassivityConfig& config, PassivityState& state,
                                  const Eigen::Vector3d& force_device_n, const Eigen::Vector3d& v_filtered_m_per_s,
                                  const Eigen::Vector3d& v_raw_m_per_s, double period_s) noexcept {
  state.damping_n_s_per_m = 0.0;
  state.recovery_window_left_s = std::max(0.0, state.recovery_window_left_s - period_s);
  if (!config.enabled) {
    state.reduction_fraction = 0.0;
    state.reduction_n = 0.0;
    state.added_damping_n_s_per_m = 0.0;
    return force_device_n;
  }
  const Eigen::Vector3d& v = v_filtered_m_per_s;
  const double speed = v.norm();
  const double force_n = force_device_n.norm();
  const Eigen::Vector3d force_direction =
      force_n > 0.0 ? Eigen::Vector3d(force_device_n / force_n) : Eigen::Vector3d::Zero();

  if (speed >= config.min_speed_m_per_s) {
    // Energy by the end of the interval this force acts in: what is observed, plus the
    // command already sent (acting now), plus this one. Of the two velocity estimates take
    // the one that predicts more energy out: the filtered one lags by ~3 ms, the raw
    // difference is current but quantised. (Only the decision uses v_raw: it drives ramps,
    // so its noise cannot reach the force as a step.)
    const Eigen::Vector3d total = state.force_sent_last_device_n + force_device_n;
    const double predicted_j =
        state.energy_j - state.recovery_energy_j + std::max(total.dot(v_filtered_m_per_s), total.dot(v_raw_m_per_s)) * period_s;
    const double excess_j = predicted_j + config.margin_j;  // above the reference −margin

    // g: while the environment returns energy (F̂·v > 0 by the raw difference, which has no
    // filter lag: gated by the lagging filtered velocity the reduction landed in the next
    // inward half-cycle and pumped the contact resonance) and E' is above the reference, head
    // for the fraction of F that dissipates the excess within dissipation_time_s. While E'
    // stays above the reference and the hand pushes in, hold it (giving the force back now
    // would store energy the environment will return); below the reference give it back.
    const double returning_m_per_s = force_direction.dot(v_raw_m_per_s);  // F̂·v
    double target = 0.0;
    if (excess_j > 0.0) {
      target = returning_m_per_s > 0.0 && force_n > 0.0
                   ? std::max(state.reduction_fraction,
                              std::min(1.0, excess_j / (config.dissipation_time_s * returning_m_per_s * force_n)))
                   : state.reduction_fraction;
    }
    // The fraction may change by at most max_correction_step_n of force per tick, steeper in
    // proportion to how much energy has really been created (E' > 0).
    const double urgency =
        std::min(kPassivityMaxUrgency, 1.0 + std::max(0.0, predicted_j) / (kPassivityUrgencyMargins * config.margin_j));
    const double max_fraction_step =
        std::min(1.0, config.max_correction_step_n * urgency / std::max(force_n, config.max_correction_step_n));
    state.reduction_fraction = slew(state.reduction_fraction, target, max_fraction_step);

    // β: the damping that dissipates the excess within dissipation_time_s at this speed,
    // bounded, ramped.
    const double damping_target =
        excess_j > 0.0 ? std::min(config.max_damping_n_s_per_m, excess_j / (config.dissipation_time_s * speed * speed))
                       : 0.0;
    const double damping_step = config.damping_ramp_s > 0.0
                                    ? config.max_damping_n_s_per_m * period_s / config.damping_ramp_s
                                    : config.max_damping_n_s_per_m;
    state.added_damping_n_s_per_m = slew(state.added_damping_n_s_per_m, damping_target, damping_step);
  }
  // At (filtered) standstill g and β hold: the force does no work there, and giving it back
  // between the swings of a buzzing contact (still on average) undid the controller — with a
  // give-back at a tenth of the base ramp the Z-width with the controller on fell below the
  // uncontrolled one (a 1–3 mm slow limit cycle at 2–8 kHz, fissure bench rt).

  // A fraction of F: the force is reduced, never reversed, and follows F continuously as the
  // contact comes and goes (the fraction persists across bounces).
  state.reduction_n = state.reduction_fraction * force_n;
  const Eigen::Vector3d correction = state.reduction_n * force_direction + state.added_damping_n_s_per_m * v;
  if (state.reduction_fraction <= 0.0 && state.added_damping_n_s_per_m <= 0.0) return force_device_n;
  state.damping_n_s_per_m = correction.norm() / std::max(speed, config.min_speed_m_per_s);
  state.dissipated_by_controller_j += correction.dot(v) * period_s;
  return force_device_n - correction;
}

void record_sent_force(PassivityState& state, const Eigen::Vector3d& force_device_n) noexcept {
  state.force_sent_last_device_n = force_device_n;
}

void restart_observer(PassivityState& state) noexcept {
  state.primed = false;
  state.recovery_window_left_s = kPassivityRecoveryWindow_s;
  state.force_sent_last_device_n.setZero();
  state.force_acting_device_n.setZero();
  state.reduction_fraction = 0.0;
  state.reduction_n = 0.0;
  state.added_damping_n_s_per_m = 0.0;
}

}  // namespace fissure::rt
