#include "fissure/rt_core/passivity.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include "fissure/rt_core/safety.hpp"
#include "fissure/rt_core/velocity_filter.hpp"

namespace fissure::rt {
namespace {

constexpr double kRate_hz = 1000.0;
constexpr double kPeriod_s = 1.0 / kRate_hz;
/// One encoder count of tool motion near the workspace centre (BRIEF §6: ≈ 0.05 mm).
constexpr double kCount_m = 50e-6;

double quantise(double x_m) { return kCount_m * std::round(x_m / kCount_m); }

TEST(PassivityObserver, PairsEachMotionWithTheForceThatWasActingDuringIt) {
  PassivityState state;
  // Tick 0: first sample, nothing to account. The loop sends F0 = (1, 0, 0).
  observe_energy(state, Eigen::Vector3d(0.0, 0.0, 0.0));
  record_sent_force(state, Eigen::Vector3d(1.0, 0.0, 0.0));
  // Tick 1: motion 0→1 mm happened under the force sent before tick 0 (zero).
  observe_energy(state, Eigen::Vector3d(1e-3, 0.0, 0.0));
  EXPECT_DOUBLE_EQ(state.energy_j, 0.0);
  record_sent_force(state, Eigen::Vector3d(2.0, 0.0, 0.0));
  // Tick 2: motion 1→3 mm happened under F0 = 1 N (sent with exchange 1).
  observe_energy(state, Eigen::Vector3d(3e-3, 0.0, 0.0));
  EXPECT_DOUBLE_EQ(state.energy_j, 2e-3);
  record_sent_force(state, Eigen::Vector3d::Zero());
  // Tick 3: motion 3→2 mm under F1 = 2 N: −2 mJ.
  observe_energy(state, Eigen::Vector3d(2e-3, 0.0, 0.0));
  EXPECT_NEAR(state.energy_j, 0.0, 1e-18);
}

TEST(PassivityController, RampsTheReductionAlongTheForceInsteadOfSteppingIt) {
  PassivityConfig config;
  config.device_damping_n_s_per_m = 0.0;  // the ramp alone (the damper's credit: below)
  PassivityState state;
  state.energy_j = 1e-4;                                        // already +0.1 mJ generated
  state.force_sent_last_device_n = Eigen::Vector3d(3.0, 0, 0);  // acting now
  const Eigen::Vector3d v(0.1, 0.0, 0.0);                       // the wall pushes the hand out: returning energy
  const Eigen::Vector3d f(3.0, 0.0, 0.0);
  // Nothing stored (U = 0): the debt is E, 0.5 mJ above the reference −margin. A one-tick
  // controller (plain Hannaford–Ryu) would remove the whole 3 N push in this one tick.
  const double debt_excess_j = 1e-4 + config.margin_j;
  // The share of F that withholds that within dissipation_time_s: 0.5e-3/(0.05·0.1·3) = 3.3 %.
  const double target_fraction = debt_excess_j / (config.dissipation_time_s * v.x() * f.x());
  // The ramp's urgency grows with the predicted E' = 1e-4 + 6·0.1·1e-3 = 0.7 mJ.
  const double predicted_j = 7e-4;
  const double urgency = 1.0 + predicted_j / (kPassivityUrgencyMargins * config.margin_j);
  // …or, if larger, the step that takes the 3 N off before the 0.3 W it pushes out with has
  // returned kPassivityRampEnergyBudgetMargins margins: 0.3·1e-3·3/(2·4e-3) = 0.11 N.
  const double energy_bounded_step_n =
      0.1 * 3.0 * kPeriod_s * 3.0 / (2.0 * kPassivityRampEnergyBudgetMargins * config.margin_j);
  const double first_step_n = std::max(config.max_correction_step_n * urgency, energy_bounded_step_n);
  EXPECT_LT(first_step_n, 0.15);  // still a ramp: a one-tick controller removes all 3 N at once
  const double damping_step = config.max_damping_n_s_per_m * kPeriod_s / config.damping_ramp_s;
  const Eigen::Vector3d out = passivity_control(config, state, f, v, v, kPeriod_s);
  EXPECT_NEAR(state.reduction_n, std::min(first_step_n, target_fraction * f.x()), 1e-12);
  EXPECT_NEAR(state.added_damping_n_s_per_m, damping_step, 1e-12);
  EXPECT_NEAR(out.x(), 3.0 - state.reduction_n - damping_step * 0.1, 1e-12);
  EXPECT_DOUBLE_EQ(out.y(), 0.0);
  EXPECT_GT(state.damping_n_s_per_m, 0.0);  // reported active (kFlagPassivityActive)
  // The reduction keeps growing while the debt stays the same, one bounded step a tick, up to
  // its target, never past it.
  for (int k = 0; k < 200; ++k) {
    const double before = state.reduction_n;
    passivity_control(config, state, f, v, v, kPeriod_s);
    EXPECT_LE(state.reduction_n - before, first_step_n + 1e-12);  // the power only falls as g grows
  }
  EXPECT_NEAR(state.reduction_fraction, target_fraction, 1e-12);
  // β: the damping that dissipates E' + margin within dissipation_time_s at this speed.
  EXPECT_NEAR(state.added_damping_n_s_per_m,
              std::min(config.max_damping_n_s_per_m, (predicted_j + config.margin_j) / (config.dissipation_time_s * 0.01)),
              1e-12);
}

// The reduction's reference follows what the environment stores: a wall pressed 2 mm (U = 3 mJ)
// whose observer says E = −2.8 mJ owes 0.2 mJ — the surplus of a sampled spring — and g acts
// on that alone; against the fixed reference −margin it would treat the whole E as owed.
TEST(PassivityController, TheDebtIsTheObservedEnergyPlusWhatTheEnvironmentStores) {
  PassivityConfig config;
  config.device_damping_n_s_per_m = 0.0;
  const Eigen::Vector3d f(3.0, 0.0, 0.0);
  const Eigen::Vector3d v(0.02, 0.0, 0.0);  // returning, slowly
  const double stored_j = 0.5 * 3.0 * 2e-3;
  PassivityState owed;
  owed.energy_j = -2.8e-3;
  owed.force_sent_last_device_n = f;
  for (int k = 0; k < 300; ++k) passivity_control(config, owed, f, v, v, kPeriod_s, stored_j);
  const double debt_excess_j = -2.8e-3 + stored_j + config.margin_j;
  EXPECT_NEAR(owed.reduction_fraction, debt_excess_j / (config.dissipation_time_s * v.x() * f.x()), 1e-12);
  // The same E with less stored (1 mm: 1.5 mJ) is below the reference: nothing owed.
  PassivityState paid;
  paid.energy_j = -2.8e-3;
  paid.force_sent_last_device_n = f;
  EXPECT_EQ(passivity_control(config, paid, f, v, v, kPeriod_s, 0.5 * 3.0 * 1e-3), f);
  EXPECT_EQ(paid.reduction_fraction, 0.0);
}

// The device's own damper dissipates b·|v|²·T whatever the controller does: g counts that
// against the debt (up to kPassivityMaxDampingCredit_j), so a wall that returned a little more
// than it stored during an impact the damper has already absorbed is not held back afterwards.
TEST(PassivityController, CountsTheDevicesOwnDampingAgainstTheDebtUpToACap) {
  const PassivityConfig config;  // b = 3 N·s/m
  const Eigen::Vector3d f(2.0, 0.0, 0.0);
  PassivityState state;
  state.energy_j = 2e-3;  // 2 mJ owed (U = 0)
  state.force_sent_last_device_n = f;
  // 0.2 m/s in contact for 20 ticks: 3·0.04·1e-3 = 0.12 mJ per tick, 2.4 mJ in all.
  const Eigen::Vector3d in(-0.2, 0.0, 0.0);
  for (int k = 0; k < 20; ++k) passivity_control(config, state, f, in, in, kPeriod_s);
  EXPECT_NEAR(state.damping_credit_j, 20 * 3.0 * 0.04 * kPeriod_s, 1e-12);
  // Paid: moving out, g stays at 0 (the damper β still acts on all of E: it is the one that
  // drains what the observer reports).
  const Eigen::Vector3d out(0.01, 0.0, 0.0);
  const Eigen::Vector3d rendered = passivity_control(config, state, f, out, out, kPeriod_s);
  EXPECT_EQ(state.reduction_fraction, 0.0);
  EXPECT_NEAR(rendered.x(), f.x() - state.added_damping_n_s_per_m * out.x(), 1e-12);
  // The credit never exceeds the cap, and out of contact never what is still owed.
  for (int k = 0; k < 10000; ++k) passivity_control(config, state, f, in, in, kPeriod_s);
  EXPECT_EQ(state.damping_credit_j, kPassivityMaxDampingCredit_j);
  passivity_control(config, state, Eigen::Vector3d::Zero(), in, in, kPeriod_s);
  EXPECT_NEAR(state.damping_credit_j, state.energy_j + config.margin_j, 1e-15);
}

TEST(PassivityController, HoldsTheReductionWhileInExcessAndTheHandPushesIn) {
  PassivityConfig config;
  PassivityState state;
  state.reduction_fraction = 0.3;
  state.energy_j = 5e-3;  // well above zero
  const Eigen::Vector3d f(2.0, 0.0, 0.0);
  const Eigen::Vector3d in(-0.05, 0.0, 0.0);
  // Giving the force back while pressed in would store energy the wall returns later.
  const Eigen::Vector3d out = passivity_control(config, state, f, in, in, kPeriod_s);
  EXPECT_DOUBLE_EQ(state.reduction_fraction, 0.3);
  EXPECT_NEAR(out.x(), 0.7 * 2.0 - state.added_damping_n_s_per_m * in.x(), 1e-12);
  // Out of contact the fraction persists (a bouncing contact comes back reduced) and the
  // force stays zero apart from the damper: nothing to reduce.
  const Eigen::Vector3d free = passivity_control(config, state, Eigen::Vector3d::Zero(), in, in, kPeriod_s);
  EXPECT_DOUBLE_EQ(state.reduction_fraction, 0.3);
  EXPECT_NEAR(free.x(), -state.added_damping_n_s_per_m * in.x(), 1e-12);
}

/// A hand resting on a 500 N/m wall 10 mm deep (5 N, U = 25 mJ) that it never paid for — pressed
/// in while the loop stalled — buzzing by ±1 count per tick at the rest (v_f ±5 mm/s, v_raw ±50 mm/s),
/// then leaving at 0.1 m/s. E two margins below the reference at the start: the debt is U less that.
struct StallRest {
  static constexpr double kStiffness_n_per_m = 500.0;
  static constexpr double kDepth_m = 0.01;
  PassivityConfig config;
  PassivityState state;
  StallRest() { state.energy_j = -2.0 * config.margin_j; }
  double y_m = 0.0;  // outward along the force (+y): the depth is kDepth_m − y_m
  Eigen::Vector3d out = Eigen::Vector3d::Zero();

