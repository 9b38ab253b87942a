// `fissure rt --transport can:IFACE|udp:HOST:PORT [--device sim|usb] [--scene SCENE] [--seconds N]`
// The rt box of a split deployment (issue 6, docs/deployment.md): device + RtLoop on the rt
// thread (SCHED_FIFO, --rt-policy) + a LinkBridge (role rt) pumped on a service thread, so
// the tick never touches the carrier. The main thread drains telemetry and prints the status.
// Host death needs nothing here: no proxy reaches rt_core, whose staleness stage fades the
// force to zero (stale 0.1 s + fade 0.05 s); this command only reports it.
// Ctrl-C: the loop ramps the force out (safety.hpp) and the command exits 0. A second Ctrl-C kills.
#include "rt_command.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "commands.hpp"
#include "fissure/host_sim/scene_loader.hpp"
#include "fissure/rt_core/rt_config.hpp"
#include "fissure/rt_core/rt_loop.hpp"
#include "fissure/rt_core/rt_thread.hpp"
#include "fissure/shared/latest_value_exchange.hpp"
#include "link_bridge.hpp"
#include "split_device.hpp"

#include "sigint_flag.hpp"

namespace fissure::app {
namespace {

/// Bridge pump period [ns]: a quarter of the 1 kHz tick, so a proxy waits ≤ 0.25 ms in the
/// bridge before rt_core can take it and a DeviceState leaves within 0.25 ms of its tick; at
/// 4 kHz of non-blocking polls the service thread costs a few % of one core.
constexpr TimeNs kPumpPeriod_ns = 250'000;
/// Main-thread drain/status period [ms]: the telemetry ring holds 8 s at 1 kHz.
constexpr int kDrainPeriod_ms = 10;

struct RtOptions {
  std::string transport;
  std::string device = "sim";
  std::string scene;
  double rate_hz = 1000.0;
  double seconds = 0.0;
  std::string rt_policy = "best-effort";
  bool quiet = false;
};

void run(const RtOptions& options) {
  MonotonicClock clock;
  std::optional<host::SceneDescription> scene;
  if (!options.scene.empty()) {
    try {
      scene = host::load_scene(host::resolve_scene_path(options.scene));
    } catch (const std::exception& e) {
      throw CommandError(e.what());
    }
  }
  rt::RtConfig config;
  config.rate_hz = options.rate_hz;
  if (scene) config.mapping = scene->device_mapping;
  rt::RtModel model;
  const char* config_error = nullptr;
  if (!rt::build_model(config, model, &config_error)) throw CommandError(std::string("rt config: ") + config_error);

  std::unique_ptr<transport::FrameCarrier> carrier = open_split_carrier(options.transport, wire::Role::kRt, clock, "fissure rt");
  std::unique_ptr<SplitDevice> device =
      options.device == "usb" ? SplitDevice::open_usb(clock)
                              : SplitDevice::open_sim(scene ? std::optional<HandScript>(scene->hand) : std::nullopt, clock);

  struct Exchanges {
    rt::ProxyExchange proxy;
    rt::DeviceStateExchange state;
    rt::TelemetryRing telemetry;
  };
  auto exchanges = std::make_unique<Exchanges>();
  transport::LinkConfig link_config;
  link_config.role = wire::Role::kRt;
  link_config.publish_rate_hz = static_cast<float>(options.rate_hz);
  link_config.session_id = fresh_session_id();
  LinkBridge bridge(*carrier, clock, link_config, kHostSilentAfter_ns);
  rt::RtLoop loop(model, device->device(), clock, exchanges->proxy, exchanges->state, exchanges->telemetry);

  std::atomic<bool> stop_rt{false};
  std::atomic<bool> rt_done{false};
  std::atomic<bool> rt_refused{false};
  rt::RtSetupReport setup_report;
  const TimeNs start_ns = clock.now();
  const TimeNs end_ns = options.seconds > 0.0 ? start_ns + static_cast<TimeNs>(options.seconds * 1e9)
                                              : std::numeric_limits<TimeNs>::max();
  std::thread rt_thread([&] {
    rt::RtThreadSetup setup;
    rt::RtThreadConfig thread_config;
    thread_config.policy = options.rt_policy == "enforce" ? rt::RtPolicy::kEnforce : rt::RtPolicy::kBestEffort;
    setup_report = setup.apply(thread_config);
    if (!setup_report.ok) {
      rt_refused.store(true);
      rt_done.store(true, std::memory_order_release);
      return;
    }
    loop.run_until(end_ns, stop_rt);
    rt_done.store(true, std::memory_order_release);
  });
  // The service thread: everything that touches the carrier. The main thread sees the bridge
  // only through the snapshots this thread publishes (and reads it directly after the join).
  LatestValueExchange<BridgeStatus> status_exchange;
  std::atomic<bool> stop_service{false};
  std::thread service_thread([&] {
    TimeNs next = clock.now();
    while (!stop_service.load(std::memory_order_relaxed)) {
      bridge.pump_rt(exchanges->state, exchanges->proxy);
      status_exchange.publish(bridge.status());
      next += kPumpPeriod_ns;
      const TimeNs now = clock.now();
      if (now > next) next = now;  // late (loaded machine): no burst of catch-up pumps
      clock.sleep_until(next);
    }
  });

  const bool tty = isatty(STDERR_FILENO) == 1;
  const double status_period_s = tty ? 0.1 : 1.0;
  auto last_status = std::chrono::steady_clock::now();
  BridgeStatus link{};
  bool ever_established = false;
  bool host_was_live = false;
  TimeNs silent_since_ns = 0;
  bool fade_reported = true;
  double force_max_n = 0.0;
  std::uint64_t ticks = 0;
  std::uint64_t proxies_used = 0;
  std::uint64_t last_proxy_sequence = 0;
  std::string refused;
  rt::TelemetrySample sample{};
  rt::TelemetrySample last_sample{};
  spdlog::info("fissure rt: {} on {}, rt_core at {:.0f} Hz, waiting for the host", device->device().name(),
               options.transport, options.rate_hz);
  while (!rt_done.load(std::memory_order_acquire)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(kDrainPeriod_ms));
    if (SigintFlag::raised()) stop_rt.store(true);
    while (exchanges->telemetry.try_pop(sample)) {
      ++ticks;
      const Eigen::Vector3d force = as_eigen(sample.force_device_n);
      force_max_n = std::max(force_max_n, force.norm());
      if (sample.proxy_sequence != last_proxy_sequence) {
        ++proxies_used;
        last_proxy_sequence = sample.proxy_sequence;
      }
      last_sample = sample;
    }
    status_exchange.try_fetch(link);
    if (link.established && !ever_established) {
      ever_established = true;
      spdlog::info("link established with the host");
    }
    if (link.failed) stop_rt.store(true);  // a refused peer sends nothing usable: ramp out and stop
    // Host death (or link loss): report when rt_core's fade has taken the force to zero.
    const bool host_live = link.established && !link.peer_silent;
    if (host_was_live && !host_live) {
      silent_since_ns = clock.now();
      fade_reported = false;
      spdlog::warn("host silent (no proxy for {:.0f} ms): rt_core fades the force to zero", to_seconds(kHostSilentAfter_ns) * 1e3);
    }
    if (!fade_reported && last_sample.fade_gain == 0.0) {
      spdlog::warn("force faded to zero, proxy age {:.1f} ms", to_seconds(last_sample.proxy_age_ns) * 1e3);
      fade_reported = true;
    }
    if (!host_was_live && host_live && silent_since_ns != 0) {
      spdlog::info("host back after {:.0f} ms", to_seconds(clock.now() - silent_since_ns) * 1e3);
    }
    host_was_live = host_live;
    const auto now = std::chrono::steady_clock::now();
    if (!options.quiet && std::chrono::duration<double>(now - last_status).count() >= status_period_s) {
      const std::string line = format_bridge_status(link, wire::Role::kRt);
      std::fprintf(stderr, tty ? "\r[rt %.1f s] |F| %.2f N fade %.2f | %s\033[K" : "[rt %.1f s] |F| %.2f N fade %.2f | %s\n",
                   to_seconds(clock.now() - start_ns), as_eigen(last_sample.force_device_n).norm(), last_sample.fade_gain,
                   line.c_str());
      last_status = now;
    }
  }
  rt_thread.join();
  stop_service.store(true);
  service_thread.join();
  if (!options.quiet && tty) std::fprintf(stderr, "\n");
  if (rt_refused.load()) throw CommandError(std::string("--rt-policy enforce: ") + setup_report.message);
  if (setup_report.message[0] != '\0') spdlog::warn("rt thread: {}", setup_report.message);
  link = bridge.status();
  if (link.failed) refused = link.error;
  std::printf("fissure rt: %.2f s, %llu ticks, overruns %llu | link %s | proxies used %llu | force max %.2f N | "
              "discards %llu frames / %llu msgs | host restarts %llu%s\n",
              to_seconds(clock.now() - start_ns), static_cast<unsigned long long>(loop.stats().ticks),
              static_cast<unsigned long long>(loop.stats().overruns), ever_established ? "established" : "never established",
              static_cast<unsigned long long>(proxies_used), force_max_n,
              static_cast<unsigned long long>(link.frames_discarded), static_cast<unsigned long long>(link.messages_discarded),
              static_cast<unsigned long long>(link.peer_restarts), SigintFlag::raised() ? " | stopped by Ctrl-C" : "");
  if (!refused.empty()) throw CommandError(refused);
}

}  // namespace

