#include "fissure/session/session_runner.hpp"

#include "fissure/session/machine_info.hpp"
#include "fissure/session/usb_falcon.hpp"

#include <sys/utsname.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <memory>
#include <thread>

#include <spdlog/spdlog.h>

#include "fissure/session/session_error.hpp"
#include "fissure/falcon_hw/device_recording.hpp"
#include "fissure/falcon_hw/recording_device.hpp"
#include "fissure/falcon_hw/replay_device.hpp"
#include "fissure/falcon_hw/sim_falcon.hpp"
#include "fissure/rt_core/faults.hpp"
#include "fissure/rt_core/rt_config.hpp"
#include "fissure/rt_core/rt_loop.hpp"
#include "fissure/rt_core/rt_thread.hpp"
#include "fissure/shared/clock.hpp"
#include "fissure/shared/spsc_ring.hpp"
#include "fissure/viewer/render_snapshot.hpp"
#include "fissure/viewer/session_view.hpp"
#include "fissure/session/host_loop.hpp"
#include "fissure/session/output_staging.hpp"
#include "fissure/session/scene_plausibility.hpp"
#include "fissure/session/rt_stack.hpp"
#include "fissure/session/session_host.hpp"

namespace fissure::session {
namespace {

using WallClock = std::chrono::steady_clock;

/// Status line refresh [s]: ~10×/s, slow enough not to cost the host thread CPU.
constexpr double kStatusPeriod_s = 0.1;
/// How often the main thread drains telemetry in real time [ms]: the 8192-sample ring holds
/// 8 s at 1 kHz, so 10 ms is far inside it and keeps Ctrl-C responsive.
constexpr int kDrainPeriod_ms = 10;
/// Session time the view's per-step figures are reserved for up front [s]; longer sessions grow them.
constexpr double kReservedView_s = 600.0;
/// Host statuses buffered between drains: 4096 host steps ≥ 4 s at 1 kHz.
constexpr std::size_t kHostStatusCapacity = 4096;

/// Host statuses from the host thread to the main thread (real time). Large: on the heap.
using HostStatusRing = SpscRing<HostStatus, kHostStatusCapacity>;

nlohmann::json quantile_json(std::vector<double> values) {
  const Quantiles q = quantiles(values);
  return {{"median", q.median}, {"p99", q.p99}, {"max", q.max}};
}

nlohmann::json quantile_json(const SampleReservoir& samples) {
  const Quantiles q = quantiles(samples);
  nlohmann::json j = {{"median", q.median}, {"p99", q.p99}, {"max", q.max}};
  // Beyond the reservoir the median and p99 come from a uniform sample of the values; say of how many.
  if (!samples.exact()) j["sampled_from"] = samples.count();
  return j;
}

/// The dotted path of the first non-finite number in `j` ("" when there is none): JSON has no
/// NaN or infinity, nlohmann writes them as null, and a summary with a null figure is not valid.
std::string first_non_finite_key(const nlohmann::json& j, const std::string& path) {
  if (j.is_number_float()) return std::isfinite(j.get<double>()) ? std::string() : path;
  if (j.is_object()) {
    for (const auto& [key, value] : j.items()) {
      const std::string found = first_non_finite_key(value, path.empty() ? key : path + "." + key);
      if (!found.empty()) return found;
    }
  }
  if (j.is_array()) {
    for (std::size_t i = 0; i < j.size(); ++i) {
      const std::string found = first_non_finite_key(j[i], path + "[" + std::to_string(i) + "]");
      if (!found.empty()) return found;
    }
  }
  return {};
}

/// --replay's recording, read and checked before anything else runs; null without --replay.
std::unique_ptr<const falcon::DeviceRecording> load_replay(const SessionOptions& options, const host::SceneDescription& scene) {
  if (options.replay_path.empty()) return nullptr;
  if (options.device == SessionDevice::kUsb) {
    throw SessionError("--replay answers from a recording instead of a device: it needs --device sim, not usb", true);
  }
  auto recording = std::make_unique<falcon::DeviceRecording>();
  try {
    *recording = falcon::read_recording(options.replay_path);
    if (recording->exchanges.empty()) throw falcon::RecordingError(options.replay_path.string() + ": holds no exchanges: nothing to replay");
  } catch (const falcon::RecordingError& e) {
    throw SessionError(std::string("--replay: ") + e.what(), true);
  }
  if (recording->header.scene_name != scene.name) {
    spdlog::warn("--replay: '{}' was recorded with scene '{}', this session runs '{}'", options.replay_path.string(),
                 recording->header.scene_name, scene.name);
  }
  return recording;
}

/// Whole seconds the longest session may last: a day at the bench. Longer is a typo (1e9) and
/// in lockstep would never end.
constexpr double kMaxSessionDuration_s = 86400.0;
/// The lockstep rt rates the command line accepts (--rate's range) [Hz].
constexpr double kMinRtRate_hz = 500.0;
constexpr double kMaxRtRate_hz = 10000.0;
/// How many whole-divisor --rate values a refusal suggests.
constexpr int kRateSuggestions = 4;

std::string ms_text(double seconds) {
  char text[48];
  std::snprintf(text, sizeof text, "%.4g ms", seconds * 1e3);
  return text;
}

std::string plain_number(double hz) {
  char text[48];
  std::snprintf(text, sizeof text, "%.6g", hz);
  return text;
}

/// Lockstep runs N whole rt ticks per host step: refuses, before anything is built, a host step
/// that is no whole number of rt periods, and says which --rate or --host-rate would work.
void check_lockstep_rates(const SessionOptions& options, const host::SceneDescription& scene) {
  if (!options.lockstep) return;
  const double host_dt_s = scene.simulation.time_step_s;
  const double rt_period_s = 1.0 / options.rt_rate_hz;
  const double ratio = host_dt_s / rt_period_s;
  const long ticks = std::lround(ratio);
  if (ticks >= 1 && std::abs(ratio - static_cast<double>(ticks)) <= 1e-6 * ratio) return;
  const std::string host_source = options.host_rate_hz > 0.0 ? "--host-rate" : "the scene's simulation.time_step_s";
  std::string message = "--lockstep: the host step (" + ms_text(host_dt_s) + ", " + host_source +
                        ") must be a whole number of rt periods (" + ms_text(rt_period_s) + " at --rate " + plain_number(options.rt_rate_hz) +
                        " Hz)";
  std::string rates;
  int suggested = 0;
  for (long n = std::max(1L, static_cast<long>(std::ceil(kMinRtRate_hz * host_dt_s - 1e-9)));
       suggested < kRateSuggestions && static_cast<double>(n) / host_dt_s <= kMaxRtRate_hz * (1.0 + 1e-9); ++n, ++suggested) {
    rates += (rates.empty() ? "" : ", ") + plain_number(static_cast<double>(n) / host_dt_s);
  }
  if (!rates.empty()) {
    message += ": use --rate " + rates;
  } else {
    message += ": the host step is " + std::string(ratio < 1.0 ? "shorter than one rt period" : "too long") +
               " for any --rate in 500..10000 Hz; use --host-rate H with a whole number of rt periods per host step (e.g. --host-rate " +
               plain_number(options.rt_rate_hz) + ")";
  }
  throw SessionError(message, true);
}

/// Session lengths that can run: a day at most, from --duration or the scene's hand script.
void check_duration(const SessionOptions& options, const host::SceneDescription& scene, double duration_s) {
  if (duration_s <= kMaxSessionDuration_s) return;
  const std::string source =
      options.duration_s > 0.0 ? "--duration" : "the hand script of " + scene.source_path + " (its legs and hold_s)";
  throw SessionError(source + " makes the session " + plain_number(duration_s) + " s long; at most " + plain_number(kMaxSessionDuration_s) +
                         " s (one day) per session",
                     options.duration_s > 0.0);
}

nlohmann::json fault_names(std::uint32_t bits) {
  nlohmann::json names = nlohmann::json::array();
  for (std::uint32_t bit = 1; bit != 0 && bit <= rt::kAnyFault; bit <<= 1u) {
    if ((bits & bit) != 0) names.push_back(rt::fault_name(bit));
  }
  return names;
}

// Prints the status line: in place on a terminal, one line per second otherwise (logs, CI).
class StatusPrinter {
 public:
  explicit StatusPrinter(bool enabled) : enabled_(enabled), tty_(isatty(STDERR_FILENO) == 1) {}
  void maybe_print(const SessionRecorder& recorder, double session_time_s, std::uint64_t ticks, std::uint64_t host_steps) {
    if (!enabled_) return;
    const WallClock::time_point now = WallClock::now();
    const double since = std::chrono::duration<double>(now - last_).count();
    if (since < (tty_ ? kStatusPeriod_s : 1.0)) return;
    const double tick_rate = static_cast<double>(ticks - last_ticks_) / since;
    const double host_rate = static_cast<double>(host_steps - last_host_steps_) / since;
    const std::string line = recorder.status_line(session_time_s, tick_rate, host_rate);
    std::fprintf(stderr, tty_ ? "\r%s\033[K" : "%s\n", line.c_str());
    last_ = now;
    last_ticks_ = ticks;
    last_host_steps_ = host_steps;
    printed_ = true;
  }
  void finish() {
    if (enabled_ && tty_ && printed_) std::fprintf(stderr, "\n");
  }

