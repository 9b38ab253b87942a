#include "fissure/session/host_end.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "fissure/session/console_log.hpp"
#include "fissure/session/host_loop.hpp"
#include "fissure/session/link_bridge.hpp"
#include "fissure/session/scene_plausibility.hpp"
#include "fissure/session/session_error.hpp"
#include "fissure/session/session_host.hpp"
#include "fissure/session/split_device.hpp"

namespace fissure::session {
namespace {

/// While paused or waiting for the link the host still pumps the bridge this often [ns]:
/// Hellos get answered and a returning rt_core is seen within a millisecond.
constexpr TimeNs kIdlePumpPeriod_ns = 1'000'000;

bool interrupted(const HostEndOptions& options) {
  return options.interrupt != nullptr && options.interrupt->load(std::memory_order_relaxed);
}

}  // namespace

HostEndOutcome run_host_end(const HostEndOptions& options) {
  const host::SceneDescription& scene = options.scene;
  MonotonicClock clock;
  std::unique_ptr<transport::FrameCarrier> carrier = open_split_carrier(options.transport, wire::Role::kHost, clock, "fissure host");
  std::unique_ptr<SessionHost> host;
  try {
    host = std::make_unique<SessionHost>(scene);
  } catch (const std::exception& e) {
    throw SessionError(e.what());
  }
  const Eigen::AlignedBox3d loaded_bounds = host->simulation().soft_bounds_world_m();
  host->settle(options.settle_s);
  const std::string settle_warning =
      check_settled_on_ground(loaded_bounds, host->simulation().soft_bounds_world_m(), scene, options.settle_s);
  if (!settle_warning.empty()) std::fprintf(stderr, "fissure host: warning: %s\n", settle_warning.c_str());

  const double host_dt_s = scene.simulation.time_step_s;
  const auto period_ns = static_cast<TimeNs>(std::llround(host_dt_s * 1e9));
  transport::LinkConfig link_config;
  link_config.role = wire::Role::kHost;
  link_config.publish_rate_hz = static_cast<float>(1.0 / host_dt_s);
  link_config.session_id = fresh_session_id();
  link_config.identity = wire::session_identity(scene.name, scene.device_mapping);
  LinkBridge bridge(*carrier, clock, link_config, kRtSilentAfter_ns);
  DeviceStateExchange state_in;
  ProxyExchange proxy_out;

  const TimeNs start_ns = clock.now();
  const TimeNs end_ns = options.seconds > 0.0 ? start_ns + static_cast<TimeNs>(options.seconds * 1e9) : 0;
  const auto connect_deadline_ns = start_ns + static_cast<TimeNs>(options.connect_timeout_s * 1e9);
  const bool tty = isatty(STDERR_FILENO) == 1;
  const TimeNs status_period_ns = tty ? 100'000'000 : 1'000'000'000;
  TimeNs last_status_ns = start_ns;
  TimeNs established_at_ns = -1;
  TimeNs paused_since_ns = -1;
  TimeNs paused_total_ns = 0;
  HostEndOutcome outcome;
  HostStatus last{};
  log_info("fissure host: scene '%s' at %.0f Hz, connecting to rt_core over %s", scene.name.c_str(), 1.0 / host_dt_s,
           options.transport.c_str());
  HostLoop schedule(clock);
  for (;;) {
    const TimeNs now = clock.now();
    if (interrupted(options) || (end_ns != 0 && now >= end_ns)) break;
    bridge.pump_host(state_in, proxy_out);
    if (bridge.failed()) throw SessionError(bridge.status().error);
    if (established_at_ns < 0 && bridge.established()) {
      established_at_ns = now;
      log_info("link established with rt_core after %.0f ms", to_seconds(now - start_ns) * 1e3);
    }
    if (established_at_ns < 0 && now >= connect_deadline_ns) {
      throw SessionError("rt_core at " + options.transport + " never answered: link not established within " +
                         std::to_string(options.connect_timeout_s) + " s (is 'fissure rt --transport " + options.transport +
                         "' running?)");
    }
    // Step only while rt_core is alive and talking: a scene stepped towards a stale tool
    // pose would drift away from where the hand really is.
    const bool rt_live = bridge.established() && !bridge.peer_silent();
    if (rt_live) {
      if (paused_since_ns >= 0) {
        log_info("rt_core back after %.0f ms: scene resumed", to_seconds(now - paused_since_ns) * 1e3);
        paused_total_ns += now - paused_since_ns;
        paused_since_ns = -1;
      }
      try {
        last = host->step(state_in, proxy_out);
      } catch (const std::exception& e) {
        throw SessionError(std::string("host step: ") + e.what());
      }
      bridge.pump_host(state_in, proxy_out);  // the proxy leaves now, not a period later
      outcome.crossed_nodes_max = std::max(outcome.crossed_nodes_max, last.crossed_nodes);
      outcome.host_force_max_n = std::max(outcome.host_force_max_n, last.force_n);
    } else if (established_at_ns >= 0 && paused_since_ns < 0) {
      paused_since_ns = now;
      ++outcome.pauses;
      const TimeNs age = bridge.peer_data_age_ns();
      if (bridge.status().peer_closed) {
        log_info("rt_core closed the link cleanly: scene paused");
      } else if (age == transport::kNeverReceived) {
        log_warn("rt_core sends no device state yet: scene paused");
      } else {
        log_warn("rt_core silent for %.0f ms: scene paused", to_seconds(age) * 1e3);
      }
    }
    if (options.status_line && now - last_status_ns >= status_period_ns) {
      const std::string line = format_bridge_status(bridge.status(), wire::Role::kHost);
      std::fprintf(stderr, tty ? "\r[host %.1f s] %s | steps %llu |F_host| %.2f N crossed %d | %s\033[K"
                               : "[host %.1f s] %s | steps %llu |F_host| %.2f N crossed %d | %s\n",
                   to_seconds(now - start_ns), rt_live ? "running" : "PAUSED", static_cast<unsigned long long>(last.steps),
                   last.force_n, last.crossed_nodes, line.c_str());
      last_status_ns = now;
    }
    // A paused host's idle pumps are not steps: they are never counted late.
    schedule.wait_next(rt_live ? period_ns : kIdlePumpPeriod_ns, rt_live);
  }
  if (options.status_line && tty) std::fprintf(stderr, "\n");
  if (paused_since_ns >= 0) paused_total_ns += clock.now() - paused_since_ns;
  const BridgeStatus link = bridge.status();
  if (established_at_ns >= 0) bridge.close();  // rt_core reports "closed cleanly by the host", not a lost link
  outcome.rt_closed = link.peer_closed;
  outcome.rt_lost = established_at_ns >= 0 && paused_since_ns >= 0 && !link.peer_closed && link.peer_silent;
  // The pause starts kRtSilentAfter_ns after rt_core's last DeviceState: that is when it went silent.
  if (outcome.rt_lost) outcome.rt_lost_at_s = std::max(0.0, to_seconds(paused_since_ns - kRtSilentAfter_ns - start_ns));
  outcome.seconds = to_seconds(clock.now() - start_ns);
  outcome.steps = last.steps;
  outcome.late_steps = schedule.late_steps();
  outcome.paused_s = to_seconds(paused_total_ns);
  outcome.interrupted = interrupted(options);
  char lost_story[96];
  std::snprintf(lost_story, sizeof lost_story, "established, LOST at %.2f s (rt_core silent from then to the end)", outcome.rt_lost_at_s);
  const std::string link_story = established_at_ns < 0 ? "never established"
                                 : outcome.rt_closed   ? "established, closed cleanly by rt_core"
                                 : outcome.rt_lost     ? lost_story
                                                       : "established";
  std::printf("fissure host: '%s' %.2f s | link %s | steps %llu (late %llu) | paused %llu× %.2f s | crossed nodes max %d | "
              "host force max %.2f N | discards %llu frames / %llu msgs | rt restarts %llu%s\n",
              scene.name.c_str(), outcome.seconds, link_story.c_str(),
              static_cast<unsigned long long>(outcome.steps), static_cast<unsigned long long>(outcome.late_steps),
              static_cast<unsigned long long>(outcome.pauses), outcome.paused_s, outcome.crossed_nodes_max,
              outcome.host_force_max_n, static_cast<unsigned long long>(link.frames_discarded),
              static_cast<unsigned long long>(link.messages_discarded), static_cast<unsigned long long>(link.peer_restarts),
              outcome.interrupted ? " | stopped by Ctrl-C" : "");
  std::fflush(stdout);
  if (established_at_ns < 0) throw SessionError("rt_core at " + options.transport + " never answered: link not established");
  if (outcome.rt_lost) {
    char at[32];
    std::snprintf(at, sizeof at, "%.2f s", outcome.rt_lost_at_s);
    throw SessionError("link lost: rt_core at " + options.transport + " went silent at " + at +
                       " without closing the link (crashed, killed or cut off)");
  }
  return outcome;
}

}  // namespace fissure::session
