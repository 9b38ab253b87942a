#pragma once
// Pipeline stage: blending on a proxy swap (BRIEF §5: a new proxy never causes a force step
// larger than a bound).
// At a swap the force the old proxy gives at the current position and the force the new one
// gives there generally differ. The difference is kept as an offset added to the new
// proxy's force and walked to zero by at most ProxyConfig::blend_max_step_n per tick, so
// the swap itself changes the rendered force by ≤ blend_max_step_n in every tick (motion of
// the tool still changes it at full bandwidth — that is the stiffness being rendered).
// Swaps during a blend add their own difference to the remaining offset: still continuous.
#include <Eigen/Core>

namespace fissure::rt {

struct BlendState {
  Eigen::Vector3d offset_device_n = Eigen::Vector3d::Zero();  ///< remaining swap difference
};

/// Call on the tick a new proxy is accepted, with both proxies' forces at the current position.
void begin_swap(BlendState& state, const Eigen::Vector3d& old_force_device_n,
                const Eigen::Vector3d& new_force_device_n) noexcept;

/// Drops what is left of the swap offsets: the force they stood for no longer applies (the
/// old proxies were built for a tool pose lost in a device fault; the tick calls this while
/// one is latched and safety's ramp-in brings the force back continuously instead).
inline void cancel_swaps(BlendState& state) noexcept { state.offset_device_n.setZero(); }

/// Walks the offset ≤ max_step_n towards zero, then returns new_force + offset.
Eigen::Vector3d blend(BlendState& state, const Eigen::Vector3d& new_force_device_n, double max_step_n) noexcept;

inline bool blending(const BlendState& state) noexcept { return !state.offset_device_n.isZero(0.0); }

}  // namespace fissure::rt
