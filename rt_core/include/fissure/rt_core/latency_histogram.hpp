#pragma once
// Wake-up latency histogram filled by the loop (no allocation: fixed 1 µs bins).
// 1 µs bins match cyclictest's histogram (-h), so the two distributions compare bin for bin.
#include <array>
#include <cstdint>

#include "fissure/shared/time.hpp"

namespace fissure::rt {

/// Bins of 1 µs up to 20 ms; later samples land in the overflow count (the max is exact).
inline constexpr std::size_t kLatencyHistogramBins = 20'000;

struct LatencyHistogram {
  std::array<std::uint32_t, kLatencyHistogramBins> bins{};
  std::uint64_t count = 0;
  std::uint64_t overflow = 0;
  TimeNs max_ns = 0;
  TimeNs min_ns = 0;

  void add(TimeNs latency_ns) noexcept;
  void clear() noexcept { *this = LatencyHistogram{}; }
  /// Latency [µs] of the sample at quantile q, truncated to whole µs the way cyclictest
  /// reports (lower bin edge); q = 1 gives the exact max.
  [[nodiscard]] double quantile_us(double q) const noexcept;
};

}  // namespace fissure::rt
