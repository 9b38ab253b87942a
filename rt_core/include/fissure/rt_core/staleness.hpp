#pragma once
// Pipeline stage: staleness fade-out (BRIEF §5: host stopped or link lost → the force fades
// to zero within a bound). The contact force is multiplied by a gain g ∈ [0, 1] that moves
// towards 1 while the proxy is usable and towards 0 otherwise, by period/fade_s per tick:
//   * a proxy older than stale_after_s, or an invalid newest proxy → g reaches 0 at most
//     fade_s later, so the force is zero at proxy age ≤ stale_after_s + fade_s (+ one tick);
//   * a fresh valid proxy → g ramps back to 1 over fade_s (no step on recovery either).
// Each tick the gain changes the force by at most |F|·T/fade_s (8 N·1 ms/50 ms = 0.16 N).
#include "fissure/shared/time.hpp"

namespace fissure::rt {

struct ProxyConfig {
  /// Max |ΔF| per tick of the rendered contact force while a swap blends [N]: issue 6's
  /// target for the whole session is ≤ 0.05 N per tick, and the swap's walk shares it with the
  /// tool's motion (proxy_blend.hpp) — a tick's step is ≤ max(this, the motion's own step).
  double blend_max_step_n = 0.05;
  /// A proxy older than this is stale [s]. The slowest host rate we support is 50 Hz
  /// (issue 6) = 20 ms per step; 100 ms tolerates four lost steps before fading.
  double stale_after_s = 0.1;
  /// Time for the fade gain to go 1 → 0 (and 0 → 1 on recovery) [s]; 50 ms is fast
  /// enough that a dead host is noticed at once, slow enough not to feel like a step.
  double fade_s = 0.05;
};

struct FadeState {
  double gain = 0.0;  ///< starts at 0: the first proxy fades in
};

/// Moves the gain one tick towards 1 (usable) or 0 (not) and returns it.
double update_fade(const ProxyConfig& config, FadeState& state, bool proxy_usable, double period_s) noexcept;

/// Whether the active proxy may be rendered at full gain.
inline bool proxy_usable(const ProxyConfig& config, bool have_proxy, bool invalid_latched, TimeNs age_ns) noexcept {
  return have_proxy && !invalid_latched && to_seconds(age_ns) <= config.stale_after_s;
}

}  // namespace fissure::rt
