#include "fissure/session/host_loop.hpp"

namespace fissure::session {

void HostLoop::wait_next(TimeNs period_ns, bool count_late) noexcept {
  next_ns_ += period_ns;
  const TimeNs now = clock_.now();
  if (now >= next_ns_ + period_ns) {
    if (count_late) late_steps_.fetch_add(1, std::memory_order_relaxed);
    next_ns_ = now;
  } else if (now < next_ns_) {
    clock_.sleep_until(next_ns_);
  }
}

}  // namespace fissure::session
