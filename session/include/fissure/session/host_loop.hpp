#pragma once
// The host's periodic schedule, the counterpart of rt_core's RtLoop for the soft real-time
// threads of a session (the host pipeline step, a link bridge's pump):
//   * deadlines are absolute: next += period, Clock::sleep_until(next);
//   * a step that ends a whole period or more behind the next deadline is counted late and
//     the schedule restarts from now, so a stall never turns into a burst of catch-up steps;
//   * less than a period late (a late wake-up on a loaded machine), the next step starts at
//     once and the schedule is kept, so the average rate stays the requested one.
// The period may change between steps (the split host pumps its link every millisecond while
// rt_core is silent and steps the scene at its own rate otherwise). Lockstep sessions do not
// use it: they interleave rt ticks and host steps on one thread.
#include <atomic>
#include <cstdint>

#include "fissure/shared/clock.hpp"

namespace fissure::session {

class HostLoop {
 public:
  /// `clock` must outlive the loop; the first deadline is one period after construction.
  explicit HostLoop(Clock& clock) noexcept : clock_(clock), next_ns_(clock.now()) {}

  /// Waits for the deadline `period_ns` after the previous one. `count_late`: whether a step
  /// that ran a whole period over counts as late (a paused host's idle pumps do not).
  void wait_next(TimeNs period_ns, bool count_late = true) noexcept;

  /// Calls step() once per period until `stop` is set or step() returns false.
  template <class Step>
  void run(TimeNs period_ns, const std::atomic<bool>& stop, Step&& step) {
    while (!stop.load(std::memory_order_relaxed)) {
      if (!step()) return;
      wait_next(period_ns);
    }
  }

  /// Steps that ended a whole period or more behind their schedule.
  [[nodiscard]] std::uint64_t late_steps() const noexcept { return late_steps_.load(std::memory_order_relaxed); }

 private:
  Clock& clock_;
  TimeNs next_ns_;
  std::atomic<std::uint64_t> late_steps_{0};  ///< read by the session's main thread
};

}  // namespace fissure::session
