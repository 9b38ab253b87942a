// `fissure bench proxy --json FILE` (issue 6, "Accuracy against run time"): the contact force
// rt_core renders when the host refreshes the proxy at {1000, 500, 250, 100, 50} Hz, against an
// oracle in which the host refreshes it every rt tick — on the SAME device trajectory.
//
// How "same trajectory" is made exact: the oracle is a closed-loop lockstep session (SimFalcon
// with the scene's hand, rt_core, host at the rt rate) whose device readings (encoder counts,
// buttons) are recorded exchange by exchange; every row then replays those readings into a fresh
// rt loop (the replay device ignores the motor commands), so FK, velocity and the tool path are
// bit-identical and only the proxy refresh rate differs. The oracle's own replay is run too and
// must give exactly the oracle's forces (a determinism check, reported).
//
// The rt loop runs at 2 kHz by default so that the 1000 Hz row is a real comparison (at a 1 kHz
// rt loop the 1 kHz host IS the oracle). The host's collision sub-step is one rt period for every
// row (the scene's physics is the same; a slower host takes more sub-steps per step), so the
// error is the proxy's, not a different discretisation of the soft body.
// Measured per row: RMS and peak |F − F_oracle| of the rendered contact force (after blend and
// fade, before passivity/safety) as % of the oracle's peak |F|, max |ΔF| per tick, and host CPU
// time (thread CPU clock) per simulated second, plus host step time median/p99.
#include "bench_proxy.hpp"
#include "machine_info.hpp"

#include <sys/utsname.h>
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "fissure/falcon_hw/sim_falcon.hpp"
#include "fissure/host_sim/scene_loader.hpp"
#include "fissure/rt_core/rt_config.hpp"
#include "fissure/rt_core/rt_loop.hpp"
#include "fissure/shared/clock.hpp"
#include "session_host.hpp"
#include "session_record.hpp"
#include "session_runner.hpp"

namespace fissure::app {
namespace {

// Records every reading a device gives (the oracle run), forwarding to the real device.
class RecordingDevice final : public falcon::HapticDevice {
 public:
  RecordingDevice(falcon::HapticDevice& inner, std::size_t expected) : inner_(inner) { readings_.reserve(expected); }
  [[nodiscard]] const char* name() const noexcept override { return inner_.name(); }
  falcon::IoStatus try_exchange(const falcon::DeviceCommand& command, falcon::DeviceReading& reading) noexcept override {
    const falcon::IoStatus status = inner_.try_exchange(command, reading);
    if (readings_.size() < readings_.capacity()) readings_.push_back({status, reading});  // never reallocates
    return status;
  }
  struct Entry {
    falcon::IoStatus status;
    falcon::DeviceReading reading;
  };
  [[nodiscard]] const std::vector<Entry>& readings() const noexcept { return readings_; }

 private:
  falcon::HapticDevice& inner_;
  std::vector<Entry> readings_;
};

// Plays the recorded readings back in order, whatever the command (the hand does not feel it).
class ReplayDevice final : public falcon::HapticDevice {
 public:
  explicit ReplayDevice(const std::vector<RecordingDevice::Entry>& readings) : readings_(readings) {}
  [[nodiscard]] const char* name() const noexcept override { return "replay"; }
  falcon::IoStatus try_exchange(const falcon::DeviceCommand& /*command*/, falcon::DeviceReading& reading) noexcept override {
    if (readings_.empty()) return falcon::IoStatus::kNotRunning;
    const RecordingDevice::Entry& e = readings_[std::min(next_, readings_.size() - 1)];
    ++next_;
    if (e.status == falcon::IoStatus::kOk) reading = e.reading;
    return e.status;
  }

