#include "fissure/rt_core/passivity.hpp"

#include <algorithm>
#include <cmath>

#include "fissure/rt_core/safety.hpp"

namespace fissure::rt {
namespace {

/// Moves `value` towards `target` by at most `max_step`.
double slew(double value, double target, double max_step) noexcept {
  return value + std::clamp(target - value, -max_step, max_step);
}

/// Closes the recovery window's account: its forgiven share joins the total.
void close_recovery_window(PassivityState& state) noexcept {
  state.recovery_forgiven_j += std::clamp(state.recovery_window_energy_j, 0.0, kPassivityRecoveryForgiveness_j);
  state.recovery_window_energy_j = 0.0;
}

/// What the reduction g does not act on: the closed windows' forgiven work plus the open one's,
/// but never more than E stands above the reference −margin — forgiven work that the damper
/// (or the hand) has since dissipated is no longer owed. (Without this bound the forgiveness
/// of every past fault adds up — 4 mJ × 18 faults — and g stops acting at all.)
double forgiven_j(const PassivityState& state, double margin_j) noexcept {
  const double owed_j =
      state.recovery_forgiven_j + std::clamp(state.recovery_window_energy_j, 0.0, kPassivityRecoveryForgiveness_j);
  return std::min(owed_j, std::max(0.0, state.energy_j + margin_j));
}

/// Raw speed from which the energy bound acts (passivity.hpp).
double bounding_speed_m_per_s(double period_s) noexcept {
  return std::max(kPassivityBoundingMinSpeed_m_per_s,
                  kPassivityBoundingMinCountsPerTick * kPassivityEncoderCount_m / period_s);
}

}  // namespace

void observe_energy(PassivityState& state, const Eigen::Vector3d& p_device_m) noexcept {
  if (state.primed) {
    const double work_j = state.force_acting_device_n.dot(p_device_m - state.p_prev_device_m);
    state.energy_j += work_j;
    if (state.recovery_window_left_s > 0.0) {
      state.recovery_energy_j += work_j;
      state.recovery_window_energy_j += work_j;
    }
  }
  state.p_prev_device_m = p_device_m;
  state.primed = true;
  // From this exchange on, the force computed last tick is the one acting.
  state.force_acting_device_n = state.force_sent_last_device_n;
}

Eigen::Vector3d passivity_control(const PassivityConfig& config, PassivityState& state,
                                  const Eigen::Vector3d& force_device_n, const Eigen::Vector3d& v_filtered_m_per_s,
                                  const Eigen::Vector3d& v_raw_m_per_s, double period_s,
                                  double stored_energy_j) noexcept {
  state.damping_n_s_per_m = 0.0;
  state.energy_bound_acted = false;
  if (state.recovery_window_left_s > 0.0) {
    state.recovery_window_left_s = std::max(0.0, state.recovery_window_left_s - period_s);
    if (state.recovery_window_left_s <= 0.0) close_recovery_window(state);
  }
  // U as the rendered spring stores it: past max_force_n the force is clamped, and a spring
  // clamped at the fraction r = F_max/|F| of its force stores r·(2 − r) of U (exact for n = 1, a
  // slight underestimate for n > 1).
  const double raw_force_n = force_device_n.norm();
  const double clamp_share = raw_force_n > config.max_force_n ? config.max_force_n / raw_force_n : 1.0;
  const double stored_j = std::max(0.0, stored_energy_j) * clamp_share * (2.0 - clamp_share);
  // Forgiven work already dissipated is no longer owed (see forgiven_j): not beyond the debt.
  state.recovery_forgiven_j =
      std::min(state.recovery_forgiven_j, std::max(0.0, state.energy_j + stored_j + config.margin_j));
  if (!config.enabled) {
    state.reduction_fraction = 0.0;
    state.reduction_n = 0.0;
    state.added_damping_n_s_per_m = 0.0;
    return force_device_n;
  }
  // Everything below works on the force the device will render (passivity.hpp).
  // (safety's clamp makes this of it afterwards; the controller must act on it, not on a force never sent)
  const Eigen::Vector3d force = clamp_force_magnitude(force_device_n, config.max_force_n);
  const Eigen::Vector3d& v = v_filtered_m_per_s;
  const double speed = v.norm();
  const double force_n = force.norm();
  const Eigen::Vector3d force_direction = force_n > 0.0 ? Eigen::Vector3d(force / force_n) : Eigen::Vector3d::Zero();
  const double budget_j = kPassivityRampEnergyBudgetMargins * config.margin_j;

  // The reduction g's debt: what the environment would have put into the hand once it has
  // returned everything it stores now, E + U (passivity.hpp: the reference follows the stored
  // energy), less the forgiven recovery work and what the device's own damper has dissipated,
  // measured against the reference −margin.
  const double debt_j = state.energy_j + stored_j - forgiven_j(state, config.margin_j + stored_j);
  state.damping_credit_j += config.device_damping_n_s_per_m * v_filtered_m_per_s.squaredNorm() * period_s;
  state.damping_credit_j = std::min(state.damping_credit_j, kPassivityMaxDampingCredit_j);
  // In contact the damper's dissipation is banked for this contact's debt; out of it only what
  // is still owed is kept (free motion does not pre-pay the next contact).
  if (force_device_n.isZero(0.0)) state.damping_credit_j = std::min(state.damping_credit_j, std::max(0.0, debt_j + config.margin_j));
  const double debt_excess_j = debt_j - state.damping_credit_j + config.margin_j;
  // The same debt if g stays as it is: the rendered spring is (1 − g) of the environment's and
  // stores (1 − g)·U, so a contact pressed with g in effect owes nothing for the part withheld.
  const double kept_debt_excess_j = debt_excess_j - state.reduction_fraction * stored_j;
  // The stall account (kPassivityStallAccountWindow_s): booked while its window is open, never
  // more than the debt (g, β, the damper have paid the rest) nor than U (what is returned later).
  if (state.stall_window_left_s > 0.0) {
    state.stall_window_left_s = std::max(0.0, state.stall_window_left_s - period_s);
    state.stall_debt_j = std::max(state.stall_debt_j, debt_excess_j);
  }
  state.stall_debt_j = std::clamp(state.stall_debt_j, 0.0, std::min(std::max(0.0, debt_excess_j), stored_j));
  const double stall_debt_j = state.stall_debt_j;
  // The rest the hand holds: followed inwards at once, outwards with kPassivityRestAnchorTime_s.
  // (p_prev_device_m is this tick's reading: observe_energy ran first.)
  const Eigen::Vector3d& p_device_m = state.p_prev_device_m;
  if (force_direction.dot(p_device_m - state.rest_anchor_device_m) < 0.0) state.rest_anchor_device_m = p_device_m;
  state.rest_anchor_device_m +=
      std::min(1.0, period_s / kPassivityRestAnchorTime_s) * (p_device_m - state.rest_anchor_device_m);
  const bool leaving_rest = force_direction.dot(p_device_m - state.rest_anchor_device_m) > kPassivityExitGate_m;
  // While that debt is above the reference g holds (giving the force back while the hand pushes
  // in would store energy the environment returns later; at standstill nothing is paid back)
  // and grows while the environment returns energy (below); once it is paid — by g, by β, or by
  // the device's own damper — g gives the force back, at a hold too: nothing is owed there
  // (what the full force then stores is owed, and withheld, on the way out).
  // The stall account is not held at rest: it is collected on the way out (below).
  double target = kept_debt_excess_j - stall_debt_j > 0.0 ? state.reduction_fraction : 0.0;
  double raise_step_n = config.max_correction_step_n;

  if (speed >= config.min_speed_m_per_s) {
    // Energy by the end of the interval this force acts in: what is observed, plus the
    // command already sent (acting now), plus this one. Of the two velocity estimates take
    // the one that predicts more energy out: the filtered one lags by ~3 ms, the raw
    // difference is current but quantised. (Only the decision uses v_raw: it drives ramps,
    // so its noise cannot reach the force as a step.)
    const Eigen::Vector3d total = state.force_sent_last_device_n + force;
    // The damper acts on all of E; the reduction g on E less the forgiven recovery work
    // (kPassivityRecoveryForgiveness_j per fault: a force brought back at a static hold) and
    // less the device damper's credit.
    const double predicted_all_j =
        state.energy_j + std::max(total.dot(v_filtered_m_per_s), total.dot(v_raw_m_per_s)) * period_s;
    const double excess_all_j = predicted_all_j + config.margin_j;
    const double predicted_j =
        predicted_all_j - forgiven_j(state, config.margin_j) - state.damping_credit_j - stall_debt_j;

    // g: while the environment returns energy (F̂·v > 0 by the raw difference, which has no
    // filter lag: gated by the lagging filtered velocity the reduction landed in the next
    // inward half-cycle and pumped the contact resonance) and its debt E + U is above the
    // reference, head for the fraction of F that withholds the debt within dissipation_time_s.
    const double returning_m_per_s = force_direction.dot(v_raw_m_per_s);  // F̂·v
    // Power the force returns by the filtered velocity (quantisation-free: ≈ 0 at a hold).
    const double returned_power_w = std::max(0.0, force_direction.dot(v_filtered_m_per_s)) * force_n;
    const double loop_debt_excess_j = debt_excess_j - stall_debt_j;
    if (loop_debt_excess_j > 0.0 && returning_m_per_s > 0.0 && force_n > 0.0) {
      // Withhold the debt from what the force returns over dissipation_time_s (a wall
      // giving back slightly more than it stored)…
      const double share_for_excess = loop_debt_excess_j / (config.dissipation_time_s * returning_m_per_s * force_n);
      // …unless the loop has already generated more than the ramp's energy budget: then
      // the environment is plainly active (a swap offset left from a contact the host has
      // lost, pushing the hand out at watts) and the push comes off entirely, ramped. Only
      // withholding the excess, g caught up with a force that keeps pushing at the rate the
      // excess grew: an overshoot of P·dissipation_time_s (0.2 J at 4 W: the
      // hc_lambda_over_k_0 stress case, 0.115 J).
      const double share = predicted_j > budget_j ? 1.0 : share_for_excess;
      target = std::max(state.reduction_fraction, std::min(1.0, share));
    }
    // The stall account, on the way out of the rest: the share of the force that, held while
    // the environment returns what it stores, withholds the account by the time U is gone
    // (stall_debt_j ≤ U, so ≤ 1). Out of the rest only, so a rest keeps the whole wall.
    if (leaving_rest && stall_debt_j > 0.0 && stored_j > 0.0) {
      target = std::max(target, std::min(1.0, stall_debt_j / stored_j));
    }
    // The fraction may grow by at most max_correction_step_n of force per tick, steeper in
    // proportion to how much energy has really been created (E' > 0).
    const double urgency =
        std::min(kPassivityMaxUrgency, 1.0 + std::max(0.0, predicted_j) / (kPassivityUrgencyMargins * config.margin_j));
    // Energy bound on the ramp itself: while the force pushes the hand out at power
    // P = F̂·v_f·|F|, taking it off at s newtons per tick returns about ½·P·T·|F|/s before it
    // is gone; s is at least what keeps that within the budget (kPassivityRampEnergyBudgetMargins
    // margins). At a hold (v_f of mm/s, a few N) this is far below max_correction_step_n and
    // changes nothing; a force pushing a hand out at 0.5 m/s with 8 N (a flick bouncing off the
    // contact, a swap offset left from a contact the host has already lost) is taken off within
    // a few ticks instead of at 0.05–2 N per tick while it delivers 4 mJ per tick
    // (hc_lambda_over_k_0 stress case: 0.115 J). (|F| and P of the whole force, not of the part
    // still acting: a step sized to the remainder shrinks as it goes and the tail returns the
    // budget again and again.)
    const double energy_bounded_step_n =
        debt_excess_j > 0.0 ? returned_power_w * period_s * force_n / (2.0 * budget_j) : 0.0;
    raise_step_n = std::max(config.max_correction_step_n * urgency, energy_bounded_step_n);

    // β: the damping that dissipates the excess within dissipation_time_s at this speed,
    // bounded, ramped.
    // (Not on the stall account: that is collected by g on the way out, see above.)
    const double loop_excess_all_j = excess_all_j - stall_debt_j;
    const double damping_target =
        loop_excess_all_j > 0.0
            ? std::min(config.max_damping_n_s_per_m, loop_excess_all_j / (config.dissipation_time_s * speed * speed))
            : 0.0;
    const double damping_step = config.damping_ramp_s > 0.0
                                    ? config.max_damping_n_s_per_m * period_s / config.damping_ramp_s
                                    : config.max_damping_n_s_per_m;
    state.added_damping_n_s_per_m = slew(state.added_damping_n_s_per_m, damping_target, damping_step);
  }
  // g gives the force back at the base ramp (no click), and takes it off at the raise step.
  const double step_n = target > state.reduction_fraction ? raise_step_n : config.max_correction_step_n;
  const double max_fraction_step = std::min(1.0, step_n / std::max(force_n, config.max_correction_step_n));
  state.reduction_fraction = slew(state.reduction_fraction, target, max_fraction_step);
  // At (filtered) standstill β holds: the force does no work there.

  // Energy bounding at speed (passivity.hpp): the part of F along the motion may return at most
  // what is left of the budget once E and the command already sent (acting over the next
  // interval) are counted; the motion is the last raw difference (no filter lag: a teleported
  // hand reads 1.7 m/s raw while v_f still says 0.2 m/s) or v_f, whichever returns more.
  // Gated by the raw speed, so it never acts at a hold; it may step the force.
  if (config.energy_bounding && force_n > 0.0 && v_raw_m_per_s.norm() >= bounding_speed_m_per_s(period_s)) {
    const double returning_m_per_s =
        std::max(force_direction.dot(v_raw_m_per_s), force_direction.dot(v_filtered_m_per_s));
    if (returning_m_per_s > 0.0) {
      const Eigen::Vector3d& sent = state.force_sent_last_device_n;
      const double committed_j = state.energy_j - forgiven_j(state, config.margin_j) +
                                 std::max(sent.dot(v_raw_m_per_s), sent.dot(v_filtered_m_per_s)) * period_s;
      const double allowed_n = std::max(0.0, budget_j - committed_j) / (returning_m_per_s * period_s);
      const double bound_fraction = std::clamp(1.0 - allowed_n / force_n, 0.0, 1.0);
      if (bound_fraction > state.reduction_fraction) {
        state.reduction_fraction = bound_fraction;
        state.energy_bound_acted = true;
        ++state.energy_bound_ticks;
      }
    }
  }

  // A fraction of F: the force is reduced, never reversed, and follows F continuously as the
  // contact comes and goes (the fraction persists across bounces).
  state.reduction_n = state.reduction_fraction * force_n;
  const Eigen::Vector3d correction = state.reduction_n * force_direction + state.added_damping_n_s_per_m * v;
  if (state.reduction_fraction <= 0.0 && state.added_damping_n_s_per_m <= 0.0) return force;
  state.damping_n_s_per_m = correction.norm() / std::max(speed, config.min_speed_m_per_s);
  state.dissipated_by_controller_j += correction.dot(v) * period_s;
  return force - correction;
}

void record_sent_force(PassivityState& state, const Eigen::Vector3d& force_device_n) noexcept {
  state.force_sent_last_device_n = force_device_n;
}

void open_stall_account(PassivityState& state) noexcept {
  state.stall_window_left_s = kPassivityStallAccountWindow_s;
}

void restart_observer(PassivityState& state) noexcept {
  close_recovery_window(state);  // a fault inside a window: that window's account closes here
  state.primed = false;
  state.recovery_window_left_s = kPassivityRecoveryWindow_s;
  state.force_sent_last_device_n.setZero();
  state.force_acting_device_n.setZero();
  state.reduction_fraction = 0.0;
  state.reduction_n = 0.0;
  state.added_damping_n_s_per_m = 0.0;
}

}  // namespace fissure::rt