void register_rt_command(CommandTree& tree) {
  auto options = std::make_shared<RtOptions>();
  CLI::App* cmd = tree.root.add_subcommand(
      "rt", "Split deployment, rt box: Falcon + rt_core, proxies from a 'fissure host' over CAN FD or UDP");
  cmd->add_option("--transport", options->transport, "can:IFACE or udp:HOST:PORT (HOST:PORT = this box's address)")
      ->required();
  cmd->add_option("--device", options->device, "sim (SimFalcon) or usb (the real Falcon)")->check(CLI::IsMember({"sim", "usb"}));
  cmd->add_option("--scene", options->scene,
                  "scene whose device mapping (and, for sim, hand script) to use — the host must run the same scene");
  cmd->add_option("--rate", options->rate_hz, "rt tick rate [Hz] (500..10000)")->check(CLI::Range(500.0, 10000.0));
  cmd->add_option("--seconds", options->seconds, "run this long, then ramp out (default: until Ctrl-C)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--rt-policy", options->rt_policy, "best-effort (warn and run without SCHED_FIFO) or enforce (fail)")
      ->check(CLI::IsMember({"best-effort", "enforce"}));
  cmd->add_flag("--quiet", options->quiet, "no status line");
  cmd->callback([options] {
    const SigintFlag sigint;
    run(*options);
  });
}

}  // namespace fissure::app
