#include "fissure/rt_core/latency_histogram.hpp"

#include <algorithm>
#include <cmath>

namespace fissure::rt {

void LatencyHistogram::add(TimeNs latency_ns) noexcept {
  if (latency_ns < 0) latency_ns = 0;  // woke before the deadline: cannot happen with TIMER_ABSTIME
  min_ns = count == 0 ? latency_ns : std::min(min_ns, latency_ns);
  max_ns = std::max(max_ns, latency_ns);
  ++count;
  const auto bin = static_cast<std::size_t>(latency_ns / 1000);
  if (bin < bins.size()) {
    ++bins[bin];
  } else {
    ++overflow;
  }
}

double LatencyHistogram::quantile_us(double q) const noexcept {
  if (count == 0) return 0.0;
  if (q >= 1.0) return static_cast<double>(max_ns) * 1e-3;
  const auto rank = static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(count)));
  std::uint64_t seen = 0;
  for (std::size_t i = 0; i < bins.size(); ++i) {
    seen += bins[i];
    if (seen >= rank) return static_cast<double>(i);
  }
  return static_cast<double>(max_ns) * 1e-3;
}

}  // namespace fissure::rt
