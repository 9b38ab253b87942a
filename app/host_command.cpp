// `fissure host SCENE --transport can:IFACE|udp:HOST:PORT [--seconds N]`
// The host PC of a split deployment (issue 6, docs/deployment.md): the scene's HostSimulation
// + proxy builder (SessionHost, the same object `fissure run` steps) at the host rate, joined
// to a `fissure rt` through a LinkBridge (role host) pumped before and after each step.
// rt_core death: no DeviceState for kRtSilentAfter_ns (50 ms) → "rt_core silent for X ms",
// the scene is paused (no step, no proxy) until rt_core is heard again (a restarted rt_core
// re-handshakes with a new session id). Ctrl-C: stop stepping and exit 0 — rt_core's proxy
// goes stale and fades the force out on its own.
#include "host_command.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "commands.hpp"
#include "fissure/host_sim/scene_loader.hpp"
#include "link_bridge.hpp"
#include "session_host.hpp"
#include "session_runner.hpp"
#include "split_device.hpp"

#include "sigint_flag.hpp"

namespace fissure::app {
namespace {

/// While paused or waiting for the link the host still pumps the bridge this often [ns]:
/// Hellos get answered and a returning rt_core is seen within a millisecond.
constexpr TimeNs kIdlePumpPeriod_ns = 1'000'000;

struct HostOptions {
  std::string scene;
  std::string transport;
  double seconds = 0.0;
  double host_rate_hz = 0.0;
  double settle_s = 1.0;
  double connect_timeout_s = 10.0;
  bool quiet = false;
};

void run(const HostOptions& options) {
  host::SceneDescription loaded;
  try {
    loaded = host::load_scene(host::resolve_scene_path(options.scene));
  } catch (const std::exception& e) {
    throw CommandError(e.what());
  }
  const host::SceneDescription scene = scene_at_host_rate(loaded, options.host_rate_hz);
  MonotonicClock clock;
  std::unique_ptr<transport::FrameCarrier> carrier = open_split_carrier(options.transport, wire::Role::kHost, clock, "fissure host");
  std::unique_ptr<SessionHost> host;
  try {
    host = std::make_unique<SessionHost>(scene);
  } catch (const std::exception& e) {
    throw CommandError(e.what());
  }
  host->settle(options.settle_s);

  const double host_dt_s = scene.simulation.time_step_s;
  const auto period_ns = static_cast<TimeNs>(std::llround(host_dt_s * 1e9));
  transport::LinkConfig link_config;
  link_config.role = wire::Role::kHost;
  link_config.publish_rate_hz = static_cast<float>(1.0 / host_dt_s);
  link_config.session_id = fresh_session_id();
  LinkBridge bridge(*carrier, clock, link_config, kRtSilentAfter_ns);
  rt::DeviceStateExchange state_in;
  rt::ProxyExchange proxy_out;

  const TimeNs start_ns = clock.now();
  const TimeNs end_ns = options.seconds > 0.0 ? start_ns + static_cast<TimeNs>(options.seconds * 1e9) : 0;
  const auto connect_deadline_ns = start_ns + static_cast<TimeNs>(options.connect_timeout_s * 1e9);
  const bool tty = isatty(STDERR_FILENO) == 1;
  const TimeNs status_period_ns = tty ? 100'000'000 : 1'000'000'000;
  TimeNs last_status_ns = start_ns;
  TimeNs established_at_ns = -1;
  TimeNs paused_since_ns = -1;
  TimeNs paused_total_ns = 0;
  std::uint64_t pauses = 0;
  std::uint64_t late_steps = 0;
  int crossed_nodes_max = 0;
  double host_force_max_n = 0.0;
  HostStatus last{};
  spdlog::info("fissure host: scene '{}' at {:.0f} Hz, connecting to rt_core over {}", scene.name, 1.0 / host_dt_s,
               options.transport);
  TimeNs next = clock.now();
  for (;;) {
    const TimeNs now = clock.now();
    if (SigintFlag::raised() || (end_ns != 0 && now >= end_ns)) break;
    bridge.pump_host(state_in, proxy_out);
    if (bridge.failed()) throw CommandError(bridge.status().error);
    if (established_at_ns < 0 && bridge.established()) {
      established_at_ns = now;
      spdlog::info("link established with rt_core after {:.0f} ms", to_seconds(now - start_ns) * 1e3);
    }
    if (established_at_ns < 0 && now >= connect_deadline_ns) {
      throw CommandError("rt_core at " + options.transport + " never answered: link not established within " +
                         std::to_string(options.connect_timeout_s) + " s (is 'fissure rt --transport " + options.transport +
                         "' running?)");
    }
    // Step only while rt_core is alive and talking: a scene stepped towards a stale tool
    // pose would drift away from where the hand really is.
    const bool rt_live = bridge.established() && !bridge.peer_silent();
    if (rt_live) {
      if (paused_since_ns >= 0) {
        spdlog::info("rt_core back after {:.0f} ms: scene resumed", to_seconds(now - paused_since_ns) * 1e3);
        paused_total_ns += now - paused_since_ns;
        paused_since_ns = -1;
      }
      try {
        last = host->step(state_in, proxy_out);
      } catch (const std::exception& e) {
        throw CommandError(std::string("host step: ") + e.what());
      }
      bridge.pump_host(state_in, proxy_out);  // the proxy leaves now, not a period later
      crossed_nodes_max = std::max(crossed_nodes_max, last.crossed_nodes);
      host_force_max_n = std::max(host_force_max_n, last.force_n);
    } else if (established_at_ns >= 0 && paused_since_ns < 0) {
      paused_since_ns = now;
      ++pauses;
      const TimeNs age = bridge.peer_data_age_ns();
      if (age == transport::kNeverReceived) {
        spdlog::warn("rt_core sends no device state yet: scene paused");
      } else {
        spdlog::warn("rt_core silent for {:.0f} ms: scene paused", to_seconds(age) * 1e3);
      }
    }
    if (!options.quiet && now - last_status_ns >= status_period_ns) {
      const std::string line = format_bridge_status(bridge.status(), wire::Role::kHost);
      std::fprintf(stderr, tty ? "\r[host %.1f s] %s | steps %llu |F_host| %.2f N crossed %d | %s\033[K"
                               : "[host %.1f s] %s | steps %llu |F_host| %.2f N crossed %d | %s\n",
                   to_seconds(now - start_ns), rt_live ? "running" : "PAUSED", static_cast<unsigned long long>(last.steps),
                   last.force_n, last.crossed_nodes, line.c_str());
      last_status_ns = now;
    }
    const TimeNs wait_ns = rt_live ? period_ns : kIdlePumpPeriod_ns;
    next += wait_ns;
    const TimeNs after = clock.now();
    if (after >= next + wait_ns) {
      if (rt_live) ++late_steps;  // a whole period behind: restart the schedule, no catch-up burst
      next = after;
    } else if (after < next) {
      clock.sleep_until(next);
    }
  }
  if (!options.quiet && tty) std::fprintf(stderr, "\n");
  if (paused_since_ns >= 0) paused_total_ns += clock.now() - paused_since_ns;
  const BridgeStatus link = bridge.status();
  std::printf("fissure host: '%s' %.2f s | link %s | steps %llu (late %llu) | paused %llu× %.2f s | crossed nodes max %d | "
              "host force max %.2f N | discards %llu frames / %llu msgs | rt restarts %llu%s\n",
              scene.name.c_str(), to_seconds(clock.now() - start_ns),
              established_at_ns >= 0 ? "established" : "never established", static_cast<unsigned long long>(last.steps),
              static_cast<unsigned long long>(late_steps), static_cast<unsigned long long>(pauses), to_seconds(paused_total_ns),
              crossed_nodes_max, host_force_max_n, static_cast<unsigned long long>(link.frames_discarded),
              static_cast<unsigned long long>(link.messages_discarded), static_cast<unsigned long long>(link.peer_restarts),
              SigintFlag::raised() ? " | stopped by Ctrl-C" : "");
  if (established_at_ns < 0) {
    throw CommandError("rt_core at " + options.transport + " never answered: link not established");
  }
}

}  // namespace

void register_host_command(CommandTree& tree) {
  auto options = std::make_shared<HostOptions>();
  CLI::App* cmd = tree.root.add_subcommand(
      "host", "Split deployment, host PC: the scene's simulation + proxy builder, feeding a 'fissure rt' over CAN FD or UDP");
  cmd->add_option("scene", options->scene, "scene name (scenes/NAME.toml) or path to a scene file")->required();
  cmd->add_option("--transport", options->transport, "can:IFACE or udp:HOST:PORT (HOST:PORT = the rt box's address)")
      ->required();
  cmd->add_option("--seconds", options->seconds, "run this long (default: until Ctrl-C)")->check(CLI::NonNegativeNumber);
  cmd->add_option("--host-rate", options->host_rate_hz, "host step rate [Hz] (default: the scene's time step)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--settle", options->settle_s, "seconds the soft body settles before connecting")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--connect-timeout", options->connect_timeout_s, "fail if rt_core has not answered within this [s]")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("--quiet", options->quiet, "no status line");
  cmd->callback([options] {
    const SigintFlag sigint;
    run(*options);
  });
}

}  // namespace fissure::app
