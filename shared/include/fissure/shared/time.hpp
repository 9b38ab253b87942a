#pragma once
// Time in Fissure is a signed 64-bit count of nanoseconds on one monotonic timeline
// (CLOCK_MONOTONIC in deployment, the lockstep clock in tests). 2^63 ns ≈ 292 years.
#include <cstdint>

namespace fissure {

using TimeNs = std::int64_t;

inline constexpr TimeNs kNanosecondsPerSecond = 1'000'000'000;

constexpr double to_seconds(TimeNs t_ns) noexcept { return static_cast<double>(t_ns) * 1e-9; }
constexpr TimeNs from_seconds(double t_s) noexcept { return static_cast<TimeNs>(t_s * 1e9); }
/// Period of a loop running at `rate_hz`, rounded to the nearest nanosecond.
constexpr TimeNs period_from_rate_hz(double rate_hz) noexcept {
  return static_cast<TimeNs>(1e9 / rate_hz + 0.5);
}

}  // namespace fissure
