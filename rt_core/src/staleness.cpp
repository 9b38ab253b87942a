#include "fissure/rt_core/staleness.hpp"

#include <algorithm>

namespace fissure::rt {

double update_fade(const ProxyConfig& config, FadeState& state, bool proxy_usable, double period_s) noexcept {
  const double step = config.fade_s > 0.0 ? period_s / config.fade_s : 1.0;
  state.gain = proxy_usable ? std::min(1.0, state.gain + step) : std::max(0.0, state.gain - step);
  return state.gain;
}

}  // namespace fissure::rt