  /// One tick with the hand at y_m, moving at v (filtered) / v_raw along +y.
  void tick(double v_f, double v_raw) {
    const Eigen::Vector3d p(0.0, y_m, 0.0);
    observe_energy(state, p);
    const double x = std::max(0.0, kDepth_m - y_m);
    const Eigen::Vector3d f(0.0, kStiffness_n_per_m * x, 0.0);
    out = passivity_control(config, state, f, Eigen::Vector3d(0.0, v_f, 0.0), Eigen::Vector3d(0.0, v_raw, 0.0),
                            kPeriod_s, 0.5 * kStiffness_n_per_m * x * x);
    record_sent_force(state, out);
  }
  /// 300 ticks of the rest buzz; returns the smallest force rendered.
  double rest() {
    double least_n = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 300; ++k) {
      const double sign = (k % 2 == 0) ? 1.0 : -1.0;
      y_m = (k % 2 == 0) ? kCount_m : 0.0;
      tick(sign * 5e-3, sign * 0.05);
      least_n = std::min(least_n, out.y());
    }
    return least_n;
  }
};

TEST(PassivityController, AStallsDebtIsNotWithheldAtTheRest) {
  // The stall account (open_stall_account at the history break) holds the debt: the rest keeps the
  // whole wall, buzz and all — the wall's own force at every tick (5 N less one count's 0.025 N).
  StallRest after_stall;
  open_stall_account(after_stall.state);
  EXPECT_NEAR(after_stall.rest(), StallRest::kStiffness_n_per_m * (StallRest::kDepth_m - kCount_m), 1e-12);
  EXPECT_EQ(after_stall.state.reduction_fraction, 0.0);
  EXPECT_GT(after_stall.state.stall_debt_j, 0.02);
  // The same debt without a stall (sampled-data activity of the loop) is withheld on the buzz's
  // outward strokes and held: the wall is held back.
  StallRest loop_debt;
  EXPECT_LT(loop_debt.rest(), 0.5 * StallRest::kStiffness_n_per_m * StallRest::kDepth_m);
  EXPECT_GT(loop_debt.state.reduction_fraction, 0.5);
}

TEST(PassivityController, AStallsDebtIsCollectedOnTheWayOutOfTheRest) {
  StallRest s;
  open_stall_account(s.state);
  s.rest();
  const double energy_at_rest_j = s.state.energy_j;
  // Leaving at 0.1 m/s until the wall is gone (100 ticks) and 50 more.
  double most_withheld = 0.0;
  for (int k = 0; k < 150; ++k) {
    s.y_m += 0.1 * kPeriod_s;
    s.tick(0.1, 0.1);
    most_withheld = std::max(most_withheld, s.state.reduction_fraction);
  }
  // Rendered in full the wall returns its 25 mJ; with the account collected on the way out what
  // reaches the hand is what it returns before the hand is kPassivityExitGate_m out of the rest
  // (≤ 5 N × 0.2 mm = 1 mJ) and while g ramps in within the ramp's energy budget (4 mJ).
  const double returned_j = s.state.energy_j - energy_at_rest_j;
  EXPECT_LT(returned_j, 5.0 * kPassivityExitGate_m + kPassivityRampEnergyBudgetMargins * kDefaultPassivityMargin_j);
  EXPECT_GT(most_withheld, 0.9);
  EXPECT_EQ(s.state.stall_debt_j, 0.0);  // U is gone: nothing left to collect from this contact
}

TEST(PassivityController, GivesTheForceBackGraduallyOnceTheEnergyIsBelowTheReference) {
  PassivityConfig config;
  PassivityState state;
  state.reduction_fraction = 0.5;
  state.added_damping_n_s_per_m = config.max_damping_n_s_per_m;
  state.energy_j = -1e-2;  // far below −margin: passive with reserve
  const Eigen::Vector3d f(2.0, 0.0, 0.0);
  const Eigen::Vector3d v(0.05, 0.0, 0.0);
  passivity_control(config, state, f, v, v, kPeriod_s);
  // 0.05 N of the 2 N per tick: 2.5 % of F.
  EXPECT_NEAR(state.reduction_fraction, 0.5 - config.max_correction_step_n / f.x(), 1e-12);
  EXPECT_LT(state.added_damping_n_s_per_m, config.max_damping_n_s_per_m);
  for (int k = 0; k < 100; ++k) passivity_control(config, state, f, v, v, kPeriod_s);
  EXPECT_EQ(state.reduction_fraction, 0.0);
  EXPECT_EQ(state.added_damping_n_s_per_m, 0.0);
  EXPECT_EQ(passivity_control(config, state, f, v, v, kPeriod_s), f);
  EXPECT_EQ(state.damping_n_s_per_m, 0.0);
}

TEST(PassivityController, UsesWhicheverVelocityPredictsMoreEnergyOut) {
  PassivityConfig config;
  PassivityState state;
  const Eigen::Vector3d f(1.0, 0.0, 0.0);
  // Filtered velocity still says "pressing in" (slowly), the raw difference already says
  // "rebounding": E' = (1·0.4)·1e-3 = 0.4 mJ > −margin ⇒ the damper starts.
  passivity_control(config, state, f, Eigen::Vector3d(-0.005, 0, 0), Eigen::Vector3d(0.4, 0, 0), kPeriod_s);
  EXPECT_GT(state.added_damping_n_s_per_m, 0.0);
  // The same with both estimates pressing in: nothing to do.
  PassivityState quiet;
  quiet.energy_j = -1e-3;
  EXPECT_EQ(passivity_control(config, quiet, f, Eigen::Vector3d(-0.005, 0, 0), Eigen::Vector3d(-0.05, 0, 0), kPeriod_s),
            f);
}

TEST(PassivityController, NothingWhenPassiveSlowOrDisabled) {
  PassivityConfig config;
  PassivityState state;
  const Eigen::Vector3d f(1.0, 2.0, 3.0);
  const Eigen::Vector3d v(0.1, 0, 0);
  state.energy_j = -1.0;  // passive so far, with a large reserve
  EXPECT_EQ(passivity_control(config, state, f, v, v, kPeriod_s), f);
  state.energy_j = 1.0;   // active, but below the minimum speed: v's direction is noise
  EXPECT_EQ(passivity_control(config, state, f, Eigen::Vector3d(1e-4, 0, 0), Eigen::Vector3d(1e-4, 0, 0), kPeriod_s), f);
  config.enabled = false;
  EXPECT_EQ(passivity_control(config, state, f, v, v, kPeriod_s), f);
  EXPECT_EQ(state.reduction_fraction, 0.0);
}

// A force pushing the hand out fast (8 N at 0.5 m/s: 4 mJ per tick, a flick bouncing off the
// contact or a swap offset from a contact the host has lost) is taken off within a few ticks:
// the energy returned while the reduction ramps in stays within the ramp's energy budget.
// With only the urgency factor it took 0.05–0.3 N per tick and returned ≈ 0.1 J
// (hc_lambda_over_k_0 stress case).
TEST(PassivityController, TakesOffAForcePushingOutFastWithinTheRampEnergyBudget) {
  PassivityConfig config;
  PassivityState state;
  const Eigen::Vector3d f(0.0, 8.0, 0.0);
  const Eigen::Vector3d v(0.0, 0.5, 0.0);
  state.energy_j = 0.0;
  state.force_sent_last_device_n = f;
  double returned_j = 0.0;
  int ticks = 0;
  for (; ticks < 100; ++ticks) {
    const Eigen::Vector3d out = passivity_control(config, state, f, v, v, kPeriod_s);
    const double push_n = std::max(0.0, out.y());
    if (push_n <= 0.0) break;
    returned_j += push_n * v.y() * kPeriod_s;
    state.energy_j += push_n * v.y() * kPeriod_s;
    state.force_sent_last_device_n = out;
  }
  EXPECT_LE(ticks, 3);  // 4 N per tick: P·T·|F|/(2·budget) = 4 W · 1 ms · 8 N / 8 mJ
  EXPECT_LE(returned_j, kPassivityRampEnergyBudgetMargins * config.margin_j);
}

// Once the loop has generated more than the ramp's energy budget (10 margins) the push comes
// off entirely (ramped), not just the share that withholds the excess.
TEST(PassivityController, CutsThePushEntirelyOnceTheEnergyIsBeyondTheBudget) {
  PassivityConfig config;
  PassivityState state;
  state.energy_j = 5e-3;  // > 4 mJ
  const Eigen::Vector3d f(2.0, 0.0, 0.0);
  const Eigen::Vector3d v(0.02, 0.0, 0.0);
  state.force_sent_last_device_n = f;
  for (int k = 0; k < 100; ++k) passivity_control(config, state, f, v, v, kPeriod_s);
  EXPECT_EQ(state.reduction_fraction, 1.0);
  PassivityState below;
  below.energy_j = 1e-3;
  below.force_sent_last_device_n = f;
  for (int k = 0; k < 100; ++k) passivity_control(config, below, f, v, v, kPeriod_s);
  EXPECT_LT(below.reduction_fraction, 1.0);
  EXPECT_GT(below.reduction_fraction, 0.0);
}

// At a hold (a few N, v_f of a few mm/s) the energy bound is far below the base ramp: the
// correction still moves by max_correction_step_n (× urgency) per tick, no more.
TEST(PassivityController, KeepsTheBaseRampAtAHold) {
  PassivityConfig config;
  PassivityState state;
  state.energy_j = 0.0;
  const Eigen::Vector3d f(3.0, 0.0, 0.0);
  const Eigen::Vector3d v(0.003, 0.0, 0.0);
  state.force_sent_last_device_n = f;
  passivity_control(config, state, f, v, v, kPeriod_s);
  // E' less the device damper's credit for this tick (b·|v|²·T).
  const double predicted_j = 6.0 * 0.003 * kPeriod_s - config.device_damping_n_s_per_m * 0.003 * 0.003 * kPeriod_s;
  const double urgency = 1.0 + predicted_j / (kPassivityUrgencyMargins * config.margin_j);
  EXPECT_NEAR(state.reduction_n, config.max_correction_step_n * urgency, 1e-12);
}

// Work done while safety ramps the force back in after a device fault is energy the device put
// into the hand like any other. Up to kPassivityRecoveryForgiveness_j per fault (bringing a
// force back at a static hold) the reduction g ignores it and only the damper β acts (the
// wall is not held soft while the hand holds still); beyond that g acts as well. With g
// ignoring all of it nothing takes it back: the stress harness's encoder_jumps case gains
// ≈ 5 mJ per injected fault, 4.7 J over 10⁶ ticks.
TEST(PassivityController, ForgivesABoundedShareOfTheRecoveryWorkForTheReductionOnly) {
  PassivityConfig config;
  const Eigen::Vector3d f(2.0, 0.0, 0.0);
  const Eigen::Vector3d v(0.05, 0.0, 0.0);
  auto after_recovery_work = [&](double work_j) {
    PassivityState state;
    restart_observer(state);
    observe_energy(state, Eigen::Vector3d::Zero());
    record_sent_force(state, Eigen::Vector3d(1.0, 0.0, 0.0));
    observe_energy(state, Eigen::Vector3d::Zero());
    observe_energy(state, Eigen::Vector3d(work_j, 0.0, 0.0));  // 1 N over work_j metres
    EXPECT_DOUBLE_EQ(state.energy_j, work_j);
    passivity_control(config, state, f, v, v, kPeriod_s);
    return state;
  };
  // Baseline: the same tick with no recovery work at all (E = 0).
  PassivityState fresh;
  fresh.force_sent_last_device_n = Eigen::Vector3d(1.0, 0.0, 0.0);
  passivity_control(config, fresh, f, v, v, kPeriod_s);
  const PassivityState small = after_recovery_work(1.4e-3);  // a force brought back at a hold
  EXPECT_DOUBLE_EQ(small.reduction_fraction, fresh.reduction_fraction);  // g: as if it had not happened
  EXPECT_GT(small.added_damping_n_s_per_m, fresh.added_damping_n_s_per_m - 1e-15);
  const PassivityState large = after_recovery_work(2e-2);  // a wall rendered at a false position
  EXPECT_GT(large.reduction_fraction, 2.0 * fresh.reduction_fraction);
  EXPECT_GT(large.added_damping_n_s_per_m, 0.0);
}

// The forgiven share is per window: it is fixed when the window closes (or a new fault opens
// the next one), and never more than kPassivityRecoveryForgiveness_j per fault.
TEST(PassivityController, ForgivenessIsBoundedPerFaultWindow) {
  PassivityState state;
  for (int fault = 0; fault < 3; ++fault) {
    restart_observer(state);
    observe_energy(state, Eigen::Vector3d::Zero());
    record_sent_force(state, Eigen::Vector3d(1.0, 0.0, 0.0));
    observe_energy(state, Eigen::Vector3d::Zero());
    observe_energy(state, Eigen::Vector3d(1e-2, 0.0, 0.0));  // 10 mJ in this window
  }
  restart_observer(state);
  EXPECT_NEAR(state.recovery_forgiven_j, 3.0 * kPassivityRecoveryForgiveness_j, 1e-15);
  EXPECT_NEAR(state.recovery_energy_j, 3e-2, 1e-15);
  // Once that energy has been dissipated (E back at the reference) nothing is owed any more:
  // g acts on later energy in full (the forgiveness of past faults does not pile up).
  state.energy_j = -PassivityConfig{}.margin_j;
  passivity_control(PassivityConfig{}, state, Eigen::Vector3d(1.0, 0, 0), Eigen::Vector3d(0.01, 0, 0),
                    Eigen::Vector3d(0.01, 0, 0), kPeriod_s);
  EXPECT_EQ(state.recovery_forgiven_j, 0.0);
}

TEST(PassivityController, RestartDropsTheCorrection) {
  PassivityState state;
  state.reduction_fraction = 0.5;
  state.reduction_n = 2.0;
  state.added_damping_n_s_per_m = 1.0;
  state.energy_j = 3e-3;
  restart_observer(state);
  EXPECT_EQ(state.reduction_fraction, 0.0);
  EXPECT_EQ(state.reduction_n, 0.0);
  EXPECT_EQ(state.added_damping_n_s_per_m, 0.0);
  EXPECT_EQ(state.energy_j, 3e-3);  // the total is kept
  // Work in the recovery window is counted, and attributed to the fault.
  observe_energy(state, Eigen::Vector3d::Zero());
  record_sent_force(state, Eigen::Vector3d(1.0, 0.0, 0.0));
  observe_energy(state, Eigen::Vector3d::Zero());
  observe_energy(state, Eigen::Vector3d(1e-3, 0.0, 0.0));
  EXPECT_DOUBLE_EQ(state.energy_j, 3e-3 + 1e-3);
  EXPECT_DOUBLE_EQ(state.recovery_energy_j, 1e-3);
  // The window closes after kPassivityRecoveryWindow_s of controller ticks.
  const PassivityConfig config;
  for (int k = 0; k < static_cast<int>(kPassivityRecoveryWindow_s / kPeriod_s) + 1; ++k) {
    passivity_control(config, state, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), kPeriod_s);
  }
  EXPECT_EQ(state.recovery_window_left_s, 0.0);
  observe_energy(state, Eigen::Vector3d(2e-3, 0.0, 0.0));
  EXPECT_DOUBLE_EQ(state.recovery_energy_j, 1e-3);
}

