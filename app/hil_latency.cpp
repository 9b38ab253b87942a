// `fissure hil latency [--device usb|sim] [--transport inproc|udp:HOST:PORT|can:IFACE] [--seconds N]
//                      [--scene SCENE] --json FILE`
// Hardware-in-the-loop latency (issue 6): the scene's session in real time, rt_core on the rt
// thread (SCHED_FIFO best effort), the host on its own thread, joined in-process or through a
// real carrier. For udp/can BOTH ends run in this one process (rt bridge on a service thread
// bound to HOST:PORT, host bridge pumped by the host thread sending to it), so the two clocks
// are one CLOCK_MONOTONIC and the end-to-end latency is measured without clock sync; the frames
// still cross the kernel's UDP stack (or the CAN bus) both ways. Distributions (median, p99, max):
//   device_round_trip_us — duration of each HapticDevice::try_exchange (TimedDevice);
//   rt_tick_us           — RtLoop::step() from its wake-up to its return (device I/O included);
//   host_step_us         — SessionHost::step wall time (simulation + proxy builder);
//   proxy_age_ms         — per tick, the age of the proxy rt_core rendered (rt clock, from intake);
//   end_to_end_ms        — for each proxy rt_core rendered: time of the first tick that rendered
//                          it − sample_time_ns of the DeviceState the host built it from, i.e.
//                          from the encoder sample (a change of device position) to the first
//                          force computed from the host's response to exactly that sample.
#include "hil_latency.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "commands.hpp"
#include "fissure/host_sim/scene_loader.hpp"
#include "fissure/rt_core/rt_config.hpp"
#include "fissure/rt_core/rt_loop.hpp"
#include "fissure/rt_core/rt_thread.hpp"
#include "fissure/session/link_bridge.hpp"
#include "fissure/session/session_host.hpp"
#include "fissure/session/session_record.hpp"
#include "fissure/session/host_loop.hpp"
#include "fissure/session/rt_stack.hpp"
#include "fissure/session/session_runner.hpp"
#include "sim_report.hpp"
#include "fissure/session/split_device.hpp"

