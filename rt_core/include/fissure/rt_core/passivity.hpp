#pragma once
// Pipeline stage: time-domain passivity observer / controller (Hannaford & Ryu 2002), with a
// controller that never steps the force (reference-energy following, Ryu, Preusche,
// Hannaford & Hirzinger 2005, and per-tick force bounds as in Kim & Ryu's energy bounding).
//
// Observer: the energy the rendered force has put into the operator's hand since start,
//     E = Σ F_in_effect · Δp_device       [J]   (= Σ f·v·T with v = Δp/T)
// where F_in_effect is the force command that was acting while the device moved by Δp. On
// the Falcon's ping-pong a command computed in tick k goes out with exchange k+1 and acts
// until exchange k+2, so the motion seen in tick k+2 (p_{k+2} − p_{k+1}) is paired with the
// force computed two ticks earlier. E ≤ 0 means the virtual environment is passive (it
// has absorbed at least as much energy as it returned); E > 0 means it created energy —
// the precursor of the buzzing/instability Colgate & Schenkel's bound b > K·T/2 predicts.
//
// Controller. Predicted energy at the end of the interval this tick's force acts in:
//     E' = E + (F_sent + F)·v·T       (F_sent: the command already on its way)
// The reduction's reference follows the energy the environment stores (Ryu, Preusche,
// Hannaford & Hirzinger 2005: reference-energy following): with U = Σ k·xⁿ⁺¹/(n+1) over the
// patches in contact (hunt_crossley.hpp), E + U is what the hand will have received once the
// environment has returned everything it stores now — its debt. A passive spring pressed and
// held has E = −U, debt 0; a sampled one hit hard returns a little more than it stored, and
// that surplus is what the controller takes back, from the force while it returns energy.
// (Against a fixed reference, E = −U + surplus sat above −margin while the hand rested on a
// stiff wall after an impact, and a reduction held at standstill rendered the wall near 0 N.)
// The correction it applies is smooth by construction — two rate-limited quantities:
//   * r [N], a reduction of the environment force along the force's own direction:
//         F_out = F − min(r, |F|)·F̂ − β·v_f
//     F̂ is the contact normal (stable in contact), not v̂ (which flips with every encoder
//     count at standstill), so the correction does not jump when the motion reverses.
//     r heads for the share of F that withholds the debt E + U − C (above the reference
//     −margin; C: the device damper's credit, PassivityConfig::device_damping_n_s_per_m) within
//     dissipation_time_s while the environment is returning energy (F̂·v_raw > 0, v_f above
//     min_speed). Otherwise it holds while the debt at the current reduction, E + (1 − g)·U − C
//     (the rendered spring is (1 − g) of the environment's), is above the reference, and heads
//     back to 0 once that is paid — at a hold too: the force does no work there, and what the
//     full force then stores is counted in U and owed on the way out.
//     The debt an rt stall leaves (open_stall_account) is kept apart, in the stall account
//     (kPassivityStallAccountWindow_s): r neither holds for it at the rest nor grows for it on
//     the rest's buzz, and β does not act on it; r collects it on the way out of the rest
//     (kPassivityExitGate_m), as the share stall account / U of the force.
//     Per tick r grows by at most
//         Δr_max = max_correction_rate_n_per_s · T · (1 + max(0, E')/margin)
//     i.e. a ramp the hand does not feel as a click while the loop is nearly passive (E' ≤
//     0: 0.05 N per tick at 1 kHz, the same bound as a proxy swap), faster in proportion to
//     how much energy has really been created (a loop far beyond its Z-width must be caught
//     within a few ticks; at E' = 10·margin the ramp is 11× steeper), and falls by at most
//     max_correction_step_n.
//   * β [N·s/m], a damper on the filtered velocity v_f, ramped between 0 and
//     max_damping_n_s_per_m over damping_ramp_s: full while E' > −margin, zero otherwise.
//     v_f is continuous (2nd-order low-pass), so β·v_f has no steps either. β is bounded
//     (kDefaultPassivityMaxDamping_n_s_per_m says why it may exceed the device's b on v_f).
//     β acts on all of E (not on the debt): it is what drains the energy the observer reports.
// Energy bound on the ramp: while E' is above the reference and F pushes the hand
// out at power P (filtered velocity), r heads for at least the share that lets the force
// return no more than the rest of a 10-margin budget over dissipation_time_s, and moves by at
// least the step that removes it before ½·P·T·(remaining/step) exceeds that budget. At a
// hold P ≈ 0 and both are far below the base ramp; a force pushing out at watts is gone in a
// few ticks (without it the excess only grew until g caught up: P·50 ms, 0.2 J at 4 W).
// Reference energy −margin: the controller starts before E reaches zero, so it can spread the
// dissipation over many ticks instead of removing it all in the tick E crosses zero (the
// chatter of the plain Hannaford–Ryu controller: a 2.3 N step per encoder count at a hold).
// The cost is that E may overshoot 0 briefly; what the observer sees is still returned.
// Below min_speed_m_per_s β holds its value and r only gives back: the direction of v_f is
// noise there, and a force at standstill does no work.
//
// The force the controller works on is the one the device can render: the environment force
// clamped to max_force_n (safety's clamp, which comes after). Acting on the unclamped force,
// the first 70 % of a reduction against a 27 N contact rendered at 8 N would change nothing the
// hand feels (hc_lambda_over_k_1 stress case), and the prediction E' would count a force that
// never goes out.
//
// Energy bounding at speed (Kim & Ryu 2004). The ramps above act from the next tick
// on, at most 2 N per tick; a hand that leaves a contact at 1–2 m/s while the full 8 N pushes it
// out receives 8–16 mJ per tick, and the two commands already on their way (the ping-pong)
// return that twice before any correction acts (hc_lambda_over_k_1: E from −2.8 to +32.5 mJ in
// 5 ticks; hand_teleports: 1.3 → 26.0 mJ in 3 ticks). So once the device moves at least
// kPassivityBoundingMinSpeed_m_per_s (raw difference: never a hold), the force is bounded
// outright so that what the interval it acts in can return at the current speed stays within
// what is left of the ramp's energy budget after the command already sent:
//     E_less_forgiven + F_sent·v·T + (1 − g)·|F|·(F̂·v)·T ≤ kPassivityRampEnergyBudgetMargins·margin
// (v: whichever of v_raw, v_f returns more). This may step the force — by design, and only at a
// speed no hand holding still reaches; safety's rate limit (4 N per tick) still applies.
// What it cannot bound is the work of the command already sent (and of the one whose motion
// was just observed): at 1.7 m/s and 6 N that is ≈ 10 mJ per tick (hand_teleports).
#include <cstdint>