// The controller works on the force the device renders (clamped to max_force_n), not on an
// environment force safety will clamp afterwards: against a 27 N contact (rendered at 8 N) its
// first reduction already lowers what goes out. Acting on the 27 N, the first 70 % of the
// reduction would leave 8 N going out (hc_lambda_over_k_1 stress case).
TEST(PassivityController, ReducesTheForceTheDeviceRendersNotTheUnclampedOne) {
  PassivityConfig config;
  PassivityState state;
  state.energy_j = 2e-3;  // above the reference: the controller has work to do
  state.reduction_fraction = 0.2;
  const Eigen::Vector3d f(0.0, -27.0, 0.0);  // far above the Falcon's 8 N
  state.force_sent_last_device_n = Eigen::Vector3d(0.0, -8.0, 0.0);
  const Eigen::Vector3d v(0.0, -0.01, 0.0);  // slowly along the force: below the bound's gate
  const Eigen::Vector3d out = passivity_control(config, state, f, v, v, kPeriod_s);
  // g (≥ 0.2) of the 8 N that can go out is taken off: at most 6.4 N (+ the damper) remain.
  EXPECT_GE(state.reduction_fraction, 0.2);
  EXPECT_NEAR(state.reduction_n, state.reduction_fraction * config.max_force_n, 1e-12);
  EXPECT_LE(out.norm(), (1.0 - 0.2) * config.max_force_n + 1e-9);
  EXPECT_FALSE(state.energy_bound_acted);
  // Passive with a reserve: nothing to correct, the force goes out as the device renders it.
  PassivityState passive;
  passive.energy_j = -1.0;
  EXPECT_TRUE(passivity_control(config, passive, f, v, v, kPeriod_s).isApprox(Eigen::Vector3d(0.0, -8.0, 0.0)));
}

