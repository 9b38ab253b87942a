#include "fissure/rt_core/proxy_intake.hpp"

#include <algorithm>
#include <cmath>

namespace fissure::rt {
namespace {

// minmod: 0 when the two disagree in sign, else the one closer to 0 (a trend both saw).
double minmod(double a, double b) noexcept {
  if (a * b <= 0.0) return 0.0;
  return std::abs(a) < std::abs(b) ? a : b;
}

double dot(const Vec3& a, const Vec3& b) noexcept { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Moves buffer `b`'s rendered planes to `now_ns` (the proxy was accepted at accepted_at_ns).
void extrapolate_to(ProxyState& state, int b, TimeNs accepted_at_ns, TimeNs now_ns) noexcept {
  const auto i = static_cast<std::size_t>(b);
  const ContactProxy& received = state.buffers[i];
  ContactProxy& rendered = state.rendered[i];
  const TimeNs horizon = std::clamp<TimeNs>(now_ns - accepted_at_ns, 0, state.horizon_ns[i]);
  const double t_s = to_seconds(horizon);
  const int count = std::min<int>(received.patch_count, static_cast<int>(kMaxContactPatches));
  for (int p = 0; p < count; ++p) {
    const ContactPatch& from = received.patches[static_cast<std::size_t>(p)];
    const double shift_m = state.speed_m_per_s[i][static_cast<std::size_t>(p)] * t_s;
    for (std::size_t a = 0; a < 3; ++a) {
      rendered.patches[static_cast<std::size_t>(p)].plane_point_world_m[a] =
          from.plane_point_world_m[a] + shift_m * from.normal_world[a];
    }
  }
}

// Surface speeds of buffer `to` (just accepted) from buffer `from` (the proxy before it).
void estimate_speeds(ProxyState& state, int from, int to, const ProxyExtrapolation& model) noexcept {
  const auto f = static_cast<std::size_t>(from);
  const auto t = static_cast<std::size_t>(to);
  state.raw_speed_m_per_s[t].fill(0.0);
  state.speed_m_per_s[t].fill(0.0);
  state.horizon_ns[t] = 0;
  if (!model.enabled) return;
  const ContactProxy& old_proxy = state.buffers[f];
  const ContactProxy& new_proxy = state.buffers[t];
  const int old_count = std::min<int>(old_proxy.patch_count, static_cast<int>(kMaxContactPatches));
  const int new_count = std::min<int>(new_proxy.patch_count, static_cast<int>(kMaxContactPatches));
  TimeNs horizon = 0;
  for (int p = 0; p < new_count; ++p) {
    const ContactPatch& patch = new_proxy.patches[static_cast<std::size_t>(p)];
    int match = -1;
    double best = model.match_min_cosine;
    for (int q = 0; q < old_count; ++q) {
      const ContactPatch& candidate = old_proxy.patches[static_cast<std::size_t>(q)];
      if (candidate.tool_part != patch.tool_part) continue;
      const double cosine = dot(candidate.normal_world, patch.normal_world);
      if (cosine >= best) {
        best = cosine;
        match = q;
      }
    }
    if (match < 0) continue;
    const ContactPatch& old_patch = old_proxy.patches[static_cast<std::size_t>(match)];
    const TimeNs baseline = patch.reference_time_ns - old_patch.reference_time_ns;
    if (baseline <= 0 || to_seconds(baseline) > model.max_baseline_s) continue;
    // Surface offset along the new normal: plane_point · n (the builder puts the plane at
    // q_host + x_ref·n, so a surface that holds still while the tool pushes keeps this offset).
    const double moved_m = dot(patch.plane_point_world_m, patch.normal_world) -
                           dot(old_patch.plane_point_world_m, patch.normal_world);
    const double raw = std::clamp(moved_m / to_seconds(baseline), -model.max_surface_speed_m_per_s,
                                  model.max_surface_speed_m_per_s);
    state.raw_speed_m_per_s[t][static_cast<std::size_t>(p)] = raw;
    state.speed_m_per_s[t][static_cast<std::size_t>(p)] =
        minmod(raw, state.raw_speed_m_per_s[f][static_cast<std::size_t>(match)]);
    horizon = std::max(horizon, baseline);
  }
  state.horizon_ns[t] = horizon;
}

}  // namespace

ProxyIntake take_latest_proxy(ProxyExchange& exchange, ProxyState& state, TimeNs now_ns,
                              const ProxyExtrapolation& extrapolation) noexcept {
  // The active proxy at this tick (it becomes the previous one if a new proxy is accepted now).
  // A zero horizon (extrapolation off, the default, or no matched patch) leaves the rendered copy
  // exactly as received, so the tick does no per-patch work then.
  if (state.have_proxy && state.horizon_ns[static_cast<std::size_t>(state.active)] > 0) {
    extrapolate_to(state, state.active, state.accepted_at_ns, now_ns);
  }

  // Fetch straight into the inactive buffer. If the candidate is rejected, that buffer no
  // longer holds the previous proxy; the blend only needs it on an accepted swap (and reads
  // the rendered copy, which the fetch does not touch).
  ContactProxy& candidate = state.buffers[1 - state.active];
  if (!exchange.try_fetch(candidate)) return ProxyIntake::kNothingNew;
  state.have_previous = false;

  ProxyError error = validate(candidate);
  if (error == ProxyError::kNone && (candidate.flags & kProxyValid) == 0u) {
    // The host says its content is unusable; treat like corruption (never render it).
    error = ProxyError::kNonFinite;
  }
  if (error != ProxyError::kNone) {
    ++state.rejected_count;
    state.last_error = error;
    state.invalid_latched = true;
    return ProxyIntake::kRejected;
  }
  if (state.have_proxy && candidate.sequence <= received_proxy(state).sequence) {
    ++state.out_of_order_count;
    return ProxyIntake::kOutOfOrder;
  }
  const int next = 1 - state.active;
  if (state.have_proxy) {
    estimate_speeds(state, state.active, next, extrapolation);
  } else {
    state.raw_speed_m_per_s[static_cast<std::size_t>(next)].fill(0.0);
    state.speed_m_per_s[static_cast<std::size_t>(next)].fill(0.0);
    state.horizon_ns[static_cast<std::size_t>(next)] = 0;
  }
  state.rendered[static_cast<std::size_t>(next)] = candidate;  // age 0: exactly as received
  state.have_previous = state.have_proxy;
  state.active = next;
  state.have_proxy = true;
  state.invalid_latched = false;
  state.accepted_at_ns = now_ns;
  ++state.accepted_count;
  return ProxyIntake::kAccepted;
}

}  // namespace fissure::rt
