#pragma once
// Pipeline stage: the position the contact force is evaluated at — the encoder reading
// interpolated below one count.
//
// The Falcon's encoders resolve ≈ 50 µm of end-effector motion near the workspace centre
// (kPassivityEncoderCount_m, BRIEF §6). A contact evaluated at the quantised reading steps by
// k·50 µm whenever a count changes — 0.05 N at 1000 N/m, issue 6's whole per-tick bound, before
// any proxy swap is blended — and a hand resting on a count boundary toggles that step back and
// forth. The estimate moves with the filtered velocity and is kept within h of the reading,
// per device axis:
//     p̂_k = clamp(p̂_{k−1} + v_f·T,  p_k − h,  p_k + h),   h = kSubCountHalfWidth_m (¼ count)
// It moves at the hand's speed instead of in counts; a reading toggling across a boundary the
// hand rests on moves it by half a count instead of a whole one (the two sets are half a count
// apart); it is never more than h from the reading. Its lag behind the reading: zero at a
// constant velocity (v_f is exact there) and at most h otherwise — h/|v| in time, 0.125 ms at
// 0.1 m/s, 1.25 ms at 10 mm/s; the force differs from the one at the reading by at most k·h per
// axis (0.0125 N at 1000 N/m).
// h is a quarter count, not the half count the reading's own uncertainty would allow: the clamp
// is a play of width 2h between the reading and the estimate, and a play in the position a
// wall is rendered at returns more on the way out than it took on the way in. With h = ½ count
// the resting-hand test (3000 N/m, rt_loop_test) kept a ±0.19 N buzz about its equilibrium
// (docs/decisions.md, issue 26).
// Only the contact force uses it: the passivity observer pairs forces with the readings
// themselves, and the host receives the readings.
#include <Eigen/Core>

#include "fissure/rt_core/passivity.hpp"

namespace fissure::rt {

/// Largest distance of the estimate from the reading, per device axis [m]: a quarter of an
/// encoder count of end-effector motion near the workspace centre (see above for why not half).
inline constexpr double kSubCountHalfWidth_m = 0.25 * kPassivityEncoderCount_m;

struct SubCountPositionState {
  Eigen::Vector3d p_device_m = Eigen::Vector3d::Zero();  ///< p̂, the last estimate
  bool primed = false;  ///< false: the next update starts at the reading
};

/// Forgets the history: the next update starts at the reading (with the velocity filter's
/// restart — after a fault or a stall the prediction has nothing to go on).
void reset(SubCountPositionState& state) noexcept;

/// One reading p (device frame) and this tick's filtered velocity v_f → p̂.
Eigen::Vector3d update_sub_count_position(SubCountPositionState& state, const Eigen::Vector3d& p_device_m,
                                          const Eigen::Vector3d& v_filtered_m_per_s, double period_s) noexcept;

}  // namespace fissure::rt