// Energy bounding at speed (Kim & Ryu): the force this tick acts over the interval after the
// next one; what it can return there at the current speed, on top of E and of what the
// command already sent returns over the next interval, stays within the ramp's energy budget.
// v_raw says 0.55 m/s (the filtered estimate still 0.08 m/s: its lag is what let the ramps
// act too late), 8 N push along the motion, 8 N already sent.
TEST(PassivityController, BoundsTheForceSoThatTheNextIntervalStaysWithinTheBudget) {
  const PassivityConfig config;
  const double budget_j = kPassivityRampEnergyBudgetMargins * config.margin_j;
  const Eigen::Vector3d f(8.0, 0.0, 0.0);
  const Eigen::Vector3d v_raw(0.55, 0.0, 0.0);
  const Eigen::Vector3d v_f(0.08, 0.0, 0.0);
  auto run = [&](double energy_j) {
    PassivityState state;
    state.energy_j = energy_j;
    state.force_sent_last_device_n = f;
    const Eigen::Vector3d out = passivity_control(config, state, f, v_f, v_raw, kPeriod_s);
    return std::pair{state, out};
  };
  // E = −3 mJ: the sent 8 N returns 4.4 mJ over the next interval, 2.6 mJ of the budget are
  // left, so this tick's force may push the hand out with 2.6 mJ / (0.55 m/s · 1 ms) = 4.73 N.
  {
    const auto [state, out] = run(-3e-3);
    const double allowed_n = (budget_j - (-3e-3 + 8.0 * 0.55 * kPeriod_s)) / (0.55 * kPeriod_s);
    EXPECT_TRUE(state.energy_bound_acted);
    EXPECT_NEAR(state.reduction_fraction, 1.0 - allowed_n / 8.0, 1e-12);
    EXPECT_NEAR(out.x() + state.added_damping_n_s_per_m * v_f.x(), allowed_n, 1e-9);
    EXPECT_LE(-3e-3 + (8.0 + out.x()) * 0.55 * kPeriod_s, budget_j + 1e-12);  // the bound holds
  }
  // E = +1 mJ: the command already sent uses up the budget; nothing may push out any more —
  // a step from 8 N to ≤ 0 (safety's rate limit then takes it down at 4 N per tick).
  {
    const auto [state, out] = run(1e-3);
    EXPECT_TRUE(state.energy_bound_acted);
    EXPECT_EQ(state.reduction_fraction, 1.0);
    EXPECT_LE(out.x(), 0.0);
  }
  // E = −10 mJ: enough reserve for the full 8 N over both intervals: the bound does nothing.
  {
    const auto [state, out] = run(-10e-3);
    EXPECT_FALSE(state.energy_bound_acted);
    EXPECT_EQ(state.reduction_fraction, 0.0);
    EXPECT_EQ(out, f);
  }
  // Moving into the force (the hand presses in): nothing is returned, nothing to bound.
  {
    PassivityState state;
    state.energy_j = 1e-3;
    state.force_sent_last_device_n = f;
    passivity_control(config, state, f, -v_f, -v_raw, kPeriod_s);
    EXPECT_FALSE(state.energy_bound_acted);
  }
}

