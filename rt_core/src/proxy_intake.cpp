#include "fissure/rt_core/proxy_intake.hpp"

namespace fissure::rt {

ProxyIntake take_latest_proxy(ProxyExchange& exchange, ProxyState& state, TimeNs now_ns) noexcept {
  // Fetch straight into the inactive buffer. If the candidate is rejected, that buffer no
  // longer holds the previous proxy; the blend only needs it on an accepted swap.
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
  if (state.have_proxy && candidate.sequence <= active_proxy(state).sequence) {
    ++state.out_of_order_count;
    return ProxyIntake::kOutOfOrder;
  }
  state.have_previous = state.have_proxy;
  state.active = 1 - state.active;
  state.have_proxy = true;
  state.invalid_latched = false;
  state.accepted_at_ns = now_ns;
  ++state.accepted_count;
  return ProxyIntake::kAccepted;
}

}  // namespace fissure::rt
