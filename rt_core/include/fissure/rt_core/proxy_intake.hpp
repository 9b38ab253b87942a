#pragma once
// Pipeline stage: take the newest contact proxy from the host (wait-free try_fetch on the
// LatestValueExchange), validate it, keep it double-buffered so that the previous proxy stays
// readable for the swap blend (proxy_blend.hpp), and extrapolate each patch's plane in time
// between host updates.
//   * invalid (validate() fails, or the host did not set kProxyValid): rejected, counted,
//     kFaultProxyInvalid latched — the contact force fades out (staleness.hpp) until a valid
//     proxy arrives;
//   * sequence not newer than the current one (a transport delivered it late): ignored and
//     counted; it neither refreshes the proxy age nor faults.
// Proxy age is measured on rt_core's clock from the tick that accepted it, so it is right
// even when the host's simulation clock is another machine's.
//
// Why extrapolate (optional, off by default — see ProxyExtrapolation for the measurement): when
// the host's soft body keeps moving while the tool holds still (a host force rising by ~20 N/s
// at a fixed tool pose after the press), a proxy frozen
// at its reference pose is wrong by (force rate × host period) just before the next one arrives. Each patch's surface speed along its normal is
// estimated from two consecutive proxies (matched by tool part and normal; host times from
// the same host clock, so no clock mapping is needed), passed through a minmod limiter against
// the previous estimate (a one-off jump — contact lost, a patch appearing — has no trend behind
// it and gives 0; a steady drift gives the smaller of the two rates), and the plane is moved by
// speed × min(age, host period): never further than the host itself moved it in one period.
// HAPI (H3D) extrapolates its transferred shapes between transfers the same way (BRIEF §5).
// The rendered (extrapolated) proxies are what active_proxy()/previous_proxy() return; the
// proxies as received are kept beside them.
#include <array>
#include <cstdint>

#include "fissure/shared/latest_value_exchange.hpp"
#include "fissure/shared/exchanges.hpp"
#include "fissure/shared/message_validation.hpp"
#include "fissure/shared/messages.hpp"
#include "fissure/shared/time.hpp"

namespace fissure::rt {

enum class ProxyIntake : std::uint8_t { kNothingNew, kAccepted, kRejected, kOutOfOrder };

/// How patch planes are extrapolated between host updates (const model).
/// Off by default: extrapolating makes the held proxy slightly WORSE (`fissure bench proxy`,
/// column extrap_v_h% against mdl_v_hst%, and the PaperSceneProxy held-proxy test; figures in
/// docs/decisions.md): the host's force does not drift at a still pose, and what the plane
/// offset does between proxies is noise more than trend. Keep it measured.
struct ProxyExtrapolation {
  bool enabled = false;
  /// Two patches of consecutive proxies are "the same contact" when they act on the same tool
  /// part and their normals are within ~10° (cos 10° = 0.985): a tool face's patch turns far
  /// less than that in one host period of a soft-tissue contact.
  double match_min_cosine = 0.985;
  /// Host periods longer than this do not give a speed [s]: the proxies are too far apart for
  /// a linear trend (100 ms = the stale bound, ProxyConfig::stale_after_s).
  double max_baseline_s = 0.1;
  /// Surface speeds are clamped to this [m/s]: hand motion is < 1 m/s; a faster "surface" is a
  /// host discontinuity, not motion.
  double max_surface_speed_m_per_s = 1.0;
};

struct ProxyState {
  std::array<ContactProxy, 2> buffers{};   ///< as received: [active] in use; [1 − active] the previous one
  std::array<ContactProxy, 2> rendered{};  ///< the same, planes extrapolated to the current tick
  /// Per buffer and patch: surface speed along the patch normal [m/s] (> 0: the surface advances
  /// onto the tool), raw (for the next limiter) and limited (used), and the host period it spans.
  std::array<std::array<double, kMaxContactPatches>, 2> raw_speed_m_per_s{};
  std::array<std::array<double, kMaxContactPatches>, 2> speed_m_per_s{};
  std::array<TimeNs, 2> horizon_ns{};
  int active = 0;
  bool have_proxy = false;                ///< a valid proxy was ever accepted
  bool have_previous = false;             ///< rendered[1 − active] holds the proxy before it (at now)
  bool invalid_latched = false;           ///< newest proxy from the host was invalid
  TimeNs accepted_at_ns = 0;              ///< rt time of the tick that accepted the active proxy
  std::uint64_t accepted_count = 0;
  std::uint64_t rejected_count = 0;
  std::uint64_t out_of_order_count = 0;
  ProxyError last_error = ProxyError::kNone;
};

/// Wait-free: at most one try_fetch (one atomic exchange + a copy) and one validate(); moves
/// the active proxy's planes to `now_ns` every call (also when nothing new came).
ProxyIntake take_latest_proxy(ProxyExchange& exchange, ProxyState& state, TimeNs now_ns,
                              const ProxyExtrapolation& extrapolation = {}) noexcept;

/// The proxy to evaluate this tick (extrapolated to the tick of the last take_latest_proxy).
inline const ContactProxy& active_proxy(const ProxyState& state) noexcept { return state.rendered[state.active]; }
/// The proxy before it, extrapolated to the same tick (valid when have_previous).
inline const ContactProxy& previous_proxy(const ProxyState& state) noexcept {
  return state.rendered[1 - state.active];
}
/// The active proxy exactly as the host sent it.
inline const ContactProxy& received_proxy(const ProxyState& state) noexcept { return state.buffers[state.active]; }

/// Age of the active proxy [ns] (0 when there is none).
inline TimeNs proxy_age_ns(const ProxyState& state, TimeNs now_ns) noexcept {
  return state.have_proxy ? now_ns - state.accepted_at_ns : 0;
}

}  // namespace fissure::rt
