#pragma once
// Pipeline stage: blending on a proxy swap (BRIEF §5: a new proxy never causes a force step
// larger than a bound; issue 6: max |ΔF| per tick ≤ 0.05 N for the rendered contact force).
// At a swap the force the old proxy gives at the current position and the force the new one
// gives there generally differ. The difference is kept as an offset added to the new
// proxy's force and walked to zero; swaps during a blend add their own difference to the
// remaining offset, so the rendered force stays continuous.
//
// The walk shares ONE per-tick budget, max_step_n, with the tool's motion. Between two ticks
// the rendered force changes by
//     ΔF = m + w,   m = (new_force + offset) − previous output   (the motion step: the proxy in
//                                                                 use, moved from the last pose)
//                   w = the offset's walk this tick (|w| ≤ max_step_n, against the offset)
// m is the stiffness being rendered (k·ẋ·T for a Hunt-Crossley patch) and is never smoothed —
// that would be a lag, i.e. a softer, less transparent contact. The walk takes whatever the
// motion leaves of the budget: the largest |w| ≤ max_step_n with |m + w| ≤ max(max_step_n, |m|).
// So a swap never makes a tick's step exceed max_step_n, nor the motion's own step when that
// is larger; while the motion alone uses the whole budget in the walk's direction the offset
// holds and walks out as soon as the motion slows (motion against the walk direction lets it
// walk at the full rate). A walk that always takes max_step_n on top of m steps by 0.062 N per
// tick in `fissure bench proxy` (500 Hz host: 0.05 N walk + 0.012 N of motion).
#include <Eigen/Core>

namespace fissure::rt {

struct BlendState {
  Eigen::Vector3d offset_device_n = Eigen::Vector3d::Zero();  ///< remaining swap difference
  /// What blend() returned last (the rendered force before the staleness fade): the reference
  /// the motion step m is measured from.
  Eigen::Vector3d last_output_device_n = Eigen::Vector3d::Zero();
  bool have_last_output = false;
  /// Set by continue_after_break until the next swap: the offset holds instead of walking
  /// towards the force of a proxy built before the break.
  bool offset_held = false;
};

/// Call on the tick a new proxy is accepted, with both proxies' forces at the current position.
void begin_swap(BlendState& state, const Eigen::Vector3d& old_force_device_n,
                const Eigen::Vector3d& new_force_device_n) noexcept;

/// Drops what is left of the swap offsets: the force they stood for no longer applies (the
/// old proxies were built for a tool pose lost in a device fault; the tick calls this while
/// one is latched and safety's ramp-in brings the force back continuously instead).
inline void cancel_swaps(BlendState& state) noexcept {
  state.offset_device_n.setZero();
  state.offset_held = false;
}
/// After a break in the motion history (the loop stalled while the device kept its last
/// command, tick.cpp): the proxies on hand were built for a pose the tool has since left, and
/// evaluated at the new pose they give a force no contact produces — their planes extend far
/// past the contact they stood for (rt-stall stress case: 6 N at a pose 8 mm away, against the
/// 1.7 N the device held through the stall, and the next proxy saw no contact there). The blend
/// goes on from the force it last rendered instead: the difference to the proxy in use is the
/// offset, held until the next proxy is accepted (walking it would head for the stale force)
/// and walked out from then on as at a swap, so what the hand feels is continuous with the stall.
void continue_after_break(BlendState& state, const Eigen::Vector3d& force_in_use_device_n) noexcept;

/// The length of this tick's walk of an offset along unit direction −offset_unit, given the
/// motion step m: the largest s ∈ [0, min(|offset|, B)] with |m − s·offset_unit| ≤ max(B, |m|),
/// B = max_step_n less a 1e-13 N margin that keeps the rendered step within max_step_n after
/// rounding (proxy_blend.cpp). Exposed for its test.
double blend_walk_n(const Eigen::Vector3d& motion_step_n, const Eigen::Vector3d& offset_unit, double offset_norm_n,
                    double max_step_n) noexcept;

/// Walks the offset towards zero within the shared budget (see above), then returns
/// new_force + offset.
Eigen::Vector3d blend(BlendState& state, const Eigen::Vector3d& new_force_device_n, double max_step_n) noexcept;

inline bool blending(const BlendState& state) noexcept { return !state.offset_device_n.isZero(0.0); }

}  // namespace fissure::rt