// The bound is gated by the raw speed, so it never steps the force at a hold: there the raw
// difference toggles by one encoder count per tick (50 mm/s at 1 kHz, 0.2 m/s at 4 kHz) and
// only the ramps act, even with E at the budget.
TEST(PassivityController, TheEnergyBoundNeverActsAtAHold) {
  const PassivityConfig config;
  for (const double rate_hz : {250.0, 500.0, 1000.0, 4000.0}) {
    const double period_s = 1.0 / rate_hz;
    PassivityState state;
    state.energy_j = kPassivityRampEnergyBudgetMargins * config.margin_j;  // at the budget
    const Eigen::Vector3d f(0.0, 0.0, 8.0);
    state.force_sent_last_device_n = f;
    const Eigen::Vector3d one_count(0.0, 0.0, kCount_m / period_s);  // quantisation toggle, outwards
    const Eigen::Vector3d tremor(0.0, 0.0, 0.005);
    const double before_n = state.reduction_n;
    passivity_control(config, state, f, tremor, one_count, period_s);
    EXPECT_FALSE(state.energy_bound_acted) << rate_hz << " Hz";
    EXPECT_LE(state.reduction_n - before_n, config.max_correction_step_n * kPassivityMaxUrgency + 1e-12) << rate_hz;
    // Four counts per tick at 1 kHz (0.2 m/s) is not a hold: there it acts.
    if (rate_hz == 1000.0) {
      PassivityState fast = PassivityState{};
      fast.energy_j = state.energy_j;
      fast.force_sent_last_device_n = f;
      passivity_control(config, fast, f, tremor, Eigen::Vector3d(0.0, 0.0, kPassivityBoundingMinSpeed_m_per_s), period_s);
      EXPECT_TRUE(fast.energy_bound_acted);
    }
  }
}

