#pragma once
// Injectable time (BRIEF §2): deployment uses MonotonicClock, tests and benchmarks a
// LockstepClock that the test (or the lockstep session runner) advances explicitly,
// so everything involving time is deterministic and runs as fast as the CPU allows.
#include <atomic>

#include "fissure/shared/time.hpp"

namespace fissure {

class Clock {
 public:
  virtual ~Clock() = default;
  /// Current time on the shared monotonic timeline. Wait-free, callable from the RT tick.
  [[nodiscard]] virtual TimeNs now() const noexcept = 0;
  /// Returns once now() ≥ deadline and reports now() at that moment. The real clock
  /// sleeps (clock_nanosleep, TIMER_ABSTIME); the lockstep clock jumps to the deadline.
  virtual TimeNs sleep_until(TimeNs deadline) noexcept = 0;
};

/// CLOCK_MONOTONIC with absolute-deadline sleeps (no drift from relative sleeps).
class MonotonicClock final : public Clock {
 public:
  [[nodiscard]] TimeNs now() const noexcept override;
  TimeNs sleep_until(TimeNs deadline) noexcept override;
};

/// Simulated time that only moves when told to. Thread-safe: one driver thread advances,
/// any thread may read. sleep_until() moves time forward to the deadline (never back),
/// which is what a single-threaded lockstep loop wants.
class LockstepClock final : public Clock {
 public:
  explicit LockstepClock(TimeNs start = 0) noexcept : now_ns_(start) {}
  [[nodiscard]] TimeNs now() const noexcept override { return now_ns_.load(std::memory_order_acquire); }
  TimeNs sleep_until(TimeNs deadline) noexcept override;
  /// Moves time forward by `dt_ns` ≥ 0 and returns the new time.
  TimeNs advance(TimeNs dt_ns) noexcept;

 private:
  std::atomic<TimeNs> now_ns_;
};

}  // namespace fissure
