#include "fissure/rt_core/rt_loop.hpp"

#include <algorithm>
#include <cstring>

namespace fissure::rt {

RtLoop::RtLoop(const RtModel& model, falcon::HapticDevice& device, Clock& clock, ProxyExchange& proxy_in,
               DeviceStateExchange& state_out, TelemetryRing& telemetry) noexcept
    : model_(model), clock_(clock), io_{device, proxy_in, state_out, telemetry} {
  reset_data(model_, data_);
  data_.device_is_simulated = std::strcmp(device.name(), "sim-falcon") == 0;
}

TickResult RtLoop::step() noexcept {
  const TimeNs period = model_.period_ns;
  if (!started_) {
    next_deadline_ns_ = clock_.now() + period;
    started_ = true;
  }
  const TimeNs woke_ns = clock_.sleep_until(next_deadline_ns_);
  const TimeNs latency_ns = woke_ns - next_deadline_ns_;
  stats_.wakeup.add(latency_ns);

  TickTiming timing;
  timing.now_ns = woke_ns;
  timing.wakeup_latency_ns = latency_ns;
  timing.overruns = stats_.overruns;
  timing.stop_requested = stop_requested_.load(std::memory_order_relaxed);
  const TickResult result = tick(model_, data_, io_, timing);
  ++stats_.ticks;

  next_deadline_ns_ += period;
  const TimeNs done_ns = clock_.now();
  stats_.max_tick_ns = std::max(stats_.max_tick_ns, done_ns - woke_ns);
  if (done_ns > next_deadline_ns_) {
    // Skip the periods we missed instead of bursting through them: a burst would hand the
    // device several commands in a row computed from stale samples.
    const TimeNs missed = (done_ns - next_deadline_ns_) / period + 1;
    stats_.overruns += static_cast<std::uint64_t>(missed);
    next_deadline_ns_ += missed * period;
  }
  return result;
}

std::uint64_t RtLoop::run_ticks(std::uint64_t n) noexcept {
  std::uint64_t done = 0;
  while (done < n && !stopped()) {
    step();
    ++done;
  }
  return done;
}

void RtLoop::run(const std::atomic<bool>& stop) noexcept {
  while (!stopped()) {
    if (stop.load(std::memory_order_relaxed)) request_stop();
    step();
  }
  send_zero_command();
}

void RtLoop::run_until(TimeNs end_ns, const std::atomic<bool>& stop) noexcept {
  while (!stopped()) {
    if (stop.load(std::memory_order_relaxed) || clock_.now() >= end_ns) request_stop();
    step();
  }
  send_zero_command();
}

void RtLoop::send_zero_command() noexcept {
  data_.pending_command.motor_counts = {0, 0, 0};
  falcon::DeviceReading reading;
  io_.device.try_exchange(data_.pending_command, reading);
}

void RtLoop::clear_stats() noexcept {
  stats_.ticks = 0;
  stats_.overruns = 0;
  stats_.max_tick_ns = 0;
  stats_.wakeup.clear();
}

}  // namespace fissure::rt