 private:
  bool enabled_;
  bool tty_;
  bool printed_ = false;
  WallClock::time_point last_ = WallClock::now();
  std::uint64_t last_ticks_ = 0;
  std::uint64_t last_host_steps_ = 0;
};

// The rt side of the view's overlay, from the telemetry drained so far. Tick rate over windows
// of at least kRateWindow_s of loop-clock time (one 10 ms drain is too short to read steadily).
class RtFiguresTracker {
 public:
  static constexpr double kRateWindow_s = 0.25;
  viewer::RtFigures update(const SessionRecorder& recorder) {
    const rt::TelemetrySample& s = recorder.last_tick();
    if (recorder.figures().telemetry_samples == 0) return figures_;
    if (!started_) {
      started_ = true;
      window_tick_ = s.tick;
      window_start_ns_ = s.time_ns;
    }
    const double span_s = to_seconds(s.time_ns - window_start_ns_);
    if (span_s >= kRateWindow_s) {
      figures_.tick_rate_hz = static_cast<double>(s.tick - window_tick_) / span_s;
      window_tick_ = s.tick;
      window_start_ns_ = s.time_ns;
    }
    figures_.force_n = as_eigen(s.force_device_n).norm();
    figures_.proxy_age_ms = s.proxy_sequence != 0 ? static_cast<double>(s.proxy_age_ns) * 1e-6 : std::numeric_limits<double>::quiet_NaN();
    figures_.overruns = static_cast<std::int64_t>(s.overruns);
    return figures_;
  }