 private:
  const std::vector<RecordingDevice::Entry>& readings_;
  std::size_t next_ = 0;
};

double thread_cpu_s() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

struct RunResult {
  std::vector<Eigen::Vector3d> contact_force_n;  // per tick, device frame
  std::vector<double> host_step_ms;
  double host_cpu_s = 0.0;
  double simulated_s = 0.0;
  int crossed_nodes_max = 0;
};

// One lockstep run: `device` (SimFalcon for the oracle, a replay for the rows), host every
// ticks_per_host rt ticks, for `ticks` rt ticks (no ramp-out: the trajectory is the hand script).
RunResult run_once(const host::SceneDescription& scene, const rt::RtModel& model, falcon::HapticDevice& device,
                   LockstepClock& clock, int ticks_per_host, std::size_t ticks, double settle_s) {
  SessionHost host(scene);
  host.settle(settle_s);
  auto proxy = std::make_unique<rt::ProxyExchange>();
  auto state = std::make_unique<rt::DeviceStateExchange>();
  auto telemetry = std::make_unique<rt::TelemetryRing>();
  rt::RtLoop loop(model, device, clock, *proxy, *state, *telemetry);
  RunResult result;
  result.contact_force_n.reserve(ticks);
  result.host_step_ms.reserve(ticks / static_cast<std::size_t>(ticks_per_host) + 1);
  rt::TelemetrySample sample;
  std::size_t done = 0;
  while (done < ticks) {
    for (int k = 0; k < ticks_per_host && done < ticks; ++k, ++done) loop.step();
    const double cpu_before = thread_cpu_s();
    const HostStatus& status = host.step(*state, *proxy);
    result.host_cpu_s += thread_cpu_s() - cpu_before;
    result.host_step_ms.push_back(status.step_cpu_s * 1e3);
    result.crossed_nodes_max = std::max(result.crossed_nodes_max, status.crossed_nodes);
    while (telemetry->try_pop(sample)) result.contact_force_n.push_back(as_eigen(sample.contact_force_device_n));
  }
  result.simulated_s = static_cast<double>(ticks) * model.period_s;
  return result;
}

struct BenchOptions {
  std::string scene = "spatula-sphere";
  std::string json_path;
  double rt_rate_hz = 2000.0;
  std::vector<double> host_rates_hz{1000.0, 500.0, 250.0, 100.0, 50.0};
  double duration_s = 0.0;
  double settle_s = 1.0;
};

struct ErrorFigures {
  double rms_pct = 0.0;
  double peak_pct = 0.0;
  double max_dforce_n = 0.0;
};

ErrorFigures compare(const std::vector<Eigen::Vector3d>& run, const std::vector<Eigen::Vector3d>& oracle) {
  ErrorFigures e;
  double peak_oracle = 0.0;
  for (const Eigen::Vector3d& f : oracle) peak_oracle = std::max(peak_oracle, f.norm());
  const std::size_t n = std::min(run.size(), oracle.size());
  double sum_sq = 0.0;
  double peak_error = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double err = (run[i] - oracle[i]).norm();
    sum_sq += err * err;
    peak_error = std::max(peak_error, err);
    if (i > 0) e.max_dforce_n = std::max(e.max_dforce_n, (run[i] - run[i - 1]).norm());
  }
  if (n > 0 && peak_oracle > 0.0) {
    e.rms_pct = 100.0 * std::sqrt(sum_sq / static_cast<double>(n)) / peak_oracle;
    e.peak_pct = 100.0 * peak_error / peak_oracle;
  }
  return e;
}

void run_bench(const BenchOptions& options) {
  host::SceneDescription base;
  try {
    base = host::load_scene(host::resolve_scene_path(options.scene));
  } catch (const std::exception& e) {
    throw CommandError(e.what());
  }
  // One collision sub-step per rt period for every row (see the file comment).
  host::SceneDescription scene_template = base;
  scene_template.simulation.time_step_s = 1.0 / options.rt_rate_hz;
  scene_template.simulation.substeps_count = 1;
  rt::RtConfig config;
  config.rate_hz = options.rt_rate_hz;
  config.mapping = base.device_mapping;
  rt::RtModel model;
  const char* error = nullptr;
  if (!rt::build_model(config, model, &error)) throw CommandError(std::string("--rt-rate: ") + error);
  const double duration_s = options.duration_s > 0.0 ? options.duration_s : hand_script_duration_s(base.hand);
  const auto ticks = static_cast<std::size_t>(std::llround(duration_s * options.rt_rate_hz));

  // Oracle: closed loop with SimFalcon, host every tick; record the readings.
  std::vector<RecordingDevice::Entry> readings;
  RunResult oracle;
  {
    LockstepClock clock(0);
    falcon::SimFalconConfig sim_config;
    sim_config.hand = base.hand;
    falcon::SimFalcon sim(sim_config, clock);
    RecordingDevice recorder(sim, ticks + 16);
    oracle = run_once(scene_template, model, recorder, clock, 1, ticks, options.settle_s);
    readings = recorder.readings();
  }
  double peak_oracle = 0.0;
  for (const Eigen::Vector3d& f : oracle.contact_force_n) peak_oracle = std::max(peak_oracle, f.norm());

  auto replay_at = [&](double host_hz) {
    const double ratio = options.rt_rate_hz / host_hz;
    const long per = std::lround(ratio);
    if (per < 1 || std::abs(ratio - static_cast<double>(per)) > 1e-9 * ratio) {
      throw CommandError("host rate " + std::to_string(host_hz) + " Hz does not divide the rt rate " +
                         std::to_string(options.rt_rate_hz) + " Hz");
    }
    const host::SceneDescription scene = scene_at_host_rate(scene_template, host_hz);
    LockstepClock clock(0);
    ReplayDevice device(readings);
    return run_once(scene, model, device, clock, static_cast<int>(per), ticks, options.settle_s);
  };

  const RunResult self = replay_at(options.rt_rate_hz);
  const ErrorFigures self_error = compare(self.contact_force_n, oracle.contact_force_n);

  std::printf("bench proxy: scene %s, rt %.0f Hz, %.2f s of the hand script (%zu ticks), oracle peak |F| %.3f N\n",
              base.name.c_str(), options.rt_rate_hz, duration_s, ticks, peak_oracle);
  std::printf("oracle replay (host every tick) vs oracle: rms %.3g %%, peak %.3g %% (determinism check)\n",
              self_error.rms_pct, self_error.peak_pct);
  std::printf("%8s %14s %15s %13s %17s %14s %14s\n", "host_hz", "rms_error_pct", "peak_error_pct", "max_dforce_n",
              "host_cpu_s_per_s", "step_ms_med", "step_ms_p99");
  nlohmann::json rows = nlohmann::json::array();
  const auto add_row = [&](double host_hz, RunResult& run) {
    const ErrorFigures e = compare(run.contact_force_n, oracle.contact_force_n);
    const Quantiles q = quantiles(run.host_step_ms);
    const double cpu_per_s = run.host_cpu_s / run.simulated_s;
    std::printf("%8.0f %14.3f %15.3f %13.4f %17.3f %14.3f %14.3f\n", host_hz, e.rms_pct, e.peak_pct, e.max_dforce_n,
                cpu_per_s, q.median, q.p99);
    rows.push_back({{"host_hz", host_hz},
                    {"rms_error_pct", e.rms_pct},
                    {"peak_error_pct", e.peak_pct},
                    {"max_dforce_n", e.max_dforce_n},
                    {"host_cpu_s_per_s", cpu_per_s},
                    {"host_step_ms", {{"median", q.median}, {"p99", q.p99}, {"max", q.max}, {"samples", run.host_step_ms.size()}}},
                    {"crossed_nodes_max", run.crossed_nodes_max}});
  };
  {
    RunResult oracle_copy = oracle;
    const Quantiles q = quantiles(oracle_copy.host_step_ms);
    std::printf("%8.0f %14.3f %15.3f %13.4f %17.3f %14.3f %14.3f  (oracle)\n", options.rt_rate_hz, 0.0, 0.0,
                compare(oracle.contact_force_n, oracle.contact_force_n).max_dforce_n,
                oracle.host_cpu_s / oracle.simulated_s, q.median, q.p99);
  }
  for (const double host_hz : options.host_rates_hz) {
    RunResult run = replay_at(host_hz);
    add_row(host_hz, run);
  }

  nlohmann::json out;
  out["benchmark"] = "proxy";
  out["scene"] = base.name;
  out["rt_rate_hz"] = options.rt_rate_hz;
  out["collision_substep_s"] = 1.0 / options.rt_rate_hz;
  out["duration_s"] = duration_s;
  out["ticks"] = ticks;
  out["force_compared"] = "rt contact force after blend and fade, before passivity/safety (device frame)";
  out["oracle"] = {{"host_hz", options.rt_rate_hz},
                   {"peak_force_n", peak_oracle},
                   {"host_cpu_s_per_s", oracle.host_cpu_s / oracle.simulated_s},
                   {"replay_rms_error_pct", self_error.rms_pct},
                   {"replay_peak_error_pct", self_error.peak_pct}};
  out["targets"] = {{"rms_error_pct_at_100_hz", 2.0}, {"rms_error_pct_at_1000_hz", 0.5}, {"max_dforce_n", 0.05}};
  out["rows"] = rows;
  out["machine"] = machine_info();
  if (!options.json_path.empty()) {
    std::ofstream file(options.json_path);
    if (!file) throw CommandError("cannot write '" + options.json_path + "'");
    file << out.dump(2) << "\n";
    std::printf("wrote %s\n", options.json_path.c_str());
  }
}

}  // namespace

void register_bench_proxy(CommandTree& tree) {
  auto options = std::make_shared<BenchOptions>();
  CLI::App* cmd = tree.bench.add_subcommand(
      "proxy", "Rendered force vs an every-tick-proxy oracle on the same trajectory, over host rates");
  cmd->add_option("--json", options->json_path, "write the table as JSON here");
  cmd->add_option("--scene", options->scene, "scene name or file (default spatula-sphere)");
  cmd->add_option("--rt-rate", options->rt_rate_hz, "rt tick rate [Hz]; the oracle's host runs at this rate")
      ->check(CLI::Range(500.0, 10000.0));
  cmd->add_option("--host-rates", options->host_rates_hz, "host rates to compare [Hz]")->expected(1, 16);
  cmd->add_option("--duration", options->duration_s, "seconds (default: the hand script's length)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--settle", options->settle_s, "soft body settling before each run [s]")->check(CLI::NonNegativeNumber);
  cmd->callback([options] { run_bench(*options); });
}

}  // namespace fissure::app