// ----------------------------------------------------------------------------------------
// Closed loops in one dimension (x along the wall normal): the tick's order — observe the
// quantised sample, filter the velocity, compute the wall force, passivity control, record —
// against a point mass whose force is the command computed one tick earlier (the Falcon's
// ping-pong: computed in tick k, acts from exchange k+1 to k+2).

struct Plant {
  double mass_kg = 0.15;            ///< SimFalcon's nominal effective mass
  double damping_n_s_per_m = 3.0;   ///< SimFalcon's nominal mechanism damping
  double hand_stiffness_n_per_m = 300.0;
  double hand_damping_n_s_per_m = 5.0;
  double x_m = 0.0, v_m_per_s = 0.0;
  /// Semi-implicit Euler at 20 kHz over one tick, motor force held (zero-order hold).
  /// The hand is a spring-damper to a target moving at hand_target_m_per_s.
  void advance(double motor_force_n, double hand_target_m, double period_s, double hand_target_m_per_s = 0.0) {
    constexpr int kSubsteps = 20;
    const double dt = period_s / kSubsteps;
    for (int i = 0; i < kSubsteps; ++i) {
      const double hand = hand_stiffness_n_per_m * (hand_target_m - x_m) +
                          hand_damping_n_s_per_m * (hand_target_m_per_s - v_m_per_s);
      v_m_per_s += dt * (motor_force_n + hand - damping_n_s_per_m * v_m_per_s) / mass_kg;
      x_m += dt * v_m_per_s;
    }
  }
};

struct LoopResult {
  double max_correction_step_n = 0.0;  ///< largest per-tick change of (F_out − F_wall) while active
  double max_output_step_n = 0.0;      ///< largest per-tick change of F_out
  int active_ticks = 0;
  double energy_end_j = 0.0;
  double energy_max_j = 0.0;
  double energy_at_two_thirds_j = 0.0;
};

/// A wall at x = 0 (force +stiffness·(−x) for x < 0), the hand pulling towards
/// hand_target(t). `modulation(t)` scales the wall force, standing in for a host whose force
/// varies on its own (it generates energy the wall's spring never stored).
template <typename HandTarget, typename Modulation>
LoopResult run_wall(const PassivityConfig& config, double stiffness_n_per_m, Plant plant, double seconds,
                    HandTarget hand_target, Modulation modulation) {
  const VelocityFilterCoefficients filter = design_velocity_filter(100.0, kRate_hz);
  VelocityFilterState velocity;
  PassivityState state;
  LoopResult result;
  double acting_n = 0.0;  // computed last tick, acts during the coming interval
  double last_out_n = 0.0, last_correction_n = 0.0;
  const int ticks = static_cast<int>(seconds * kRate_hz);
  for (int k = 0; k < ticks; ++k) {
    const double t_s = k * kPeriod_s;
    const Eigen::Vector3d p(quantise(plant.x_m), 0.0, 0.0);
    const Eigen::Vector3d raw = velocity.primed ? Eigen::Vector3d((p - velocity.p_prev_device_m) / kPeriod_s)
                                                : Eigen::Vector3d::Zero();
    observe_energy(state, p);
    const Eigen::Vector3d v = update_velocity(filter, velocity, p, kPeriod_s);
    const double depth_m = std::max(0.0, -p.x());
    const double wall_n = modulation(t_s) * stiffness_n_per_m * depth_m;
    const Eigen::Vector3d f(wall_n, 0.0, 0.0);
    const double stored_j = 0.5 * wall_n * depth_m;  // what the (modulated) spring stores now
    const double out_n = passivity_control(config, state, f, v, raw, kPeriod_s, stored_j).x();
    const double correction_n = out_n - wall_n;
    if (state.damping_n_s_per_m > 0.0) {
      ++result.active_ticks;
      result.max_correction_step_n = std::max(result.max_correction_step_n, std::abs(correction_n - last_correction_n));
    }
    if (k > 0) result.max_output_step_n = std::max(result.max_output_step_n, std::abs(out_n - last_out_n));
    last_out_n = out_n;
    last_correction_n = correction_n;
    const double sent_n = std::clamp(out_n, -8.0, 8.0);  // safety's clamp (the Falcon's 8 N)
    record_sent_force(state, Eigen::Vector3d(sent_n, 0.0, 0.0));
    plant.advance(acting_n, hand_target(t_s), kPeriod_s);
    acting_n = sent_n;
    result.energy_max_j = std::max(result.energy_max_j, state.energy_j);
    if (k == 2 * ticks / 3) result.energy_at_two_thirds_j = state.energy_j;
  }
  result.energy_end_j = state.energy_j;
  return result;
}