 private:
  bool started_ = false;
  std::uint64_t window_tick_ = 0;
  TimeNs window_start_ns_ = 0;
  viewer::RtFigures figures_{};
};

bool interrupted(const SessionOptions& options) {
  return options.interrupt != nullptr && options.interrupt->load(std::memory_order_relaxed);
}

}  // namespace

double hand_script_duration_s(const HandScript& hand) {
  double total = 0.0;
  Eigen::Vector3d from = as_eigen(hand.start_position_device_m);
  for (const HandWaypoint& leg : hand.waypoints) {
    const Eigen::Vector3d to = as_eigen(leg.position_device_m);
    if (leg.speed_m_per_s > 0.0) total += (to - from).norm() / leg.speed_m_per_s;
    total += leg.hold_s;
    from = to;
  }
  return total;
}

host::SceneDescription scene_at_host_rate(const host::SceneDescription& scene, double host_rate_hz) {
  host::SceneDescription out = scene;
  if (host_rate_hz <= 0.0) return out;
  const double sub_step_s = scene.simulation.time_step_s / scene.simulation.substeps_count;
  const double host_dt_s = 1.0 / host_rate_hz;
  const double substeps = host_dt_s / sub_step_s;
  const long rounded = std::lround(substeps);
  if (rounded < 1 || std::abs(substeps - static_cast<double>(rounded)) > 1e-6 * substeps) {
    throw SessionError("--host-rate " + std::to_string(host_rate_hz) + " Hz: the host period must be a whole number of the scene's " +
                       std::to_string(sub_step_s * 1e3) + " ms collision sub-steps");
  }
  out.simulation.time_step_s = host_dt_s;
  out.simulation.substeps_count = static_cast<int>(rounded);
  return out;
}

namespace {

/// What the session's set-up builds and both run modes use.
struct SessionParts {
  const SessionOptions& options;
  const host::SceneDescription& scene;
  const rt::RtModel& model;
  SessionHost& host;
  SessionRecorder& recorder;
  StatusPrinter& status;
  viewer::SessionView* view;        ///< null without --view/--frames
  UsbFalcon* usb;                   ///< the opened USB Falcon (--device usb), else null
  const falcon::DeviceRecording* replay;  ///< --replay's recording, else null
  falcon::RecordingWriter* record;  ///< --record's writer, else null
  RtFiguresTracker rt_figures{};
  double duration_s = 0.0;          ///< 0: until interrupted
  [[nodiscard]] double host_dt_s() const { return scene.simulation.time_step_s; }
};

/// What a run mode reports beside the recorder's figures.
struct RunFigures {
  std::string device_name;
  double session_time_s = 0.0;
  std::uint64_t proxies_rejected = 0;
  std::uint64_t host_late_steps = 0;
  std::uint64_t host_status_dropped = 0;
  double wakeup_median_us = 0.0;
  double wakeup_p99_us = 0.0;
  double wakeup_max_us = 0.0;
  double max_tick_us = 0.0;
  nlohmann::json extra;             ///< mode-specific keys added to the summary
};

/// The device a run mode talks to: SimFalcon, the USB Falcon or a replayed recording, behind a
/// RecordingDevice with --record. Built on the run mode's clock, so recorded and replayed times
/// count from the same moment (the device's construction, just before the rt stack's).
class SessionDevices {
 public:
  SessionDevices(const SessionParts& parts, const falcon::SimFalconConfig& sim_config, const Clock& clock) {
    if (parts.replay != nullptr) {
      replay_ = std::make_unique<falcon::ReplayDevice>(*parts.replay, clock);
      device_ = replay_.get();
    } else if (parts.usb != nullptr) {
      device_ = &parts.usb->device();
    } else {
      sim_ = std::make_unique<falcon::SimFalcon>(sim_config, clock);
      device_ = sim_.get();
    }
    if (parts.record != nullptr) {
      recording_ = std::make_unique<falcon::RecordingDevice>(*device_, clock);
      device_ = recording_.get();
    }
  }
  [[nodiscard]] falcon::HapticDevice& device() const noexcept { return *device_; }
  /// Non-RT side: moves the recorded exchanges to the file.
  void drain_recording(const SessionParts& parts) {
    if (recording_) recording_->drain(*parts.record);
  }
  /// After the run: the last exchanges, then the end record (`stop_ns` on the run's clock).
  void finish_recording(const SessionParts& parts, TimeNs stop_ns, nlohmann::json& extra) {
    if (!recording_) return;
    recording_->drain(*parts.record);
    parts.record->finish(recording_->records_lost(), recording_->recording_time(stop_ns));
    extra["recording"] = {{"file", parts.options.record_path.string()},
                          {"exchanges", parts.record->records()},
                          {"lost", recording_->records_lost()}};
    if (recording_->records_lost() != 0) {
      spdlog::error("--record: {} exchanges were lost (the recording fell behind); the file cannot be replayed",
                    recording_->records_lost());
    }
  }
  void report(const SessionParts& parts, nlohmann::json& extra) const {
    if (sim_) {
      extra["sim_falcon"] = {{"exchanges", sim_->counters().exchanges}, {"kinematics_failures", sim_->counters().kinematics_failures}};
    }
    if (replay_) {
      const falcon::ReplayCounters& c = replay_->counters();
      extra["replay"] = {{"file", parts.options.replay_path.string()},
                         {"recorded_device", parts.replay->header.device_name},
                         {"recorded_scene", parts.replay->header.scene_name},
                         {"recorded_rt_rate_hz", parts.replay->header.rt_rate_hz},
                         {"records", parts.replay->exchanges.size()},
                         {"exchanges", c.exchanges},
                         {"records_used", c.records_used},
                         {"commands_differing", c.commands_differing},
                         {"exchanges_after_end", c.after_end}};
    }
  }

