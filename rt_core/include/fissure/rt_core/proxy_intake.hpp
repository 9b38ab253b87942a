#pragma once
// Pipeline stage: take the newest contact proxy from the host (wait-free try_fetch on the
// LatestValueExchange), validate it, keep it double-buffered so that the previous proxy stays
// readable for the swap blend (proxy_blend.hpp).
//   * invalid (validate() fails, or the host did not set kProxyValid): rejected, counted,
//     kFaultProxyInvalid latched — the contact force fades out (staleness.hpp) until a valid
//     proxy arrives;
//   * sequence not newer than the current one (a transport delivered it late): ignored and
//     counted; it neither refreshes the proxy age nor faults.
// Proxy age is measured on rt_core's clock from the tick that accepted it, so it is right
// even when the host's simulation clock is another machine's.
// A proxy is rendered exactly as the host sent it, held at its reference pose until the next.
#include <array>
#include <cstdint>

#include "fissure/shared/latest_value_exchange.hpp"
#include "fissure/shared/exchanges.hpp"
#include "fissure/shared/message_validation.hpp"
#include "fissure/shared/messages.hpp"
#include "fissure/shared/time.hpp"

namespace fissure::rt {

enum class ProxyIntake : std::uint8_t { kNothingNew, kAccepted, kRejected, kOutOfOrder };

struct ProxyState {
  std::array<ContactProxy, 2> buffers{};  ///< [active] in use; [1 − active] the previous one (see have_previous)
  int active = 0;
  bool have_proxy = false;                ///< a valid proxy was ever accepted
  /// buffers[1 − active] holds the proxy before the active one: true from the tick that accepted
  /// the active proxy until the next fetch, which writes its candidate into that buffer.
  bool have_previous = false;
  bool invalid_latched = false;           ///< newest proxy from the host was invalid
  TimeNs accepted_at_ns = 0;              ///< rt time of the tick that accepted the active proxy
  std::uint64_t accepted_count = 0;
  std::uint64_t rejected_count = 0;
  std::uint64_t out_of_order_count = 0;
  ProxyError last_error = ProxyError::kNone;
};

/// Wait-free: at most one try_fetch (one atomic exchange + a copy) and one validate().
ProxyIntake take_latest_proxy(ProxyExchange& exchange, ProxyState& state, TimeNs now_ns) noexcept;

/// The proxy to evaluate this tick.
inline const ContactProxy& active_proxy(const ProxyState& state) noexcept { return state.buffers[state.active]; }
/// The proxy before it (valid when have_previous).
inline const ContactProxy& previous_proxy(const ProxyState& state) noexcept {
  return state.buffers[1 - state.active];
}

/// Age of the active proxy [ns] (0 when there is none).
inline TimeNs proxy_age_ns(const ProxyState& state, TimeNs now_ns) noexcept {
  return state.have_proxy ? now_ns - state.accepted_at_ns : 0;
}

}  // namespace fissure::rt