// A stationary-ish hold: the hand presses 1 mm into a 3000 N/m wall (≈ 3 N) and trembles by
// ±30 µm at 8 Hz, so the encoder toggles between neighbouring counts; the host force varies
// by ±30 % at 7 Hz on its own — the situation of spatula-sphere's hold, where a one-tick
// controller cuts 2–4 N in one tick at every outward count (2.3 N steps at 1 kHz).
TEST(PassivityClosedLoop, QuantisedHoldAgainstAStiffProxyHasNoForceSteps) {
  PassivityConfig config;
  Plant plant;
  plant.x_m = -1e-3;
  const double k_wall = 3000.0;
  // The hand holds where the wall and its spring balance at 1 mm, plus a tremor.
  const double x_hold = -1e-3 - k_wall * 1e-3 / plant.hand_stiffness_n_per_m;
  auto hand = [&](double t) { return x_hold + 30e-6 * std::sin(2.0 * M_PI * 8.0 * t); };
  auto host = [](double t) { return 1.0 + 0.3 * std::sin(2.0 * M_PI * 7.0 * t); };
  const LoopResult r = run_wall(config, k_wall, plant, 3.0, hand, host);
  // It did have work to do…
  EXPECT_GT(r.active_ticks, 100);
  // …and every change it made to the force was a ramp step: 50 N/s·T times the urgency
  // factor (1 + E'/margin; E' stays below a few margins here), never the whole force.
  constexpr double kMaxCorrectionStep_n = 0.2;
  EXPECT_LE(r.max_correction_step_n, kMaxCorrectionStep_n);
  // The wall force's own steps are K·count = 0.15 N and its ±30 % modulation; the output
  // adds at most the correction's ramp.
  EXPECT_LE(r.max_output_step_n, k_wall * kCount_m + 0.05 + kMaxCorrectionStep_n);
}

// The same hold with the controller off generates energy without bound (the modulated host
// force, and the delayed spring at every toggle): what the test above holds down is real.
TEST(PassivityClosedLoop, TheQuantisedModulatedHoldIsActiveWithoutTheController) {
  PassivityConfig config;
  config.enabled = false;
  Plant plant;
  plant.x_m = -1e-3;
  const double k_wall = 3000.0;
  const double x_hold = -1e-3 - k_wall * 1e-3 / plant.hand_stiffness_n_per_m;
  auto hand = [&](double t) { return x_hold + 30e-6 * std::sin(2.0 * M_PI * 8.0 * t); };
  auto host = [](double t) { return 1.0 + 0.3 * std::sin(2.0 * M_PI * 7.0 * t); };
  const LoopResult r = run_wall(config, k_wall, plant, 3.0, hand, host);
  EXPECT_GT(r.energy_end_j, 4.0 * PassivityConfig{}.margin_j);
}

// A wall far beyond the Z-width (20 000 N/m at 1 kHz behind a two-tick delay, with only the
// mechanism's damping and a loose hand): without the controller it buzzes and keeps
// generating energy; with it the observed energy ends bounded and stops growing.
TEST(PassivityClosedLoop, AnActiveWallEndsWithBoundedObservedEnergy) {
  Plant plant;
  plant.hand_stiffness_n_per_m = 100.0;
  plant.hand_damping_n_s_per_m = 0.0;
  plant.x_m = 0.002;
  const double k_wall = 20000.0;
  auto hand = [](double) { return -0.02; };  // presses: 2 N on the hand spring at the wall
  auto constant = [](double) { return 1.0; };
  PassivityConfig off;
  off.enabled = false;
  const LoopResult without = run_wall(off, k_wall, plant, 3.0, hand, constant);
  EXPECT_GT(without.energy_end_j, 0.2) << "the uncontrolled wall should be clearly active";
  EXPECT_GT(without.energy_end_j, 1.2 * without.energy_at_two_thirds_j) << "and keep growing";

  const LoopResult with = run_wall(PassivityConfig{}, k_wall, plant, 3.0, hand, constant);
  // Bounded below the stress harness's 25 mJ… (the wall is ~6× beyond its Z-width: the
  // controller ends up rendering a fraction of it, smoothly)
  EXPECT_LE(with.energy_max_j, 0.05);
  // Still creeping (the encoder toggling inside a 20 000 N/m wall), at a tenth of the
  // uncontrolled rate at most.
  EXPECT_LE(with.energy_end_j - with.energy_at_two_thirds_j,
            0.1 * (without.energy_end_j - without.energy_at_two_thirds_j));
  EXPECT_LT(with.energy_end_j, 0.25 * without.energy_end_j);
}

// ----------------------------------------------------------------------------------------
// The stress harness's hc_lambda_over_k_1 / hand_teleports failures, in one dimension: a hand
// presses 5 mm into a stiff, heavily damped Hunt-Crossley contact (5000 N/m, λ = 1 s/m: ~30 N,
// rendered at the Falcon's 8 N), the body then follows the tool out slowly (a host proxy that
// moves: the contact returns what it stored, so E climbs back to the reference at 8 N), and
// the hand flicks out at 5–10 m/s through its 300 N/m grip. The device leaves the contact at
// 1–2 m/s while the full 8 N pushes it out; both commands on their way through the ping-pong
// return that before any correction acts, and the ramps (≤ 2 N per tick) act from the tick
// after. Safety (8 N clamp, 4 N per tick rate limit) sits between the controller and the plant.
struct FlickResult {
  double energy_max_j = 0.0;
  std::uint64_t bound_ticks_before_flick = 0;  ///< the energy bound must not act before the flick
  double max_step_before_flick_n = 0.0;        ///< largest per-tick change of the sent force
};