 private:
  std::unique_ptr<falcon::SimFalcon> sim_;
  std::unique_ptr<falcon::ReplayDevice> replay_;
  std::unique_ptr<falcon::RecordingDevice> recording_;
  falcon::HapticDevice* device_ = nullptr;
};

// The view's picture model is built from the settled body (its rest shape is what the
// deformation colours are measured from), before any thread steps the simulation, and its
// sinks (window, frame writer) start before the first tick: Mesa maps and locks LLVM when it
// starts, which stalls a running rt loop for tens of ms (docs/decisions.md); started here,
// that cost lands in the rt set-up (summary.json's rt_setup.seconds), not in the session.
std::unique_ptr<viewer::SessionView> start_view(const SessionOptions& options, SessionHost& host, double expected_s,
                                                double host_dt_s, const std::filesystem::path& staged_frames_dir) {
  if (!options.view && options.frames_dir.empty()) return nullptr;
  viewer::RenderModel view_model;
  try {
    view_model = viewer::make_render_model(host.simulation());
  } catch (const std::exception& e) {
    throw SessionError(std::string("--view/--frames: ") + e.what());
  }
  viewer::SessionViewOptions vo;
  vo.window = options.view;
  vo.window_options.width_px = options.frame_width_px;
  vo.window_options.height_px = options.frame_height_px;
  vo.window_options.method_switching = false;  // a session cannot swap its method under the hand
  vo.window_options.screenshot_dir = options.out_dir;
  vo.frames_dir = staged_frames_dir;
  vo.frame_every_steps = options.frame_every;
  vo.frame_width_px = options.frame_width_px;
  vo.frame_height_px = options.frame_height_px;
  vo.wait_for_frames = options.lockstep;
  vo.expected_host_steps = static_cast<std::size_t>(std::min(expected_s, kReservedView_s) / host_dt_s);
  std::string error;
  std::string notice;
  std::unique_ptr<viewer::SessionView> view = viewer::SessionView::start(view_model, vo, error, notice);
  if (!notice.empty()) std::fprintf(stderr, "%s\n", notice.c_str());
  if (!view) throw SessionError("--frames: " + error);
  return view;
}

/// Lockstep: one thread on a LockstepClock — N rt ticks, one host step, repeat.
void run_lockstep(SessionParts& parts, const falcon::SimFalconConfig& sim_config, RunFigures& out) {
  LockstepClock clock(0);
  SessionDevices devices(parts, sim_config, clock);
  out.device_name = devices.device().name();
  RtStack rt(parts.model, devices.device(), clock);
  rt::RtLoop& loop = rt.loop();
  RtChannels& channels = rt.channels();
  const double host_dt_s = parts.host_dt_s();
  const double ratio = host_dt_s / parts.model.period_s;
  const auto ticks_per_host = static_cast<std::uint64_t>(std::llround(ratio));  // whole: check_lockstep_rates
  const auto end_ns = static_cast<TimeNs>(std::llround(parts.duration_s * 1e9));
  rt::TelemetrySample sample;
  std::optional<TimeNs> stop_ns;
  while (!loop.stopped()) {
    if (clock.now() >= end_ns || interrupted(parts.options) || !parts.recorder.figures().first_non_finite.empty()) {
      loop.request_stop();
      if (!stop_ns) stop_ns = clock.now();
    }
    for (std::uint64_t k = 0; k < ticks_per_host && !loop.stopped(); ++k) loop.step();
    devices.drain_recording(parts);
    const HostStatus& host_status = parts.host.step(channels.state, channels.proxy);
    parts.recorder.add_host_step(host_status);
    while (channels.telemetry.try_pop(sample)) parts.recorder.add_tick(sample, host_status);
    if (parts.view != nullptr) {
      parts.view->rt_figures().publish(parts.rt_figures.update(parts.recorder));
      parts.view->on_host_step(parts.host.simulation(), &parts.host.last_proxy());
    }
    out.session_time_s = to_seconds(clock.now());
    parts.status.maybe_print(parts.recorder, out.session_time_s, parts.recorder.figures().ticks, parts.recorder.figures().host_steps);
  }
  loop.send_zero_command();
  out.proxies_rejected = loop.data().proxy.rejected_count;
  devices.report(parts, out.extra);
  devices.finish_recording(parts, stop_ns.value_or(clock.now()), out.extra);
}

/// Real time: the rt thread (SCHED_FIFO best effort) and the host thread (one step per host
/// period); this thread drains telemetry, writes the trace and refreshes the status line.
void run_realtime(SessionParts& parts, const falcon::SimFalconConfig& sim_config, RunFigures& out) {
  const SessionOptions& options = parts.options;
  const bool until_interrupted = parts.duration_s <= 0.0;
  MonotonicClock clock;
  SessionDevices devices(parts, sim_config, clock);
  falcon::HapticDevice& haptic = devices.device();
  out.device_name = haptic.name();
  RtStack rt(parts.model, haptic, clock);
  rt::RtLoop& loop = rt.loop();
  RtChannels& channels = rt.channels();
  auto host_statuses = std::make_unique<HostStatusRing>();
  std::atomic<bool> stop_rt{false};
  std::atomic<bool> stop_host{false};
  std::atomic<std::uint64_t> dropped{0};
  std::string host_error;
  const TimeNs start_ns = clock.now();
  const TimeNs end_ns = until_interrupted ? std::numeric_limits<TimeNs>::max()
                                          : start_ns + static_cast<TimeNs>(std::llround(parts.duration_s * 1e9));

  rt::RtThreadConfig thread_config;
  thread_config.policy = rt::RtPolicy::kBestEffort;
  RtThread rt_thread(thread_config, [&] {
    // The session's length counts from the first tick, not from before the set-up.
    loop.run_until(until_interrupted ? end_ns : clock.now() + (end_ns - start_ns), stop_rt);
  });
  HostLoop host_loop(clock);
  std::thread host_thread([&] {
    host_loop.run(static_cast<TimeNs>(std::llround(parts.host_dt_s() * 1e9)), stop_host, [&] {
      try {
        const HostStatus& st = parts.host.step(channels.state, channels.proxy);
        if (!host_statuses->try_push(st)) dropped.fetch_add(1, std::memory_order_relaxed);
        // Wait-free hand-off to the window / frame writer threads (never waits in real time).
        if (parts.view != nullptr) parts.view->on_host_step(parts.host.simulation(), &parts.host.last_proxy());
        return true;
      } catch (const std::exception& e) {
        host_error = e.what();
        stop_rt.store(true);  // the proxy goes stale and fades; ramp out and stop
        return false;
      }
    });
  });

  rt::TelemetrySample sample;
  HostStatus host_status;
  auto drain = [&] {
    while (host_statuses->try_pop(host_status)) parts.recorder.add_host_step(host_status);
    while (channels.telemetry.try_pop(sample)) parts.recorder.add_tick(sample, host_status);
    devices.drain_recording(parts);
  };
  std::optional<TimeNs> stop_ns;
  while (!rt_thread.done()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(kDrainPeriod_ms));
    if (interrupted(options) || !parts.recorder.figures().first_non_finite.empty()) {
      stop_rt.store(true);
      if (!stop_ns) stop_ns = clock.now();
    }
    drain();
    if (parts.view != nullptr) parts.view->rt_figures().publish(parts.rt_figures.update(parts.recorder));
    out.session_time_s = to_seconds(clock.now() - start_ns);
    parts.status.maybe_print(parts.recorder, out.session_time_s, parts.recorder.figures().ticks, parts.recorder.figures().host_steps);
  }
  rt_thread.join();
  stop_host.store(true);
  host_thread.join();
  drain();
  if (!host_error.empty()) spdlog::error("host thread stopped: {}", host_error);
  out.proxies_rejected = loop.data().proxy.rejected_count;
  out.host_late_steps = host_loop.late_steps();
  out.host_status_dropped = dropped.load();
  out.wakeup_median_us = loop.stats().wakeup.quantile_us(0.5);
  out.wakeup_p99_us = loop.stats().wakeup.quantile_us(0.99);
  out.wakeup_max_us = loop.stats().wakeup.quantile_us(1.0);
  out.max_tick_us = static_cast<double>(loop.stats().max_tick_ns) * 1e-3;
  const rt::RtSetupReport& setup_report = rt_thread.setup_report();
  out.extra["rt_setup"] = {{"sched_fifo", setup_report.sched_fifo},
                           {"memory_locked", setup_report.memory_locked},
                           {"seconds", rt_thread.setup_seconds()},
                           {"warnings", std::string(setup_report.message)}};
  if (setup_report.message[0] != '\0') spdlog::warn("rt thread: {}", setup_report.message);
  if (!host_error.empty()) out.extra["host_error"] = host_error;
  devices.report(parts, out.extra);
  // The session's end: Ctrl-C's moment, else the duration counted from the first tick.
  const TimeNs first_tick_ns = parts.recorder.figures().telemetry_samples != 0 ? parts.recorder.figures().first_tick_time_ns : start_ns;
  const TimeNs planned_stop_ns = until_interrupted ? clock.now() : first_tick_ns + (end_ns - start_ns);
  devices.finish_recording(parts, stop_ns ? std::min(*stop_ns, planned_stop_ns) : planned_stop_ns, out.extra);
}

nlohmann::json view_json(const SessionOptions& options, const viewer::SessionViewStats& stats) {
  nlohmann::json v;
  v["window"] = {{"requested", options.view}, {"open", stats.window_open}, {"frames_drawn", stats.window_frames}};
  if (!options.frames_dir.empty()) {
    std::vector<double> frame_ms;
    for (const double t : stats.frame_s) frame_ms.push_back(t * 1e3);
    v["frames"] = {{"dir", options.frames_dir.string()},
                   {"every_host_steps", options.frame_every},
                   {"published", stats.frames_published},
                   {"written", stats.frames_written},
                   {"dropped", stats.frames_dropped},
                   {"waited_for", options.lockstep},
                   {"frame_ms", quantile_json(std::move(frame_ms))},
                   {"gl", stats.gl_description},
                   {"error", stats.frames_error}};
  }
  std::vector<double> publish_us;
  for (const double t : stats.capture_publish_s) publish_us.push_back(t * 1e6);
  v["capture_publish_us"] = quantile_json(std::move(publish_us));
  return v;
}

nlohmann::json summary_json(const SessionParts& parts, const RunFigures& run, double wall_s,
                            const std::optional<viewer::SessionViewStats>& view_stats) {
  const SessionOptions& options = parts.options;
  const SessionFigures& f = parts.recorder.figures();
  nlohmann::json summary;
  summary["scene"] = parts.scene.name;
  summary["mode"] = options.lockstep ? "lockstep" : "realtime";
  summary["device"] = run.device_name;
  summary["duration_s"] = run.session_time_s;
  summary["wall_s"] = wall_s;
  summary["rt_rate_hz"] = options.rt_rate_hz;
  summary["host_rate_hz"] = 1.0 / parts.host_dt_s();
  summary["ticks"] = f.ticks;
  // Over the ticks the loop ran (first to last telemetry sample), not the set-up before it.
  const double ticking_s = to_seconds(f.last_tick_time_ns - f.first_tick_time_ns);
  summary["tick_rate_hz"] = ticking_s > 0.0 ? static_cast<double>(f.telemetry_samples - 1) / ticking_s : 0.0;
  summary["crossed_nodes_max"] = f.crossed_nodes_max;
  summary["tool_reseats"] = f.tool_reseats;
  summary["soft_volume_ratio_min"] = f.soft_volume_ratio_min;
  summary["soft_everted"] = f.soft_volume_ratio_min < 0.0;
  summary["faults"] = f.fault_ticks;
  summary["fault_kinds"] = fault_names(f.fault_bits_seen);
  // The flag bits of fault_bits (16..20) are not faults: ticks with each, by name, so a trace row
  // with fault_bits 524288 and "faults": 0 explain each other (docs/session.md).
  nlohmann::json flags = nlohmann::json::object();
  for (std::size_t flag = 0; flag < f.flag_ticks.size(); ++flag) flags[rt::fault_name(rt::kFlagForceClamped << flag)] = f.flag_ticks[flag];
  summary["flag_ticks"] = flags;
  summary["proxies_rejected"] = run.proxies_rejected;
  summary["overruns"] = f.overruns;
  summary["force_max_n"] = f.force_max_n;
  summary["force_limit_n"] = parts.model.config.safety.max_force_n;
  summary["contact_force_max_n"] = f.contact_force_max_n;
  summary["host_force_max_n"] = f.host_force_max_n;
  summary["proxy_age_ms"] = quantile_json(f.proxy_age_ms);
  summary["energy_j"] = f.energy_j;
  summary["energy_max_j"] = f.energy_max_j;
  summary["passivity_controller"] = options.passivity_controller;
  summary["contact_depth_max_mm"] = f.rt_penetration_max_m * 1e3;
  summary["host_penetration_max_mm"] = f.host_penetration_max_m * 1e3;
  summary["host_steps"] = f.host_steps;
  summary["host_step_ms"] = quantile_json(f.host_step_ms);
  summary["host_late_steps"] = run.host_late_steps;
  summary["host_status_dropped"] = run.host_status_dropped;
  if (!options.lockstep) {
    summary["wakeup_latency_us"] = {{"median", run.wakeup_median_us}, {"p99", run.wakeup_p99_us}, {"max", run.wakeup_max_us}};
    summary["max_tick_us"] = run.max_tick_us;
    summary["tick_interval_us"] = quantile_json(f.tick_interval_us);
  }
  if (view_stats) {
    summary["view"] = view_json(options, *view_stats);
    if (!view_stats->frames_error.empty()) spdlog::error("--frames: {}", view_stats->frames_error);
  }
  summary["telemetry_samples"] = f.telemetry_samples;
  for (const auto& [key, value] : run.extra.items()) summary[key] = value;
  summary["machine"] = machine_info();
  return summary;
}

/// Writes summary and plot under their temporary names, then moves every output into place
/// (the summary last: its presence marks a complete run).
SessionOutcome write_outcome(const SessionOptions& options, const host::SceneDescription& scene, const SessionRecorder& recorder,
                             OutputStaging& staging, nlohmann::json summary) {
  SessionOutcome outcome;
  outcome.trace_path = options.out_dir / "trace.csv";
  if (options.plot) {
    std::string error;
    const std::filesystem::path png = staging.file(options.out_dir / "session.png");
    if (plot_session(recorder.trace_path(), png, scene.name + (options.lockstep ? " (lockstep)" : " (real time)"), error).empty()) {
      spdlog::warn("{}", error);
    } else {
      outcome.plot_path = options.out_dir / "session.png";
    }
  }
  outcome.summary_path = options.out_dir / "summary.json";
  {
    std::ofstream out(staging.file(outcome.summary_path));
    out << summary.dump(2) << "\n";
    if (!out) throw SessionError("cannot write '" + outcome.summary_path.string() + "'");
  }
  staging.commit();
  outcome.summary = std::move(summary);
  return outcome;
}

/// A run whose figures went non-finite has no valid outputs: say which quantity, and when.
void require_finite(const SessionRecorder& recorder, const nlohmann::json& summary) {
  const std::string& rt_or_host = recorder.figures().first_non_finite;
  if (!rt_or_host.empty()) {
    throw SessionError("the session produced a non-finite " + rt_or_host +
                       "; nothing was written (the scene's values are the usual cause: see docs/scenes.md, \"Plausible values\")");
  }
  const std::string key = first_non_finite_key(summary, "");
  if (!key.empty()) throw SessionError("the session's summary figure '" + key + "' is non-finite; nothing was written");
}

}  // namespace

