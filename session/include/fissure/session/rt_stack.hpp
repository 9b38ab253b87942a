#pragma once
// rt_core as every session and benchmark runs it, assembled in one place: the model built from
// an RtConfig, the three wait-free channels the loop talks through, and the RtLoop over a
// device and a clock; and the thread that runs such a loop in real time (RtThreadSetup's
// policy applied on that thread before the first tick).
#include <atomic>
#include <functional>
#include <memory>
#include <thread>

#include "fissure/falcon_hw/haptic_device.hpp"
#include "fissure/rt_core/rt_config.hpp"
#include "fissure/rt_core/rt_loop.hpp"
#include "fissure/rt_core/rt_thread.hpp"
#include "fissure/rt_core/telemetry.hpp"
#include "fissure/shared/clock.hpp"
#include "fissure/shared/exchanges.hpp"

namespace fissure::session {

/// The channels between rt_core and the rest of a session. Large (the telemetry ring holds
/// 8 s at 1 kHz, ~2 MB): RtStack keeps them on the heap, allocated once before the loop.
struct RtChannels {
  ProxyExchange proxy;        ///< host (or link bridge) → rt_core
  DeviceStateExchange state;  ///< rt_core → host (or link bridge)
  rt::TelemetryRing telemetry;
};

/// rt_core's model for `config`; throws SessionError ("rt config: …") when it does not build.
/// Sessions build it before their slow set-up (settling, homing) so a bad rate fails at once.
[[nodiscard]] rt::RtModel build_rt_model(const rt::RtConfig& config);

class RtStack {
 public:
  /// `model` (see build_rt_model), `device` and `clock` must outlive the stack.
  RtStack(const rt::RtModel& model, falcon::HapticDevice& device, Clock& clock);
  RtStack(const RtStack&) = delete;
  RtStack& operator=(const RtStack&) = delete;

  [[nodiscard]] rt::RtLoop& loop() noexcept { return *loop_; }
  [[nodiscard]] const rt::RtLoop& loop() const noexcept { return *loop_; }
  [[nodiscard]] RtChannels& channels() noexcept { return *channels_; }

 private:
  std::unique_ptr<RtChannels> channels_;
  std::unique_ptr<rt::RtLoop> loop_;
};

/// A thread prepared for real time (RtThreadSetup::apply with `config`) that then runs `body`
/// — typically RtLoop::run_until. If the policy is kEnforce and the set-up is refused, `body`
/// does not run. done() turns true when the thread has finished either way.
class RtThread {
 public:
  RtThread(const rt::RtThreadConfig& config, std::function<void()> body);
  ~RtThread();
  RtThread(const RtThread&) = delete;
  RtThread& operator=(const RtThread&) = delete;

  [[nodiscard]] bool done() const noexcept { return done_.load(std::memory_order_acquire); }
  void join();
  /// Valid after join(): what the set-up achieved and how long it took [s].
  [[nodiscard]] const rt::RtSetupReport& setup_report() const noexcept { return report_; }
  [[nodiscard]] double setup_seconds() const noexcept { return setup_s_; }
  [[nodiscard]] bool refused() const noexcept { return !report_.ok; }

 private:
  rt::RtSetupReport report_{};
  double setup_s_ = 0.0;
  std::atomic<bool> done_{false};
  std::thread thread_;
};

}  // namespace fissure::session
