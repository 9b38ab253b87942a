// `fissure hil latency [--device usb|sim] [--transport inproc|udp:HOST:PORT|can:IFACE] [--seconds N]
//                      [--scene SCENE] --json FILE`
// Hardware-in-the-loop latency: the scene's session in real time, rt_core on the rt
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
#include "fissure/eval/hil_latency.hpp"

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

#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "fissure/eval/eval_error.hpp"
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
#include "fissure/eval/sim_report.hpp"
#include "fissure/session/split_device.hpp"

namespace fissure::eval {
using namespace fissure::session;  // the session library: SessionHost, run_session, LinkBridge, …
namespace {

/// rt-side bridge pump period [ns] (as `fissure rt`): a quarter of a 1 kHz tick.
constexpr TimeNs kPumpPeriod_ns = 250'000;
/// Extra room in the preallocated sample buffers beyond seconds × rate [-]: overruns and
/// start-up never fill 2×.
constexpr double kBufferMargin = 2.0;


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

// Per tick, from the telemetry: when, the age of the proxy in use and its sequence.
struct TickRecord {
  TimeNs time_ns;
  TimeNs proxy_age_ns;
  std::uint64_t proxy_sequence;
};

// The samples of the distributions that need matching (the rest are recorded as they are).
struct Latencies {
  std::vector<double> round_trip_us;
  std::vector<double> proxy_age_ms;
  std::vector<double> end_to_end_ms;
  std::uint64_t proxies_rendered = 0;
  std::uint64_t unmatched = 0;
};

// The session under measurement: rt_core on an rt thread over a TimedDevice, the host on its
// own thread, and for udp/can both bridges (rt bridge on a service thread). Built in the order
// a session is: carriers first (a bad --transport fails before the slow settle), the rt end
// binds; then the host settles, then the device opens.
class HilSession {
 public:
  HilSession(const HilLatencyOptions& options, const host::SceneDescription& scene, const rt::RtModel& model, bool split)
      : options_(options),
        scene_(scene),
        split_(split),
        rt_clock_(monotonic_),
        expected_ticks_(static_cast<std::size_t>(options.seconds * options.rate_hz * kBufferMargin) + 1000) {
    if (split_) {
      rt_carrier_ = open_split_carrier(options.transport, wire::Role::kRt, monotonic_, "fissure hil latency");
      host_carrier_ = open_split_carrier(options.transport, wire::Role::kHost, monotonic_, "fissure hil latency");
    }
    host_ = std::make_unique<SessionHost>(scene_);
    host_->settle(options.settle_s);
    device_ = options.device == "usb" ? SplitDevice::open_usb(monotonic_) : SplitDevice::open_sim(scene_.hand, monotonic_);
    timed_ = std::make_unique<TimedDevice>(device_->device(), monotonic_, expected_ticks_);
    hx_ = std::make_unique<HostChannels>();
    rt_ = std::make_unique<RtStack>(model, *timed_, rt_clock_);
    if (split_) open_bridges();
    tick_us_.reserve(expected_ticks_);
    const auto expected_steps = static_cast<std::size_t>(options.seconds / scene_.simulation.time_step_s * kBufferMargin) + 1000;
    host_record_.step_us.reserve(expected_steps);
    host_record_.sample_time_of_sequence_ns.assign(expected_steps, -1);
    ticks_.reserve(expected_ticks_);
  }

  // Runs the threads for options.seconds; throws EvalError when the link or a host step failed.
  void run();
  [[nodiscard]] Latencies latencies() const;
  [[nodiscard]] nlohmann::json to_json(Latencies l) const;

 private:
  struct HostChannels {
    ProxyExchange proxy;               // host → (split: host bridge)
    DeviceStateExchange state;         // (split: host bridge) → host
    DeviceStateExchange host_private;  // the sample handed to SessionHost, recorded first
  };

  void open_bridges();
  void rt_body(TimeNs end_ns);
  // One host period: pumps the link, steps the host and records; false ends the host thread.
  bool host_step();
  void drain_telemetry();

