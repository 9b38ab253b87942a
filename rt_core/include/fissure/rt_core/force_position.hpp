#pragma once
// Pipeline stage: the position the contact force is evaluated at (issue 26, "sub-count position
// for the force").
//
// The encoder reading moves in counts (≈ 50–63 µm at the end effector, BRIEF §6); at contact
// stiffness k one count is a force step of k·count in one tick — 0.0508 N in `fissure bench
// proxy` at a 50 Hz host (2 kHz rt), against issue 6's 0.05 N per tick. The force is evaluated at
//     p_force = p_k − w·(p_k − p_{k−1})
// a two-tap FIR of the reading with weight w = kForcePositionPreviousWeight: a one-count step
// reaches the force as (1 − w) of it in its tick and w in the next, a constant velocity is
// unchanged but for a lag of exactly w·T (stated: force_position_lag_s). No play: at rest
// p_force is the reading, so a wall is rendered where the encoder says the hand is (a velocity
// prediction clamped within a fraction of a count of the reading was a play of that width and
// narrowed the Z-width, docs/decisions.md, issue 26). The observer, the velocity filter and
// the published position keep the reading itself.
#include <Eigen/Core>

namespace fissure::rt {

/// Weight w of the previous reading in the force's position [1]: 5 %, chosen by measurement
/// (docs/decisions.md, issue 26): one count's force step is cut to 95 % (bench proxy's 0.0508 N
/// needs 1.6 %) for a lag of T/20 (50 µs at 1 kHz). ¼ and 0.1 cut more, but the added lag cost
/// the controller's 1 kHz Z-width (3638 → 2910 N/m, below the Falcon's rated 3000 N/m).
inline constexpr double kForcePositionPreviousWeight = 0.05;

struct ForcePositionState {
  Eigen::Vector3d p_prev_device_m = Eigen::Vector3d::Zero();
  bool primed = false;  ///< false: the next reading is used as it is (after a start, fault or stall)
};

/// The position to evaluate the contact at, device frame [m]; feeds the reading into the state.
Eigen::Vector3d force_position(ForcePositionState& state, const Eigen::Vector3d& p_device_m) noexcept;

/// Added lag of the force's position at a constant velocity [s]: w·T.
double force_position_lag_s(double period_s) noexcept;

}  // namespace fissure::rt
