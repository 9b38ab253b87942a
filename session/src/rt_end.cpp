#include "fissure/session/rt_end.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <thread>

#include "fissure/rt_core/faults.hpp"
#include "fissure/rt_core/rt_config.hpp"
#include "fissure/session/console_log.hpp"
#include "fissure/session/host_loop.hpp"
#include "fissure/session/link_bridge.hpp"
#include "fissure/session/rt_stack.hpp"
#include "fissure/session/session_error.hpp"
#include "fissure/session/split_device.hpp"
#include "fissure/shared/latest_value_exchange.hpp"

namespace fissure::session {
namespace {

/// Bridge pump period [ns]: a quarter of the 1 kHz tick, so a proxy waits ≤ 0.25 ms in the
/// bridge before rt_core can take it and a DeviceState leaves within 0.25 ms of its tick; at
/// 4 kHz of non-blocking polls the service thread costs a few % of one core.
constexpr TimeNs kPumpPeriod_ns = 250'000;
/// Supervision (drain/status) period [ms]: the telemetry ring holds 8 s at 1 kHz.
constexpr int kDrainPeriod_ms = 10;

bool interrupted(const RtEndOptions& options) {
  return options.interrupt != nullptr && options.interrupt->load(std::memory_order_relaxed);
}

/// What happened to the link, for the summary line: "never established", "established at 0.31 s,
/// host live at the end", "established at 0.31 s, closed cleanly by the host at 3.20 s", or
/// "established at 0.31 s, host silent from 3.20 s to the end (2 losses)". A host that stops says
/// goodbye (the Hello's kHelloClosing flag); one that dies or is cut off just goes silent.
std::string describe_link(const RtEndOutcome& outcome) {
  if (!outcome.link_established) return "never established";
  char text[160];
  if (outcome.host_closed_at_s >= 0.0) {
    std::snprintf(text, sizeof text, "established at %.2f s, closed cleanly by the host at %.2f s (%llu loss%s)",
                  outcome.link_established_at_s, outcome.host_closed_at_s, static_cast<unsigned long long>(outcome.host_losses),
                  outcome.host_losses == 1 ? "" : "es");
  } else if (outcome.host_lost_at_s >= 0.0) {
    std::snprintf(text, sizeof text, "established at %.2f s, host silent from %.2f s to the end (%llu loss%s)",
                  outcome.link_established_at_s, outcome.host_lost_at_s, static_cast<unsigned long long>(outcome.host_losses),
                  outcome.host_losses == 1 ? "" : "es");
  } else {
    std::snprintf(text, sizeof text, "established at %.2f s, host live at the end (%llu loss%s)", outcome.link_established_at_s,
                  static_cast<unsigned long long>(outcome.host_losses), outcome.host_losses == 1 ? "" : "es");
  }
  return text;
}

}  // namespace

RtEndOutcome run_rt_end(const RtEndOptions& options) {
  MonotonicClock clock;
  rt::RtConfig config;
  config.rate_hz = options.rate_hz;
  config.mapping = options.device_mapping;
  const rt::RtModel model = build_rt_model(config);

  std::unique_ptr<transport::FrameCarrier> carrier = open_split_carrier(options.transport, wire::Role::kRt, clock, options.program);
  std::unique_ptr<SplitDevice> device = options.usb_device ? SplitDevice::open_usb(clock) : SplitDevice::open_sim(options.hand, clock);

  RtStack rt(model, device->device(), clock);
  RtChannels& channels = rt.channels();
  transport::LinkConfig link_config;
  link_config.role = wire::Role::kRt;
  link_config.publish_rate_hz = static_cast<float>(options.rate_hz);
  link_config.session_id = fresh_session_id();
  if (!options.scene_name.empty()) {
    link_config.identity = wire::session_identity(options.scene_name, options.device_mapping);
  } else {
    log_warn("%s: no --scene: the default device mapping, and the host's scene is not checked against it", options.program);
  }
  LinkBridge bridge(*carrier, clock, link_config, kHostSilentAfter_ns);

  std::atomic<bool> stop_rt{false};
  const TimeNs start_ns = clock.now();
  const TimeNs end_ns = options.seconds > 0.0 ? start_ns + static_cast<TimeNs>(options.seconds * 1e9)
                                              : std::numeric_limits<TimeNs>::max();
  rt::RtThreadConfig thread_config;
  thread_config.policy = options.policy;
  RtThread rt_thread(thread_config, [&] { rt.loop().run_until(end_ns, stop_rt); });
  // The service thread: everything that touches the carrier. The supervising thread sees the
  // bridge only through the snapshots this thread publishes (and reads it directly after the join).
  LatestValueExchange<BridgeStatus> status_exchange;
  std::atomic<bool> stop_service{false};
  std::thread service_thread([&] {
    HostLoop pump(clock);
    pump.run(kPumpPeriod_ns, stop_service, [&] {
      bridge.pump_rt(channels.state, channels.proxy);
      status_exchange.publish(bridge.status());
      return true;
    });
  });

  const bool tty = isatty(STDERR_FILENO) == 1;
  const double status_period_s = tty ? 0.1 : 1.0;
  auto last_status = std::chrono::steady_clock::now();
  BridgeStatus link{};
  RtEndOutcome outcome;
  bool host_was_live = false;
  TimeNs silent_since_ns = 0;
  bool fade_reported = true;
  std::uint64_t last_proxy_sequence = 0;
  rt::TelemetrySample sample{};
  rt::TelemetrySample last_sample{};
  log_info("%s: %s on %s, rt_core at %.0f Hz, waiting for the host", options.program, device->device().name(),
           options.transport.c_str(), options.rate_hz);
  while (!rt_thread.done()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(kDrainPeriod_ms));
    if (interrupted(options)) stop_rt.store(true);
    while (channels.telemetry.try_pop(sample)) {
      outcome.force_max_n = std::max(outcome.force_max_n, as_eigen(sample.force_device_n).norm());
      if ((sample.fault_bits & rt::kDeviceSideFaults) != 0) ++outcome.device_fault_ticks;
      if ((sample.fault_bits & rt::kFaultProxyStale) != 0) ++outcome.proxy_stale_ticks;
      if (sample.proxy_sequence != last_proxy_sequence) {
        ++outcome.proxies_used;
        last_proxy_sequence = sample.proxy_sequence;
      }
      last_sample = sample;
    }
    status_exchange.try_fetch(link);
    if (link.established && !outcome.link_established) {
      outcome.link_established = true;
      outcome.link_established_at_s = to_seconds(clock.now() - start_ns);
      log_info("link established with the host");
    }
    if (link.failed) stop_rt.store(true);  // a refused peer sends nothing usable: ramp out and stop
    if (link.peer_closed && outcome.host_closed_at_s < 0.0) {
      outcome.host_closed_at_s = to_seconds(clock.now() - start_ns);
      log_info("the host closed the link cleanly: rt_core fades the force to zero");
    } else if (!link.peer_closed) {
      outcome.host_closed_at_s = -1.0;  // a host that came back is live again
    }
    // Host death (or link loss): report when rt_core's fade has taken the force to zero.
    const bool host_live = link.established && !link.peer_silent;
    if (host_was_live && !host_live && link.peer_closed) {
      silent_since_ns = clock.now();
      fade_reported = false;
    } else if (host_was_live && !host_live) {
      silent_since_ns = clock.now();
      outcome.host_lost_at_s = to_seconds(silent_since_ns - kHostSilentAfter_ns - start_ns);
      ++outcome.host_losses;
      fade_reported = false;
      log_warn("host silent (no proxy for %.0f ms): rt_core fades the force to zero", to_seconds(kHostSilentAfter_ns) * 1e3);
    }
    if (!fade_reported && last_sample.fade_gain == 0.0) {
      log_warn("force faded to zero, proxy age %.1f ms", to_seconds(last_sample.proxy_age_ns) * 1e3);
      fade_reported = true;
    }
    if (!host_was_live && host_live && silent_since_ns != 0) {
      log_info("host back after %.0f ms", to_seconds(clock.now() - silent_since_ns) * 1e3);
      outcome.host_lost_at_s = -1.0;
    }
    host_was_live = host_live;
    const auto now = std::chrono::steady_clock::now();
    if (options.status_line && std::chrono::duration<double>(now - last_status).count() >= status_period_s) {
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
  if (bridge.established()) bridge.close();  // the host reports "closed by rt_core", not a lost link
  if (options.status_line && tty) std::fprintf(stderr, "\n");
  const rt::RtSetupReport& setup = rt_thread.setup_report();
  if (rt_thread.refused()) throw SessionError(std::string("--rt-policy enforce: ") + setup.message);
  if (setup.message[0] != '\0') log_warn("rt thread: %s", setup.message);
  link = bridge.status();
  outcome.seconds = to_seconds(clock.now() - start_ns);
  outcome.ticks = rt.loop().stats().ticks;
  outcome.overruns = rt.loop().stats().overruns;
  outcome.frames_discarded = link.frames_discarded;
  outcome.messages_discarded = link.messages_discarded;
  outcome.host_restarts = link.peer_restarts;
  outcome.proxies_rejected = rt.loop().data().proxy.rejected_count;
  outcome.interrupted = interrupted(options);
  const std::string link_story = describe_link(outcome);
  std::printf("%s: %.2f s, %llu ticks, overruns %llu | link %s | proxies used %llu | force max %.2f N | "
              "discards %llu frames / %llu msgs | host restarts %llu | device fault ticks %llu | proxies rejected %llu | "
              "stale-proxy ticks %llu%s\n",
              options.program, outcome.seconds, static_cast<unsigned long long>(outcome.ticks),
              static_cast<unsigned long long>(outcome.overruns), link_story.c_str(),
              static_cast<unsigned long long>(outcome.proxies_used), outcome.force_max_n,
              static_cast<unsigned long long>(outcome.frames_discarded), static_cast<unsigned long long>(outcome.messages_discarded),
              static_cast<unsigned long long>(outcome.host_restarts), static_cast<unsigned long long>(outcome.device_fault_ticks),
              static_cast<unsigned long long>(outcome.proxies_rejected), static_cast<unsigned long long>(outcome.proxy_stale_ticks),
              outcome.interrupted ? " | stopped by Ctrl-C" : "");
  std::fflush(stdout);
  if (link.failed) throw SessionError(link.error);
  if (!outcome.link_established) {
    throw SessionError("no host answered on " + options.transport +
                       ": link never established (is `fissure host` running with its --transport pointing at this end?)");
  }
  if (outcome.host_lost_at_s >= 0.0 && outcome.host_closed_at_s < 0.0) {
    char text[160];
    std::snprintf(text, sizeof text, "link lost: the host went silent at %.2f s without closing the link (crashed, killed or cut off)",
                  outcome.host_lost_at_s);
    throw SessionError(text);
  }
  return outcome;
}

}  // namespace fissure::session