  const HilLatencyOptions& options_;
  const host::SceneDescription& scene_;
  const bool split_;
  MonotonicClock monotonic_;
  WakeRecordingClock rt_clock_;
  const std::size_t expected_ticks_;
  std::unique_ptr<transport::FrameCarrier> rt_carrier_;
  std::unique_ptr<transport::FrameCarrier> host_carrier_;
  std::unique_ptr<SessionHost> host_;
  std::unique_ptr<SplitDevice> device_;
  std::unique_ptr<TimedDevice> timed_;
  std::unique_ptr<HostChannels> hx_;
  std::unique_ptr<RtStack> rt_;
  std::unique_ptr<LinkBridge> rt_bridge_;
  std::unique_ptr<LinkBridge> host_bridge_;
  std::vector<double> tick_us_;
  HostRecord host_record_;
  std::vector<TickRecord> ticks_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> link_failed_{false};
  std::unique_ptr<RtThread> rt_thread_;
  rt::RtSetupReport rt_setup_{};
  // The host thread's newest device sample.
  DeviceState latest_{};
  bool have_latest_ = false;
};

void HilSession::open_bridges() {
  transport::LinkConfig rt_link;
  rt_link.role = wire::Role::kRt;
  rt_link.publish_rate_hz = static_cast<float>(options_.rate_hz);
  rt_link.session_id = fresh_session_id();
  rt_bridge_ = std::make_unique<LinkBridge>(*rt_carrier_, monotonic_, rt_link, kHostSilentAfter_ns);
  transport::LinkConfig host_link;
  host_link.role = wire::Role::kHost;
  host_link.publish_rate_hz = static_cast<float>(1.0 / scene_.simulation.time_step_s);
  host_link.session_id = rt_link.session_id + 1;
  host_bridge_ = std::make_unique<LinkBridge>(*host_carrier_, monotonic_, host_link, kRtSilentAfter_ns);
}

void HilSession::rt_body(TimeNs end_ns) {
  rt::RtLoop& loop = rt_->loop();
  while (!loop.stopped()) {
    if (stop_.load(std::memory_order_relaxed) || monotonic_.now() >= end_ns) loop.request_stop();
    loop.step();
    // push_back within the reserved capacity never allocates; beyond it we stop recording.
    if (tick_us_.size() < tick_us_.capacity()) tick_us_.push_back(to_seconds(monotonic_.now() - rt_clock_.last_wake_ns()) * 1e6);
  }
  loop.send_zero_command();
}

bool HilSession::host_step() {
  if (rt_thread_->done()) return false;
  RtChannels& rx = rt_->channels();
  DeviceStateExchange& host_in = split_ ? hx_->state : rx.state;
  ProxyExchange& host_out = split_ ? hx_->proxy : rx.proxy;
  bool live = true;
  if (split_) {
    host_bridge_->pump_host(hx_->state, hx_->proxy);
    if (host_bridge_->failed()) {
      link_failed_.store(true);
      stop_.store(true);
      return false;
    }
    live = host_bridge_->established() && !host_bridge_->peer_silent();
  }
  if (!live) {
    ++host_record_.paused_steps;
    return true;
  }
  if (host_in.try_fetch(latest_)) have_latest_ = true;
  if (have_latest_) hx_->host_private.publish(latest_);
  try {
    const HostStatus& status = host_->step(hx_->host_private, host_out);
    if (split_) host_bridge_->pump_host(hx_->state, hx_->proxy);
    if (host_record_.step_us.size() < host_record_.step_us.capacity()) host_record_.step_us.push_back(status.step_cpu_s * 1e6);
    const std::uint64_t sequence = host_->last_proxy().sequence;
    if (have_latest_ && sequence < host_record_.sample_time_of_sequence_ns.size()) {
      host_record_.sample_time_of_sequence_ns[sequence] = latest_.sample_time_ns;
    }
    ++host_record_.steps;
  } catch (const std::exception& e) {
    host_record_.error = e.what();
    stop_.store(true);
    return false;
  }
  return true;
}

// Telemetry: per tick the proxy in use and its age; drained so the ring never fills.
void HilSession::drain_telemetry() {
  rt::TelemetrySample sample;
  while (rt_->channels().telemetry.try_pop(sample)) ticks_.push_back({sample.time_ns, sample.proxy_age_ns, sample.proxy_sequence});
}

void HilSession::run() {
  const TimeNs start_ns = monotonic_.now();
  const TimeNs end_ns = start_ns + static_cast<TimeNs>(options_.seconds * 1e9);
  rt::RtThreadConfig thread_config;
  thread_config.policy = rt::RtPolicy::kBestEffort;
  rt_thread_ = std::make_unique<RtThread>(thread_config, [this, end_ns] { rt_body(end_ns); });
  std::atomic<bool> rt_finished{false};
  std::thread service_thread;
  if (split_) {
    service_thread = std::thread([&] {
      HostLoop pump(monotonic_);
      pump.run(kPumpPeriod_ns, rt_finished, [&] {
        rt_bridge_->pump_rt(rt_->channels().state, rt_->channels().proxy);
        return !rt_thread_->done();
      });
    });
  }
  HostLoop host_loop(monotonic_);
  std::thread host_thread([&] {
    const auto period_ns = static_cast<TimeNs>(std::llround(scene_.simulation.time_step_s * 1e9));
    host_loop.run(period_ns, rt_finished, [&] { return host_step(); });
  });
  std::fprintf(stderr, "hil latency: %s over %s, %.0f s …\n", timed_->name(), options_.transport.c_str(), options_.seconds);
  while (!rt_thread_->done()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    drain_telemetry();
  }
  rt_thread_->join();
  rt_finished.store(true);
  host_thread.join();
  if (service_thread.joinable()) service_thread.join();
  host_record_.late = host_loop.late_steps();
  rt_setup_ = rt_thread_->setup_report();
  drain_telemetry();
  if (link_failed_.load()) throw EvalError(host_bridge_->status().error);
  if (!host_record_.error.empty()) throw EvalError("host step: " + host_record_.error);
}

Latencies HilSession::latencies() const {
  Latencies l;
  for (std::size_t i = 0; i < timed_->recorded(); ++i) l.round_trip_us.push_back(to_seconds(timed_->samples_ns()[i]) * 1e6);
  const std::int64_t offset = split_ ? rt_bridge_->sequence_offset() : 0;
  const std::vector<TimeNs>& sample_time_ns = host_record_.sample_time_of_sequence_ns;
  std::uint64_t previous_sequence = 0;
  for (const TickRecord& t : ticks_) {
    if (t.proxy_sequence == 0) continue;  // no proxy yet
    l.proxy_age_ms.push_back(to_seconds(t.proxy_age_ns) * 1e3);
    if (t.proxy_sequence == previous_sequence) continue;
    previous_sequence = t.proxy_sequence;
    ++l.proxies_rendered;
    const std::int64_t host_sequence = static_cast<std::int64_t>(t.proxy_sequence) - offset;
    if (host_sequence <= 0 || static_cast<std::size_t>(host_sequence) >= sample_time_ns.size() ||
        sample_time_ns[static_cast<std::size_t>(host_sequence)] < 0) {
      ++l.unmatched;
      continue;
    }
    l.end_to_end_ms.push_back(to_seconds(t.time_ns - sample_time_ns[static_cast<std::size_t>(host_sequence)]) * 1e3);
  }
  return l;
}

nlohmann::json HilSession::to_json(Latencies l) const {
  const rt::RtLoop& loop = rt_->loop();
  nlohmann::json out;
  out["command"] = "fissure hil latency";
  out["device"] = timed_->name();
  out["transport"] = options_.transport;
  out["transport_topology"] = split_ ? "both ends in this process: rt bridge (service thread, binds HOST:PORT) and host bridge "
                                       "(host thread, sends to HOST:PORT) over the real carrier"
                                     : "in-process wait-free exchanges";
  out["scene"] = scene_.name;
  out["seconds"] = options_.seconds;
  out["rt_rate_hz"] = options_.rate_hz;
  out["host_rate_hz"] = 1.0 / scene_.simulation.time_step_s;
  out["rt_sched_fifo"] = rt_setup_.sched_fifo;
  out["rt_setup_warnings"] = std::string(rt_setup_.message);
  out["ticks"] = loop.stats().ticks;
  out["overruns"] = loop.stats().overruns;
  out["host_steps"] = host_record_.steps;
  out["host_late_steps"] = host_record_.late;
  out["host_paused_steps"] = host_record_.paused_steps;
  out["proxies_rendered"] = l.proxies_rendered;
  out["proxies_unmatched"] = l.unmatched;
  out["device_round_trip_us"] = distribution(std::move(l.round_trip_us));
  out["rt_tick_us"] = distribution(tick_us_);
  out["host_step_us"] = distribution(host_record_.step_us);
  out["proxy_age_ms"] = distribution(std::move(l.proxy_age_ms));
  out["end_to_end_ms"] = distribution(std::move(l.end_to_end_ms));
  out["definitions"] = {
      {"device_round_trip_us", "duration of each HapticDevice::try_exchange (one command out, one reading back)"},
      {"rt_tick_us", "RtLoop::step from the wake-up at its deadline to its return, device I/O included"},
      {"host_step_us", "SessionHost::step wall time: HostSimulation step + proxy builder"},
      {"proxy_age_ms", "per tick with a proxy: rt clock now - the tick that accepted the proxy in use"},
      {"end_to_end_ms", "per proxy rendered: time of the first rt tick that rendered it - sample_time_ns of the DeviceState "
                        "the host built it from (encoder sample -> first force from the host's response to that sample)"}};
  if (split_) {
    const BridgeStatus rt_link = rt_bridge_->status();
    const BridgeStatus host_link = host_bridge_->status();
    out["link"] = {{"rt_frames_discarded", rt_link.frames_discarded},
                   {"rt_messages_discarded", rt_link.messages_discarded},
                   {"host_frames_discarded", host_link.frames_discarded},
                   {"host_messages_discarded", host_link.messages_discarded},
                   {"proxies_forwarded_to_rt", rt_link.messages_in},
                   {"device_states_forwarded_to_host", host_link.messages_in}};
  }
  out["machine"] = sim_machine_info();
  return out;
}

}  // namespace

nlohmann::json run_hil_latency(const HilLatencyOptions& options) {
  host::SceneDescription scene;
  try {
    scene = host::load_scene(host::resolve_scene_path(options.scene));
  } catch (const std::exception& e) {
    throw EvalError(e.what());
  }
  transport::TransportSpec spec;
  try {
    spec = transport::parse_transport_spec(options.transport);
  } catch (const transport::TransportError& e) {
    throw EvalError(std::string("--transport: ") + e.what(), true);
  }
  const bool split = spec.kind != transport::TransportSpec::Kind::kInProcess;
  rt::RtConfig config;
  config.rate_hz = options.rate_hz;
  config.mapping = scene.device_mapping;
  const rt::RtModel model = build_rt_model(config);
  HilSession session(options, scene, model, split);
  session.run();
  return session.to_json(session.latencies());
}

bool hil_latency_measured(const nlohmann::json& result) { return result["end_to_end_ms"]["count"].get<std::size_t>() > 0; }

}  // namespace fissure::eval