namespace fissure::app {
using namespace fissure::session;  // the session library: SessionHost, run_session, LinkBridge, …
namespace {

/// rt-side bridge pump period [ns] (as `fissure rt`): a quarter of a 1 kHz tick.
constexpr TimeNs kPumpPeriod_ns = 250'000;
/// Extra room in the preallocated sample buffers beyond seconds × rate [-]: overruns and
/// start-up never fill 2×.
constexpr double kBufferMargin = 2.0;

struct HilOptions {
  std::string device = "sim";
  std::string transport = "inproc";
  std::string scene = "spatula-sphere";
  double seconds = 10.0;
  double rate_hz = 1000.0;
  double settle_s = 1.0;
  std::string json_path;
};

// What the host thread records per step (read after the thread joined).
struct HostRecord {
  std::vector<double> step_us;
  /// sample_time_ns of the DeviceState each host proxy sequence was built from (index = sequence).
  std::vector<TimeNs> sample_time_of_sequence_ns;
  std::uint64_t steps = 0;
  std::uint64_t late = 0;
  std::uint64_t paused_steps = 0;
  std::string error;
};

nlohmann::json distribution(std::vector<double> values) {
  const std::size_t count = values.size();
  const Quantiles q = quantiles(values);
  return {{"median", q.median}, {"p99", q.p99}, {"max", q.max}, {"count", count}};
}

void run(const HilOptions& options) {
  if (options.json_path.empty()) throw CLI::ValidationError("--json", "an output file is required");
  host::SceneDescription scene;
  try {
    scene = host::load_scene(host::resolve_scene_path(options.scene));
  } catch (const std::exception& e) {
    throw CommandError(e.what());
  }
  transport::TransportSpec spec;
  try {
    spec = transport::parse_transport_spec(options.transport);
  } catch (const transport::TransportError& e) {
    throw CommandError(std::string("--transport: ") + e.what(), 2);
  }
  const bool split = spec.kind != transport::TransportSpec::Kind::kInProcess;

  rt::RtConfig config;
  config.rate_hz = options.rate_hz;
  config.mapping = scene.device_mapping;
  const rt::RtModel model = build_rt_model(config);

  MonotonicClock monotonic;
  WakeRecordingClock rt_clock(monotonic);
  // Both carriers first (a bad --transport fails before the slow settle), rt end binds.
  std::unique_ptr<transport::FrameCarrier> rt_carrier;
  std::unique_ptr<transport::FrameCarrier> host_carrier;
  if (split) {
    rt_carrier = open_split_carrier(options.transport, wire::Role::kRt, monotonic, "fissure hil latency");
    host_carrier = open_split_carrier(options.transport, wire::Role::kHost, monotonic, "fissure hil latency");
  }
  SessionHost host(scene);
  host.settle(options.settle_s);
  std::unique_ptr<SplitDevice> device =
      options.device == "usb" ? SplitDevice::open_usb(monotonic) : SplitDevice::open_sim(scene.hand, monotonic);

  const auto expected_ticks = static_cast<std::size_t>(options.seconds * options.rate_hz * kBufferMargin) + 1000;
  TimedDevice timed(device->device(), monotonic, expected_ticks);
  struct HostChannels {
    ProxyExchange proxy;          // host → (split: host bridge)
    DeviceStateExchange state;    // (split: host bridge) → host
    DeviceStateExchange host_private;  // the sample handed to SessionHost, recorded first
  };
  auto hx = std::make_unique<HostChannels>();
  RtStack rt(model, timed, rt_clock);
  rt::RtLoop& loop = rt.loop();
  RtChannels& rx = rt.channels();

  std::unique_ptr<LinkBridge> rt_bridge;
  std::unique_ptr<LinkBridge> host_bridge;
  if (split) {
    transport::LinkConfig rt_link;
    rt_link.role = wire::Role::kRt;
    rt_link.publish_rate_hz = static_cast<float>(options.rate_hz);
    rt_link.session_id = fresh_session_id();
    rt_bridge = std::make_unique<LinkBridge>(*rt_carrier, monotonic, rt_link, kHostSilentAfter_ns);
    transport::LinkConfig host_link;
    host_link.role = wire::Role::kHost;
    host_link.publish_rate_hz = static_cast<float>(1.0 / scene.simulation.time_step_s);
    host_link.session_id = rt_link.session_id + 1;
    host_bridge = std::make_unique<LinkBridge>(*host_carrier, monotonic, host_link, kRtSilentAfter_ns);
  }
  DeviceStateExchange& host_in = split ? hx->state : rx.state;
  ProxyExchange& host_out = split ? hx->proxy : rx.proxy;

  std::vector<double> tick_us;
  tick_us.reserve(expected_ticks);
  HostRecord host_record;
  const double host_dt_s = scene.simulation.time_step_s;
  const auto expected_steps = static_cast<std::size_t>(options.seconds / host_dt_s * kBufferMargin) + 1000;
  host_record.step_us.reserve(expected_steps);
  host_record.sample_time_of_sequence_ns.assign(expected_steps, -1);

  std::atomic<bool> stop{false};
  std::atomic<bool> link_failed{false};
  const TimeNs start_ns = monotonic.now();
  const TimeNs end_ns = start_ns + static_cast<TimeNs>(options.seconds * 1e9);

  rt::RtThreadConfig thread_config;
  thread_config.policy = rt::RtPolicy::kBestEffort;
  RtThread rt_thread(thread_config, [&] {
    while (!loop.stopped()) {
      if (stop.load(std::memory_order_relaxed) || monotonic.now() >= end_ns) loop.request_stop();
      loop.step();
      // push_back within the reserved capacity never allocates; beyond it we stop recording.
      if (tick_us.size() < tick_us.capacity()) tick_us.push_back(to_seconds(monotonic.now() - rt_clock.last_wake_ns()) * 1e6);
    }
    loop.send_zero_command();
  });
  std::atomic<bool> rt_finished{false};
  std::thread service_thread;
  if (split) {
    service_thread = std::thread([&] {
      HostLoop pump(monotonic);
      pump.run(kPumpPeriod_ns, rt_finished, [&] {
        rt_bridge->pump_rt(rx.state, rx.proxy);
        return !rt_thread.done();
      });
    });
  }
  HostLoop host_loop(monotonic);
  std::thread host_thread([&] {
    const auto period_ns = static_cast<TimeNs>(std::llround(host_dt_s * 1e9));
    DeviceState latest{};
    bool have_latest = false;
    host_loop.run(period_ns, rt_finished, [&] {
      if (rt_thread.done()) return false;
      bool live = true;
      if (split) {
        host_bridge->pump_host(hx->state, hx->proxy);
        if (host_bridge->failed()) {
          link_failed.store(true);
          stop.store(true);
          return false;
        }
        live = host_bridge->established() && !host_bridge->peer_silent();
      }
      if (live) {
        if (host_in.try_fetch(latest)) have_latest = true;
        if (have_latest) hx->host_private.publish(latest);
        try {
          const HostStatus& status = host.step(hx->host_private, host_out);
          if (split) host_bridge->pump_host(hx->state, hx->proxy);
          if (host_record.step_us.size() < host_record.step_us.capacity()) host_record.step_us.push_back(status.step_cpu_s * 1e6);
          const std::uint64_t sequence = host.last_proxy().sequence;
          if (have_latest && sequence < host_record.sample_time_of_sequence_ns.size()) {
            host_record.sample_time_of_sequence_ns[sequence] = latest.sample_time_ns;
          }
          ++host_record.steps;
        } catch (const std::exception& e) {
          host_record.error = e.what();
          stop.store(true);
          return false;
        }
      } else {
        ++host_record.paused_steps;
      }
      return true;
    });
  });

  // Telemetry: per tick the proxy in use and its age; drained here so the ring never fills.
  struct TickRecord {
    TimeNs time_ns;
    TimeNs proxy_age_ns;
    std::uint64_t proxy_sequence;
  };
  std::vector<TickRecord> ticks;
  ticks.reserve(expected_ticks);
  rt::TelemetrySample sample;
  std::fprintf(stderr, "hil latency: %s over %s, %.0f s …\n", timed.name(), options.transport.c_str(), options.seconds);
  while (!rt_thread.done()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    while (rx.telemetry.try_pop(sample)) ticks.push_back({sample.time_ns, sample.proxy_age_ns, sample.proxy_sequence});
  }
  rt_thread.join();
  rt_finished.store(true);
  host_thread.join();
  if (service_thread.joinable()) service_thread.join();
  host_record.late = host_loop.late_steps();
  while (rx.telemetry.try_pop(sample)) ticks.push_back({sample.time_ns, sample.proxy_age_ns, sample.proxy_sequence});
  if (link_failed.load()) throw CommandError(host_bridge->status().error);
  if (!host_record.error.empty()) throw CommandError("host step: " + host_record.error);

  // Distributions.
  std::vector<double> round_trip_us;
  for (std::size_t i = 0; i < timed.recorded(); ++i) round_trip_us.push_back(to_seconds(timed.samples_ns()[i]) * 1e6);
  std::vector<double> proxy_age_ms;
  std::vector<double> end_to_end_ms;
  const std::int64_t offset = split ? rt_bridge->sequence_offset() : 0;
  std::uint64_t previous_sequence = 0;
  std::uint64_t proxies_rendered = 0;
  std::uint64_t unmatched = 0;
  for (const TickRecord& t : ticks) {
    if (t.proxy_sequence == 0) continue;  // no proxy yet
    proxy_age_ms.push_back(to_seconds(t.proxy_age_ns) * 1e3);
    if (t.proxy_sequence == previous_sequence) continue;
    previous_sequence = t.proxy_sequence;
    ++proxies_rendered;
    const std::int64_t host_sequence = static_cast<std::int64_t>(t.proxy_sequence) - offset;
    if (host_sequence <= 0 || static_cast<std::size_t>(host_sequence) >= host_record.sample_time_of_sequence_ns.size() ||
        host_record.sample_time_of_sequence_ns[static_cast<std::size_t>(host_sequence)] < 0) {
      ++unmatched;
      continue;
    }
    end_to_end_ms.push_back(to_seconds(t.time_ns - host_record.sample_time_of_sequence_ns[static_cast<std::size_t>(host_sequence)]) * 1e3);
  }

  nlohmann::json out;
  out["command"] = "fissure hil latency";
  out["device"] = timed.name();
  out["transport"] = options.transport;
  out["transport_topology"] = split ? "both ends in this process: rt bridge (service thread, binds HOST:PORT) and host bridge "
                                      "(host thread, sends to HOST:PORT) over the real carrier"
                                    : "in-process wait-free exchanges";
  out["scene"] = scene.name;
  out["seconds"] = options.seconds;
  out["rt_rate_hz"] = options.rate_hz;
  out["host_rate_hz"] = 1.0 / host_dt_s;
  out["rt_sched_fifo"] = rt_thread.setup_report().sched_fifo;
  out["rt_setup_warnings"] = std::string(rt_thread.setup_report().message);
  out["ticks"] = loop.stats().ticks;
  out["overruns"] = loop.stats().overruns;
  out["host_steps"] = host_record.steps;
  out["host_late_steps"] = host_record.late;
  out["host_paused_steps"] = host_record.paused_steps;
  out["proxies_rendered"] = proxies_rendered;
  out["proxies_unmatched"] = unmatched;
  out["device_round_trip_us"] = distribution(round_trip_us);
  out["rt_tick_us"] = distribution(tick_us);
  out["host_step_us"] = distribution(host_record.step_us);
  out["proxy_age_ms"] = distribution(proxy_age_ms);
  out["end_to_end_ms"] = distribution(end_to_end_ms);
  out["definitions"] = {
      {"device_round_trip_us", "duration of each HapticDevice::try_exchange (one command out, one reading back)"},
      {"rt_tick_us", "RtLoop::step from the wake-up at its deadline to its return, device I/O included"},
      {"host_step_us", "SessionHost::step wall time: HostSimulation step + proxy builder"},
      {"proxy_age_ms", "per tick with a proxy: rt clock now - the tick that accepted the proxy in use"},
      {"end_to_end_ms", "per proxy rendered: time of the first rt tick that rendered it - sample_time_ns of the DeviceState "
                        "the host built it from (encoder sample -> first force from the host's response to that sample)"}};
  if (split) {
    const BridgeStatus rt_link = rt_bridge->status();
    const BridgeStatus host_link = host_bridge->status();
    out["link"] = {{"rt_frames_discarded", rt_link.frames_discarded},
                   {"rt_messages_discarded", rt_link.messages_discarded},
                   {"host_frames_discarded", host_link.frames_discarded},
                   {"host_messages_discarded", host_link.messages_discarded},
                   {"proxies_forwarded_to_rt", rt_link.messages_in},
                   {"device_states_forwarded_to_host", host_link.messages_in}};
  }
  out["machine"] = sim_machine_info();
  std::ofstream file(options.json_path);
  if (!file) throw CommandError("cannot write '" + options.json_path + "'");
  file << out.dump(2) << "\n";

  std::printf("hil latency: %s over %s, %.1f s, %llu ticks (%llu overruns), %llu host steps, SCHED_FIFO %s\n", timed.name(),
              options.transport.c_str(), options.seconds, static_cast<unsigned long long>(loop.stats().ticks),
              static_cast<unsigned long long>(loop.stats().overruns), static_cast<unsigned long long>(host_record.steps),
              rt_thread.setup_report().sched_fifo ? "yes" : "no");
  std::printf("  %-22s %10s %10s %10s %8s\n", "measure", "median", "p99", "max", "count");
  for (const char* key : {"device_round_trip_us", "rt_tick_us", "host_step_us", "proxy_age_ms", "end_to_end_ms"}) {
    const nlohmann::json& d = out[key];
    std::printf("  %-22s %10.3f %10.3f %10.3f %8llu\n", key, d["median"].get<double>(), d["p99"].get<double>(),
                d["max"].get<double>(), d["count"].get<unsigned long long>());
  }
  std::printf("  wrote %s\n", options.json_path.c_str());
  if (end_to_end_ms.empty()) throw CommandError("no proxy reached rt_core: the end-to-end latency could not be measured");
}

}  // namespace

void register_hil_latency(CommandTree& tree) {
  auto options = std::make_shared<HilOptions>();
  CLI::App* hil = tree.root.add_subcommand("hil", "Hardware-in-the-loop measurements");
  hil->require_subcommand(1);
  CLI::App* cmd = hil->add_subcommand(
      "latency", "Latency distributions: device round trip, rt tick, host step, proxy age, end to end (JSON + table)");
  cmd->add_option("--device", options->device, "sim (SimFalcon with the scene's hand) or usb (the real Falcon)")
      ->check(CLI::IsMember({"sim", "usb"}));
  cmd->add_option("--transport", options->transport,
                  "inproc, udp:HOST:PORT or can:IFACE (both ends run in this process over the carrier)");
  cmd->add_option("--scene", options->scene, "scene the host simulates (default spatula-sphere)");
  cmd->add_option("--seconds", options->seconds, "measurement length [s] (default 10)")->check(CLI::PositiveNumber);
  cmd->add_option("--rate", options->rate_hz, "rt tick rate [Hz] (500..10000)")->check(CLI::Range(500.0, 10000.0));
  cmd->add_option("--settle", options->settle_s, "seconds the soft body settles first")->check(CLI::NonNegativeNumber);
  cmd->add_option("--json", options->json_path, "output JSON file")->required();
  cmd->callback([options] { run(*options); });
}

}  // namespace fissure::app
