#include "fissure/rt_core/proxy_blend.hpp"

#include <algorithm>
#include <cmath>

namespace fissure::rt {

void begin_swap(BlendState& state, const Eigen::Vector3d& old_force_device_n,
                const Eigen::Vector3d& new_force_device_n) noexcept {
  state.offset_device_n += old_force_device_n - new_force_device_n;
  state.offset_held = false;
}

void continue_after_break(BlendState& state, const Eigen::Vector3d& force_in_use_device_n) noexcept {
  // The last output already holds every earlier offset: it replaces them.
  if (!state.have_last_output) return;
  state.offset_device_n = state.last_output_device_n - force_in_use_device_n;
  state.offset_held = true;
}

namespace {
// The walk leaves this much of the budget unused [N]: the rendered step is formed from forces of
// up to the safety clamp (8 N), whose rounding (~1e-15 N) would otherwise put a step that meets
// the bound exactly a few ulps over it — a step the "≤ max_step_n" contract does not allow.
constexpr double kBlendRoundingMargin_n = 1e-13;
}  // namespace

double blend_walk_n(const Eigen::Vector3d& motion_step_n, const Eigen::Vector3d& offset_unit, double offset_norm_n,
                    double max_step_n) noexcept {
  // |m − s·u|² = |m|² − 2s(m·u) + s² ≤ L², L = max(budget, |m|) ≥ |m|: s = 0 always fits, and
  // the feasible s form the interval between the two roots s = m·u ± √((m·u)² + L² − |m|²).
  const double budget_n = std::max(0.0, max_step_n - kBlendRoundingMargin_n);
  const double m_norm = motion_step_n.norm();
  const double limit = std::max(budget_n, m_norm);
  const double along = motion_step_n.dot(offset_unit);
  const double upper = along + std::sqrt(std::max(0.0, along * along + (limit - m_norm) * (limit + m_norm)));
  return std::clamp(upper, 0.0, std::min(offset_norm_n, budget_n));
}

Eigen::Vector3d blend(BlendState& state, const Eigen::Vector3d& new_force_device_n, double max_step_n) noexcept {
  const double remaining = state.offset_device_n.norm();
  if (remaining > 0.0 && !state.offset_held) {
    // Before the walk the output would be new_force + offset: its step from the last output is
    // the tool's motion under the proxy in use (at a swap: under the old one, begin_swap having
    // made new + offset = old at this pose).
    // A non-finite force (which safety turns into a fault) must not poison the offset for good:
    // without a usable motion step the walk takes the plain bound.
    Eigen::Vector3d motion_step = Eigen::Vector3d::Zero();
    if (state.have_last_output) motion_step = new_force_device_n + state.offset_device_n - state.last_output_device_n;
    if (!motion_step.allFinite()) motion_step.setZero();
    const Eigen::Vector3d unit = state.offset_device_n / remaining;
    const double walk = blend_walk_n(motion_step, unit, remaining, max_step_n);
    if (walk >= remaining) {
      state.offset_device_n.setZero();
    } else {
      state.offset_device_n -= walk * unit;
    }
  }
  state.last_output_device_n = new_force_device_n + state.offset_device_n;
  state.have_last_output = true;
  return state.last_output_device_n;
}

}  // namespace fissure::rt