#include <Eigen/Core>

#include "fissure/rt_core/safety.hpp"

namespace fissure::rt {

/// One encoder count of end-effector motion near the workspace centre [m] (BRIEF §6: ≈ 0.05 mm):
/// the resolution of every position the observer pairs with a force.
inline constexpr double kPassivityEncoderCount_m = 50e-6;
/// Reference energy margin [J]: the observer's own resolution at the Falcon's rated force —
/// one encoder count of motion under 8 N is 0.4 mJ, so an E within that of zero is
/// indistinguishable from zero.
inline constexpr double kDefaultPassivityMargin_j = kFalconMaxForce_n * kPassivityEncoderCount_m;
/// Largest change of the force reduction per tick while E' ≤ 0 [N]: the bound issue 6 sets
/// for a proxy swap (max |ΔF| per tick ≤ 0.05 N) — the same "no felt click" criterion applies
/// to the controller's own force changes.
inline constexpr double kDefaultPassivityCorrectionStep_n = 0.05;
/// Cap of the urgency factor 1 + E'/(10·margin) that steepens the reduction's ramp once energy
/// has really been created: at most 40 × 0.05 = 2 N per tick (reached at E' = 0.16 J).
/// Uncapped, a large E' turned the ramp back into the one-tick switch this controller replaces.
inline constexpr double kPassivityMaxUrgency = 40.0;
/// Energy scale of the urgency factor, in margins: 1 + E'/(10·margin), i.e. twice as steep
/// at E' = 4 mJ, 7× at the stress harness's 25 mJ bound.
inline constexpr double kPassivityUrgencyMargins = 10.0;
/// Energy the environment may still return while the controller ramps its reduction in, in
/// margins (4 mJ): the ramp is made steep enough that a force pushing the hand out at power
/// P is gone before it has returned that much (see passivity.cpp). Ten margins, the scale at
/// which the urgency factor doubles: small against the stress harness's 25 mJ bound, large
/// against what a hold returns between two ticks (≲ 10 µJ), so holds keep the 0.05 N ramp.
inline constexpr double kPassivityRampEnergyBudgetMargins = 10.0;
/// Raw speed from which the energy bound acts [m/s]: 0.2 m/s is 4 encoder counts per 1 kHz
/// tick. A hand holding still moves ≲ 1 cm/s and its raw difference toggles by one count per
/// tick (count × rate: 25 mm/s at 500 Hz, 50 mm/s at 1 kHz), so the bound never acts at a hold,
/// where a step would be felt as a click; at 0.2 m/s the full 8 N returns 1.6 mJ per 1 ms tick,
/// 40 % of the ramp's energy budget, so below it the ramps keep up.
inline constexpr double kPassivityBoundingMinSpeed_m_per_s = 0.2;
/// …and at least this many encoder counts per tick, so that at a high tick rate (4 kHz: one
/// count per tick reads 0.2 m/s) the quantisation toggle of a hold still stays below the gate.
inline constexpr double kPassivityBoundingMinCountsPerTick = 2.0;
/// Time over which the controller aims to dissipate the excess energy [s] (reference-energy
/// following): 50 ms, a few periods of the hand–device resonance (≈ 7 Hz with a 300 N/m grip)
/// and of a stiff contact (≈ 20–70 Hz), so the correction stays a small, smooth force.
inline constexpr double kDefaultPassivityDissipationTime_s = 0.05;
/// Time for the added damper to go from 0 to max_damping_n_s_per_m [s]: 20 ms, a few periods
/// of a 3000 N/m wall on the Falcon's ~0.15 kg (≈ 22 Hz), far longer than a tick.
inline constexpr double kDefaultPassivityDampingRamp_s = 0.02;

/// After a device fault [s]: the work done while safety brings the force back (its
/// kDefaultFaultRampIn_s = 0.25 s ramp-in, after FaultConfig's 20 clean ticks ≤ 40 ms at
/// 500 Hz) is counted in E and also reported as recovery_energy_j (the ramp pushes a hand
/// that sank in while the force was off back out). It counts: ignored (so as not to hold the
/// wall soft after a fault), each fault adds energy nothing takes back (4.7 J over 999 encoder
/// jumps in the stress harness).
inline constexpr double kPassivityRecoveryWindow_s = 0.3;
/// Work done in one fault-recovery window that the force reduction g does not act on [J]:
/// 10 default margins (4 mJ). Bringing the force back at a static hold necessarily pushes the
/// hand's spring back out, ½·F²/k ≈ 1.4 mJ for 1.5 N on a 300 N/m hand and a 500 N/m wall;
/// holding the wall soft for that would leave it soft for as long as the hand holds still (g
/// does not change at standstill). The damper β still acts on all of E, so the forgiven part is
/// dissipated as soon as the hand moves; what a recovery returns beyond this (a soft wall or a
/// contact rendered at a jumped, false position: 26 mJ in 80 ms) is taken off by g as usual.
inline constexpr double kPassivityRecoveryForgiveness_j = 10.0 * kDefaultPassivityMargin_j;

/// An rt stall (a sample gap the loop treats as a history break, tick.cpp) is a discontinuity of
/// the sampled system: for its length the device held one command while the hand moved, and the
/// contact the loop resumes on stores energy the hand never paid for (pressed in under the held
/// command) or the held push gave the hand more than the wall stored (pushed out under it). That
/// debt is not activity of the loop that goes on, and withholding it at rest takes nothing back
/// (a force at standstill does no work). So the debt booked during this window after a stall —
/// up to what the environment stores, the part that can still be withheld as it is returned —
/// goes into a stall account that g collects only while the hand leaves the rest it took (see
/// kPassivityExitGate_m), and neither g at rest nor β acts on it [s]: the window of a device
/// fault's recovery (kPassivityRecoveryWindow_s), long enough for the blend to bring the new
/// contact's force in (≤ 8 N at 0.05 N per 1 kHz tick: 0.16 s).
inline constexpr double kPassivityStallAccountWindow_s = 0.3;
/// The hand leaves its rest once it is this far out of it along the force [m]: four encoder
/// counts, beyond the ±1 count a hold toggles by and the ≈ ±40 µm of a 60 Hz, ±15 mm/s rest buzz,
/// so the buzz never collects. The rest is an anchor that follows the hand inwards at once and
/// outwards with kPassivityRestAnchorTime_s; at most this much (× the force) of a stall's debt
/// is returned before g starts to collect it.
inline constexpr double kPassivityExitGate_m = 4.0 * kPassivityEncoderCount_m;
/// Time constant of the rest anchor's outward follow [s]: 0.1 s, longer than a period of the
/// 7 Hz hand–device resonance (so its settle after a stall reads as a rest) and shorter than the
/// stall case's 0.2 s before the check, so a new rest is taken within it.
inline constexpr double kPassivityRestAnchorTime_s = 0.1;

/// Largest credit for the device's own dissipation the reduction g may count against the debt
/// [J]: what a wall at the Falcon's rated stiffness stores at its rated force, F²/(2K) =
/// 8²/(2·3000) = 10.7 mJ — a contact's worth. The observer E itself never counts the credit,
/// and β still acts on all of E, so the energy the stress harness bounds stays drained.
inline constexpr double kPassivityMaxDampingCredit_j =
    kFalconMaxForce_n * kFalconMaxForce_n / (2.0 * kFalconMaxStiffness_n_per_m);

/// Largest damping β the controller adds [N·s/m]: 5 N·s/m, chosen by measurement (fissure bench
/// rt and the rt_stall stress case, docs/decisions.md, issue 26). β acts on the filtered
/// velocity v_f (2nd-order, 100 Hz at 1 kHz), whose gain near the Nyquist rate — where the
/// sampled-data activity Colgate–Schenkel's b > K·T/2 + |B| is about lives — is a small fraction
/// of its gain at the contact resonance (15–30 Hz with the hand), so β may exceed the device's b
/// there without turning active: the bench's walls stay passive (device damper counted) at every
/// rate. Lower holds the wall back: at 2 N·s/m a 3000 N/m wall at 1 kHz kept a 1 mm limit cycle
/// (rendered at 56 % of its stiffness), at 4 N·s/m the next grid point after 2910 N/m (3638) buzzed.
/// Higher distorts a hold: β·v_f against a contact the host makes buzz at ~60 Hz, ±15 mm/s, is
/// 5.6 % of a 2 N force at 6 N·s/m (4.7 % at 5). Far below CHAI3D's 20 N·s/m Falcon limit (BRIEF §5).
inline constexpr double kDefaultPassivityMaxDamping_n_s_per_m = 5.0;

struct PassivityConfig {
  bool enabled = true;
  /// The device's own viscous damping b [N·s/m] (kFalconDeviceDamping_n_s_per_m, safety.hpp).
  /// It dissipates b·|v|²·T per tick whatever the controller does: g counts that (up to
  /// kPassivityMaxDampingCredit_j, on the filtered velocity, which underestimates |v|² of a
  /// buzz) against the debt — the port the hand holds is the rendered environment plus this
  /// damper, the port Colgate–Schenkel's b > K·T/2 + |B| is about. The rendered contact damping
  /// is capped with it too (hunt_crossley.hpp). Set it to the device's value: a larger one than
  /// the device has lets through energy and damping it cannot dissipate.
  double device_damping_n_s_per_m = kFalconDeviceDamping_n_s_per_m;
  /// Largest damping the controller may add [N·s/m]: kDefaultPassivityMaxDamping_n_s_per_m.
  double max_damping_n_s_per_m = kDefaultPassivityMaxDamping_n_s_per_m;
  /// Below this filtered speed the controller holds its correction [m/s]: one encoder count
  /// per tick at 1 kHz reads ≈ 50 mm/s raw, ≲ 1 mm/s after the filter; the direction of v is
  /// noise below that and a force at standstill does no work anyway.
  double min_speed_m_per_s = 1e-3;
  /// Reference energy margin [J] (kDefaultPassivityMargin_j).
  double margin_j = kDefaultPassivityMargin_j;
  /// Largest change of the force reduction r per tick while E' ≤ 0 [N] (× the urgency factor
  /// above that).
  double max_correction_step_n = kDefaultPassivityCorrectionStep_n;
  /// Time over which the excess above the reference is to be dissipated [s].
  double dissipation_time_s = kDefaultPassivityDissipationTime_s;
  /// 0 → max_damping_n_s_per_m ramp time of the added damper [s].
  double damping_ramp_s = kDefaultPassivityDampingRamp_s;
  /// Largest force the device renders [N]: the environment force is clamped to it (direction
  /// kept) before the controller acts, so g and E' work on the force that goes out. Must equal
  /// SafetyConfig::max_force_n (the clamp after the controller); both default to the Falcon's 8 N.
  double max_force_n = kFalconMaxForce_n;
  /// Energy bounding at speed (see above); off only to measure what it does.
  bool energy_bounding = true;
};

struct PassivityState {
  double energy_j = 0.0;  ///< observer: Σ F·Δp since start (positive = active)
  double dissipated_by_controller_j = 0.0;   ///< Σ −correction·v_f·T (what the controller took out)
  Eigen::Vector3d force_sent_last_device_n = Eigen::Vector3d::Zero();   ///< computed tick k−1
  Eigen::Vector3d force_acting_device_n = Eigen::Vector3d::Zero();      ///< computed tick k−2 (acting now)
  Eigen::Vector3d p_prev_device_m = Eigen::Vector3d::Zero();
  bool primed = false;
  double recovery_energy_j = 0.0;      ///< part of E done in fault-recovery windows (reported; included in E)
  double recovery_window_left_s = 0.0;
  double recovery_window_energy_j = 0.0;  ///< work done in the current recovery window
  double recovery_forgiven_j = 0.0;       ///< Σ over closed windows of min(window work, forgiveness)
  /// Σ b·|v_f|²·T, never more than the debt E + U (nor kPassivityMaxDampingCredit_j): the
  /// device's dissipation g counts against the debt [J]
  double damping_credit_j = 0.0;
  double reduction_fraction = 0.0;        ///< g: share of F taken off along F̂ [0, 1]
  double reduction_n = 0.0;               ///< r = g·|F| in the last tick [N]
  double added_damping_n_s_per_m = 0.0;   ///< β
  /// Telemetry: the correction expressed as a damping, |F − F_out| / max(|v_f|, min_speed)
  /// [N·s/m] (F clamped to max_force_n); > 0 exactly when the controller changed the force.
  double damping_n_s_per_m = 0.0;
  /// The stall account [J]: debt booked after an rt stall that g collects only on the way out of
  /// the rest (kPassivityStallAccountWindow_s); never more than the debt nor than U.
  double stall_debt_j = 0.0;
  double stall_window_left_s = 0.0;  ///< time left to book into the stall account
  /// The rest the hand holds (kPassivityExitGate_m), device frame [m].
  Eigen::Vector3d rest_anchor_device_m = Eigen::Vector3d::Zero();
  /// Telemetry: the energy bound raised g this tick (it stepped the force).
  bool energy_bound_acted = false;
  std::uint64_t energy_bound_ticks = 0;  ///< ticks in which the energy bound raised g
};

/// Observer: account the work done since the previous sample. Call once per good sample.
void observe_energy(PassivityState& state, const Eigen::Vector3d& p_device_m) noexcept;

/// Controller: returns the force with the passivity correction applied (unchanged when
/// disabled or while the correction is zero). v_raw is used only to predict the energy (it
/// leads the filtered estimate by ~3 ms); the force uses v_filtered alone.
/// stored_energy_j: the energy the environment stores at this sample, U ≥ 0 [J] at the device
/// port (the reference of the reduction g follows it: E + U is what the environment owes).
Eigen::Vector3d passivity_control(const PassivityConfig& config, PassivityState& state,
                                  const Eigen::Vector3d& force_device_n, const Eigen::Vector3d& v_filtered_m_per_s,
                                  const Eigen::Vector3d& v_raw_m_per_s, double period_s,
                                  double stored_energy_j = 0.0) noexcept;

/// Records the force that actually went out this tick (after safety) for the observer.
void record_sent_force(PassivityState& state, const Eigen::Vector3d& force_device_n) noexcept;

/// After a fault the device position history is not trustworthy: restart the Δp chain
/// (the energy total is kept), drop the correction (the force restarts from zero via
/// safety's ramp-in anyway) and open a kPassivityRecoveryWindow_s window whose work is
/// reported separately (recovery_energy_j). The damper β acts on the whole E; the reduction g
/// on E less up to kPassivityRecoveryForgiveness_j of each window's work.
void restart_observer(PassivityState& state) noexcept;

/// After an rt stall (tick.cpp's history break, after restart_observer): opens the stall account
/// for kPassivityStallAccountWindow_s.
void open_stall_account(PassivityState& state) noexcept;

}  // namespace fissure::rt
