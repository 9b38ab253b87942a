#include "fissure/shared/clock.hpp"

#include <cerrno>
#include <ctime>

namespace fissure {
namespace {

timespec to_timespec(TimeNs t_ns) noexcept {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(t_ns / kNanosecondsPerSecond);
  ts.tv_nsec = static_cast<long>(t_ns % kNanosecondsPerSecond);
  return ts;
}

}  // namespace

TimeNs MonotonicClock::now() const noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<TimeNs>(ts.tv_sec) * kNanosecondsPerSecond + ts.tv_nsec;
}

TimeNs MonotonicClock::sleep_until(TimeNs deadline) noexcept {
  const timespec ts = to_timespec(deadline);
  // Absolute deadline: a signal interrupting the sleep just resumes it (EINTR), and no
  // error accumulates across periods the way relative sleeps would.
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
  return now();
}

TimeNs LockstepClock::sleep_until(TimeNs deadline) noexcept {
  TimeNs current = now_ns_.load(std::memory_order_acquire);
  while (current < deadline &&
         !now_ns_.compare_exchange_weak(current, deadline, std::memory_order_acq_rel)) {
  }
  return now_ns_.load(std::memory_order_acquire);
}

TimeNs LockstepClock::advance(TimeNs dt_ns) noexcept {
  if (dt_ns < 0) dt_ns = 0;
  return now_ns_.fetch_add(dt_ns, std::memory_order_acq_rel) + dt_ns;
}

}  // namespace fissure
