#pragma once
// The loop owner (libfranka's control loop, ros2_control's realtime thread): owns timing,
// the model and the data, and calls tick() once per period.
//   * deadlines are absolute: next += period, Clock::sleep_until(next) — clock_nanosleep
//     TIMER_ABSTIME on the MonotonicClock, a jump on the LockstepClock;
//   * a tick that ends past the next deadline is an overrun: the missed periods are
//     counted and skipped (next moves on by whole periods), so the schedule never drifts
//     and never bursts to catch up;
//   * wake-up latency (woke − deadline) goes into a 1 µs histogram (cyclictest's measure).
// The same object runs in real time (run(), on a thread prepared by RtThreadSetup) and in
// lockstep (step()/run_ticks(), driven by a test on a LockstepClock — no threads needed).
// Stopping ramps the force out (safety.hpp) and ends with one zero-force exchange.
#include <atomic>
#include <cstdint>

#include "fissure/falcon_hw/haptic_device.hpp"
#include "fissure/rt_core/latency_histogram.hpp"
#include "fissure/rt_core/rt_config.hpp"
#include "fissure/rt_core/rt_data.hpp"
#include "fissure/rt_core/telemetry.hpp"
#include "fissure/rt_core/tick.hpp"
#include "fissure/shared/clock.hpp"

namespace fissure::rt {

struct LoopStats {
  std::uint64_t ticks = 0;
  std::uint64_t overruns = 0;         ///< periods skipped because a tick ended past its next deadline
  TimeNs max_tick_ns = 0;             ///< longest tick (clock time, incl. device I/O; 0 in lockstep)
  LatencyHistogram wakeup{};          ///< woke − deadline, 1 µs bins
};

class RtLoop {
 public:
  /// `model` must be built (build_model); everything referenced must outlive the loop.
  /// The data is reset here (ramp-in armed). Allocation-free afterwards.
  RtLoop(const RtModel& model, falcon::HapticDevice& device, Clock& clock, ProxyExchange& proxy_in,
         DeviceStateExchange& state_out, TelemetryRing& telemetry) noexcept;

  /// Sleeps until the next deadline, ticks once. Lockstep tests call this directly.
  TickResult step() noexcept;
  /// step() n times (stops early once the ramp-out has finished); returns ticks run.
  std::uint64_t run_ticks(std::uint64_t n) noexcept;

  /// Runs until `stop` becomes true (checked every tick), then ramps out and sends a final
  /// zero command. Call on the thread RtThreadSetup prepared.
  void run(const std::atomic<bool>& stop) noexcept;
  /// Same, but also requests the stop by itself once the clock reaches `end_ns`.
  void run_until(TimeNs end_ns, const std::atomic<bool>& stop) noexcept;

  /// Asks for the ramp-out (takes effect at the next step()); safe from any thread.
  void request_stop() noexcept { stop_requested_.store(true, std::memory_order_relaxed); }
  /// One exchange with a zero command: the device is left without force. Called by run()
  /// at the end; lockstep users call it after the ramp-out.
  void send_zero_command() noexcept;

  [[nodiscard]] const RtModel& model() const noexcept { return model_; }
  [[nodiscard]] const RtData& data() const noexcept { return data_; }
  [[nodiscard]] const LoopStats& stats() const noexcept { return stats_; }
  [[nodiscard]] bool stopped() const noexcept { return data_.safety.phase == RampPhase::kStopped; }
  /// Forget the timing statistics (e.g. after a warm-up).
  void clear_stats() noexcept;

 private:
  const RtModel& model_;
  Clock& clock_;
  TickIo io_;
  RtData data_{};
  LoopStats stats_{};
  TimeNs next_deadline_ns_ = 0;
  bool started_ = false;
  std::atomic<bool> stop_requested_{false};
};

}  // namespace fissure::rt