SessionOutcome run_session(const SessionOptions& options) {
  // Everything that can be refused is refused here, before the device is opened, the soft body
  // settles or any output is touched.
  const host::SceneDescription scene = scene_at_host_rate(options.scene, options.host_rate_hz);
  if (options.lockstep && options.device == SessionDevice::kUsb) {
    throw SessionError("--lockstep runs on simulated time: it needs --device sim, not the USB Falcon", true);
  }
  check_lockstep_rates(options, scene);
  rt::RtConfig config;
  config.rate_hz = options.rt_rate_hz;
  config.mapping = scene.device_mapping;
  config.passivity.enabled = options.passivity_controller;
  const rt::RtModel model = build_rt_model(config);

  const double host_dt_s = scene.simulation.time_step_s;
  const std::unique_ptr<const falcon::DeviceRecording> replay = load_replay(options, scene);
  double duration_s = options.duration_s;
  if (replay) {
    const double recorded_s = to_seconds(replay->session_end_ns);
    if (duration_s > recorded_s) {
      throw SessionError("--duration " + plain_number(duration_s) + " s is longer than the recorded session in '" +
                             options.replay_path.string() + "' (" + plain_number(recorded_s) + " s)",
                         true);
    }
    if (duration_s <= 0.0) duration_s = recorded_s;
  }
  if (duration_s <= 0.0 && options.device == SessionDevice::kSim) duration_s = hand_script_duration_s(scene.hand);
  if (duration_s <= 0.0 && options.lockstep) {
    throw SessionError("--lockstep needs a duration: the scene's hand script is empty");
  }
  check_duration(options, scene, duration_s);
  const bool until_interrupted = duration_s <= 0.0;

  if (!options.replay_path.empty() && !options.record_path.empty() &&
      std::filesystem::weakly_canonical(options.replay_path) == std::filesystem::weakly_canonical(options.record_path)) {
    throw SessionError("--record and --replay name the same file '" + options.record_path.string() + "'", true);
  }

  MonotonicClock usb_clock;
  std::unique_ptr<UsbFalcon> usb;
  if (options.device == SessionDevice::kUsb) usb = UsbFalcon::open(usb_clock);

  SessionHost host(scene);
  const Eigen::AlignedBox3d loaded_bounds = host.simulation().soft_bounds_world_m();
  host.settle(options.settle_s);
  const std::string settle_warning =
      check_settled_on_ground(loaded_bounds, host.simulation().soft_bounds_world_m(), scene, options.settle_s);
  if (!settle_warning.empty()) spdlog::warn("{}", settle_warning);

  OutputStaging staging;
  const std::filesystem::path staged_frames =
      options.frames_dir.empty() ? std::filesystem::path() : staging.directory(options.frames_dir, "frame_", ".png");
  const double expected_s = until_interrupted ? 60.0 : duration_s + 1.0;
  std::unique_ptr<viewer::SessionView> view = start_view(options, host, expected_s, host_dt_s, staged_frames);
  SessionRecorder recorder(staging.file(options.out_dir / "trace.csv"));
  std::unique_ptr<falcon::RecordingWriter> record;
  if (!options.record_path.empty()) {
    falcon::RecordingHeader header;
    header.rt_rate_hz = options.rt_rate_hz;
    header.device_name = replay ? "replay" : options.device == SessionDevice::kUsb ? "usb-falcon" : "sim-falcon";
    header.scene_name = scene.name;
    try {
      record = std::make_unique<falcon::RecordingWriter>(staging.file(options.record_path), header);
    } catch (const falcon::RecordingError& e) {
      throw SessionError(std::string("--record: ") + e.what());
    }
  }
  StatusPrinter status(options.status_line);
  SessionParts parts{options, scene, model, host, recorder, status, view.get(), usb.get(), replay.get(), record.get()};
  parts.duration_s = duration_s;
  const WallClock::time_point wall_start = WallClock::now();
  falcon::SimFalconConfig sim_config;
  sim_config.hand = scene.hand;
  RunFigures run;
  if (options.lockstep) {
    run_lockstep(parts, sim_config, run);
  } else {
    run_realtime(parts, sim_config, run);
  }
  status.finish();
  recorder.close_trace();
  std::optional<viewer::SessionViewStats> view_stats;
  if (view) view_stats = view->finish();
  const double wall_s = std::chrono::duration<double>(WallClock::now() - wall_start).count();
  nlohmann::json summary = summary_json(parts, run, wall_s, view_stats);
  require_finite(recorder, summary);
  return write_outcome(options, scene, recorder, staging, std::move(summary));
}

}  // namespace fissure::session