FlickResult run_flick(const PassivityConfig& config, double follow_m, double flick_m_per_s) {
  constexpr double kStiffness_n_per_m = 5000.0, kLambda_s_per_m = 1.0;
  constexpr double kDepth_m = 0.005, kPressSpeed_m_per_s = 0.05, kFollowSpeed_m_per_s = 0.02;
  Plant plant;
  plant.x_m = 0.002;
  const double x_press = -kDepth_m - kFalconMaxForce_n / plant.hand_stiffness_n_per_m;  // holds 5 mm in at 8 N
  const double t_in = (plant.x_m - x_press) / kPressSpeed_m_per_s, t_hold = t_in + 0.2;
  const double t_flick = t_hold + follow_m / kFollowSpeed_m_per_s;
  const double x_out = 0.03, t_end = t_flick + (x_out - x_press - follow_m) / flick_m_per_s + 0.2;
  auto hand = [&](double t) {  // target position and velocity
    if (t < t_in) return std::pair{0.002 - kPressSpeed_m_per_s * t, -kPressSpeed_m_per_s};
    if (t < t_hold) return std::pair{x_press, 0.0};
    if (t < t_flick) return std::pair{x_press + kFollowSpeed_m_per_s * (t - t_hold), kFollowSpeed_m_per_s};
    const double x = x_press + follow_m + flick_m_per_s * (t - t_flick);
    return x < x_out ? std::pair{x, flick_m_per_s} : std::pair{x_out, 0.0};
  };
  auto surface = [&](double t) { return t < t_hold ? 0.0 : std::min(follow_m, kFollowSpeed_m_per_s * (t - t_hold)); };

  const VelocityFilterCoefficients filter = design_velocity_filter(100.0, kRate_hz);
  VelocityFilterState velocity;
  PassivityState state;
  SafetyConfig safety_config;
  SafetyState safety;
  start_ramp_in(safety, 0.0);  // ramped in already
  FlickResult result;
  double acting_n = 0.0, last_sent_n = 0.0;
  for (int k = 0; k * kPeriod_s < t_end; ++k) {
    const double t_s = k * kPeriod_s;
    const Eigen::Vector3d p(quantise(plant.x_m), 0.0, 0.0);
    const Eigen::Vector3d raw = velocity.primed ? Eigen::Vector3d((p - velocity.p_prev_device_m) / kPeriod_s)
                                                : Eigen::Vector3d::Zero();
    observe_energy(state, p);
    const Eigen::Vector3d v = update_velocity(filter, velocity, p, kPeriod_s);
    const double depth_m = std::max(0.0, surface(t_s) - p.x());
    const double wall_n = std::max(0.0, kStiffness_n_per_m * depth_m * (1.0 - kLambda_s_per_m * v.x()));
    const double stored_j = 0.5 * kStiffness_n_per_m * depth_m * depth_m;
    const Eigen::Vector3d out =
        passivity_control(config, state, Eigen::Vector3d(wall_n, 0.0, 0.0), v, raw, kPeriod_s, stored_j);
    SafetyInput input;
    input.force_device_n = out;
    std::uint32_t flags = 0;
    const double sent_n = apply_safety(safety_config, safety, input, kPeriod_s, flags).x();
    record_sent_force(state, Eigen::Vector3d(sent_n, 0.0, 0.0));
    if (t_s < t_flick) {
      result.bound_ticks_before_flick = state.energy_bound_ticks;
      if (k > 0) result.max_step_before_flick_n = std::max(result.max_step_before_flick_n, std::abs(sent_n - last_sent_n));
    }
    last_sent_n = sent_n;
    const auto [target_m, target_m_per_s] = hand(t_s);
    plant.advance(acting_n, target_m, kPeriod_s, target_m_per_s);
    acting_n = sent_n;
    result.energy_max_j = std::max(result.energy_max_j, state.energy_j);
  }
  return result;
}

// The stress harness's bound (app/stress_cases.hpp, kStressEnergyBound_j).
constexpr double kStressEnergyBound_j = 0.025;

/// Worst energy over the flicks: 5 and 10 m/s, the body following 2–6 mm (E at the flick from
/// −19 mJ to +5 mJ).
double worst_flick_energy_j(const PassivityConfig& config, FlickResult* worst_before_flick = nullptr) {
  double worst_j = 0.0;
  for (const double flick_m_per_s : {5.0, 10.0}) {
    for (int i = 0; i <= 8; ++i) {
      const FlickResult r = run_flick(config, 0.002 + 0.0005 * i, flick_m_per_s);
      worst_j = std::max(worst_j, r.energy_max_j);
      if (worst_before_flick != nullptr) {
        worst_before_flick->bound_ticks_before_flick =
            std::max(worst_before_flick->bound_ticks_before_flick, r.bound_ticks_before_flick);
        worst_before_flick->max_step_before_flick_n =
            std::max(worst_before_flick->max_step_before_flick_n, r.max_step_before_flick_n);
      }
    }
  }
  return worst_j;
}

TEST(PassivityClosedLoop, AFlickOutOfAStiffDampedContactStaysWithinTheEnergyBound) {
  FlickResult before_flick;
  const double worst_j = worst_flick_energy_j(PassivityConfig{}, &before_flick);
  EXPECT_LE(worst_j, 0.8 * kStressEnergyBound_j);  // 16.1 mJ measured
  // Until the flick (press, hold, slow follow) the hand is never fast: no step from the bound,
  // and no force step beyond the wall's own (K·count = 0.25 N per count of motion). (A
  // controller reducing the unclamped 30 N steps 4 N there: its reduction only reaches the
  // hand once it exceeds 22 N, then all at once.)
  EXPECT_EQ(before_flick.bound_ticks_before_flick, 0u);
  EXPECT_LE(before_flick.max_step_before_flick_n, 0.35);
}

// With the reduction's reference following the stored energy (the deep contact stores what it
// returns, so the debt is what it returns beyond that) g keeps these flicks within the bound
// even without the energy bound at speed.
TEST(PassivityClosedLoop, TheStoredEnergyReferenceAloneKeepsTheFlickWithinTheBound) {
  PassivityConfig no_bounding;
  no_bounding.energy_bounding = false;
  EXPECT_LE(worst_flick_energy_j(no_bounding), kStressEnergyBound_j);
}

}  // namespace
}  // namespace fissure::rt
