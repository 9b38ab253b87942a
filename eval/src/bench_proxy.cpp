// `fissure bench proxy --json FILE` (accuracy against run time): the contact force
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
// time (thread CPU clock) per simulated second, plus host step time median/p99. Reported with
// them: the lag rt_core's sub-count force position adds to the rendered contact at this rt rate
// (force_position.hpp) — what the force's smoothness per tick costs in lag (issue 26).
#include "fissure/eval/bench_proxy.hpp"
#include "fissure/session/machine_info.hpp"

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

#include <nlohmann/json.hpp>

#include "fissure/eval/eval_error.hpp"
#include "fissure/falcon_hw/sim_falcon.hpp"
#include "fissure/host_sim/proxy_model.hpp"
#include "fissure/host_sim/scene_loader.hpp"
#include "fissure/shared/device_mapping.hpp"
#include "fissure/rt_core/force_position.hpp"
#include "fissure/rt_core/hunt_crossley.hpp"
#include "fissure/rt_core/proxy_intake.hpp"
#include "fissure/rt_core/rt_config.hpp"
#include "fissure/rt_core/rt_loop.hpp"
#include "fissure/session/rt_stack.hpp"
#include "fissure/shared/clock.hpp"
#include "fissure/session/session_host.hpp"
#include "fissure/session/session_record.hpp"
#include "fissure/session/session_runner.hpp"

namespace fissure::eval {
using namespace fissure::session;  // the session library: SessionHost, run_session, LinkBridge, …
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

// What one run leaves for the comparison: per tick the rendered force and what is needed to
// re-evaluate any proxy at that tick's pose; per host step the host's own force and the proxy it
// published (so the error can be split into host divergence, proxy model and blend terms).
struct RunResult {
  std::vector<Eigen::Vector3d> contact_force_n;  // per tick, device frame (after blend and fade)
  std::vector<ToolState> tool;               // per tick, as the tick mapped it
  std::vector<double> fade_gain;                 // per tick
  std::vector<std::uint64_t> proxy_sequence;     // per tick: sequence of the proxy in use (0: none)
  std::vector<TimeNs> tick_time_ns;              // per tick: the loop's clock
  std::vector<ContactProxy> proxies;             // per host step: proxies[sequence − 1]
  std::vector<Eigen::Vector3d> host_force_n;     // per host step: host's force, device frame
  std::vector<std::size_t> host_tick;            // per host step: the tick whose pose it stepped to
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
  const host::ProxyBuilderModel parts_model = host::proxy_model_for(scene, host.simulation()).value();  // SessionHost checked it
  RtStack rt(model, device, clock);
  rt::RtLoop& loop = rt.loop();
  RtChannels& channels = rt.channels();
  const DeviceMapping& mapping = model.config.mapping;
  RunResult result;
  const std::size_t steps = ticks / static_cast<std::size_t>(ticks_per_host) + 1;
  result.contact_force_n.reserve(ticks);
  result.tool.reserve(ticks);
  result.fade_gain.reserve(ticks);
  result.proxy_sequence.reserve(ticks);
  result.tick_time_ns.reserve(ticks);
  result.proxies.reserve(steps);
  result.host_force_n.reserve(steps);
  result.host_tick.reserve(steps);
  result.host_step_ms.reserve(steps);
  rt::TelemetrySample sample;
  std::size_t done = 0;
  while (done < ticks) {
    for (int k = 0; k < ticks_per_host && done < ticks; ++k, ++done) loop.step();
    const double cpu_before = thread_cpu_s();
    const HostStatus& status = host.step(channels.state, channels.proxy);
    result.host_cpu_s += thread_cpu_s() - cpu_before;
    result.host_step_ms.push_back(status.step_cpu_s * 1e3);
    result.crossed_nodes_max = std::max(result.crossed_nodes_max, status.crossed_nodes);
    result.proxies.push_back(host.last_proxy());
    const host::HostStepResult& step = host.simulation().last();
    PartForces host_forces;
    for (int jaw = 0; jaw < step.part_count && jaw < parts_model.jaw_count; ++jaw) {
      const auto j = static_cast<std::size_t>(jaw);
      host_forces.force_world_n[static_cast<std::size_t>(parts_model.part_of_jaw[j])] += step.part_force_world_n[j];
    }
    result.host_force_n.push_back(part_forces_to_device(mapping, host_forces));
    result.host_tick.push_back(done - 1);
    while (channels.telemetry.try_pop(sample)) {
      result.contact_force_n.push_back(as_eigen(sample.contact_force_device_n));
      result.tool.push_back(device_to_tool(mapping, as_eigen(sample.position_device_m),
                                               as_eigen(sample.velocity_device_m_per_s)));
      result.fade_gain.push_back(sample.fade_gain);
      result.proxy_sequence.push_back(sample.proxy_sequence);
      result.tick_time_ns.push_back(sample.time_ns);
    }
  }
  result.simulated_s = static_cast<double>(ticks) * model.period_s;
  return result;
}

// The device-frame force rt_core's evaluation gives for `proxy` at `tool` (no blend, no fade).
Eigen::Vector3d raw_proxy_force(const ContactProxy& proxy, const DeviceMapping& mapping, const ToolState& tool) {
  PartForces forces;
  rt::evaluate_proxy(proxy, mapping, tool, forces);
  return part_forces_to_device(mapping, forces);
}

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

// RMS and peak of a stream of error vectors, as % of a reference force.
struct ErrorAccumulator {
  double sum_sq = 0.0;
  double peak = 0.0;
  std::size_t count = 0;
  void add(const Eigen::Vector3d& error) {
    const double e = error.norm();
    sum_sq += e * e;
    peak = std::max(peak, e);
    ++count;
  }
  [[nodiscard]] double rms_pct(double reference_n) const {
    return count > 0 && reference_n > 0.0 ? 100.0 * std::sqrt(sum_sq / static_cast<double>(count)) / reference_n : 0.0;
  }
  [[nodiscard]] double peak_pct(double reference_n) const { return reference_n > 0.0 ? 100.0 * peak / reference_n : 0.0; }
};

// Where a row's error comes from. Per tick j (F = rendered force, P = a proxy evaluated by rt_core's
// own evaluate_proxy at tick j's pose and velocity, fade applied, no blend):
//   F_row − F_oracle = (F_row − P_row)            blend: the swap blend's offset still walking out
//                    + (P_row − P_oracle,same)     divergence: the row's host built its proxy from a
//                                                  different soft-body state than the oracle's host
//                                                  did at the same tick (P_oracle,same = the oracle's
//                                                  proxy from the tick the row's host stepped at)
//                    + (P_oracle,same − F_oracle)  model: that proxy evaluated up to `per` ticks away
//                                                  from its reference pose vs the oracle's rendering
// exactly (the three add up to the total). Beside them:
//   host divergence  = |host force of the row's host step − oracle host force at the same tick|;
//   model vs host    = |P_oracle,same − oracle host force at tick j's pose| (the proxy's local model
//                      against the host's own force where the tool is now);
//   oracle vs host   = |F_oracle − oracle host force| (the oracle's own floor: a 1-tick-old proxy).
struct Decomposition {
  double blend_rms_pct = 0.0, blend_peak_pct = 0.0;
  double divergence_rms_pct = 0.0, divergence_peak_pct = 0.0;
  double model_rms_pct = 0.0, model_peak_pct = 0.0;
  double host_divergence_rms_pct = 0.0, host_divergence_peak_pct = 0.0;
  double model_vs_host_rms_pct = 0.0, model_vs_host_peak_pct = 0.0;
  double oracle_vs_host_rms_pct = 0.0;
  double max_dforce_unblended_n = 0.0;  // per-tick step of P_row (what the device would get without the blend)
  double max_dforce_swap_n = 0.0;       // rendered step on ticks where a new proxy was taken
  double max_dforce_between_n = 0.0;    // rendered step on the other ticks (tool motion)
  // The step the tool's own motion makes with the proxy held fixed: |P(pose j) − P(pose j−1)| for
  // the proxy in use at j (as rendered at j). This is the stiffness being rendered at the encoder's resolution; the
  // swap/blend cannot remove it.
  double max_dforce_motion_n = 0.0;
  // What is left of each rendered step once the motion step is taken out: the swap/blend's share.
  double max_dforce_swap_share_n = 0.0;
};

// rt_core's own proxy intake (take_latest_proxy: validation, ordering) replayed
// outside the loop, fed a chosen proxy on the ticks where `run` took a new one: gives, per tick,
// the proxy the tick evaluated (or would have, for the oracle's proxies on the row's schedule).
class ProxyReplay {
 public:
  ProxyReplay() : exchange_(std::make_unique<ProxyExchange>()), state_(std::make_unique<rt::ProxyState>()) {}
  const ContactProxy* at(const ContactProxy* incoming, TimeNs now_ns) {
    if (incoming != nullptr) exchange_->publish(*incoming);
    rt::take_latest_proxy(*exchange_, *state_, now_ns);
    return state_->have_proxy ? &rt::active_proxy(*state_) : nullptr;
  }

 private:
  std::unique_ptr<ProxyExchange> exchange_;
  std::unique_ptr<rt::ProxyState> state_;
};

// Per tick of `run`: its own proxy as rendered before the blend (fade applied), the oracle's
// proxy from the same host tick run through the same intake, and the motion step (the proxy in
// use at tick j evaluated at pose j minus at pose j−1).
struct ReplayedForces {
  std::vector<Eigen::Vector3d> unblended, oracle_same, motion;
};

ReplayedForces replay_proxies(const RunResult& run, const RunResult& oracle, const DeviceMapping& mapping) {
  ReplayedForces out;
  const std::size_t n = std::min(run.contact_force_n.size(), oracle.contact_force_n.size());
  out.unblended.assign(n, Eigen::Vector3d::Zero());
  out.oracle_same.assign(n, Eigen::Vector3d::Zero());
  out.motion.assign(n, Eigen::Vector3d::Zero());
  ProxyReplay own;
  ProxyReplay same;
  std::uint64_t last_sequence = 0;
  for (std::size_t j = 0; j < n; ++j) {
    const std::uint64_t sequence = run.proxy_sequence[j];
    const ContactProxy* own_in = nullptr;
    const ContactProxy* same_in = nullptr;
    if (sequence != last_sequence && sequence > 0 && sequence <= run.proxies.size()) {
      own_in = &run.proxies[sequence - 1];
      const std::size_t oracle_step = run.host_tick[sequence - 1];  // the oracle's host step after that tick
      if (oracle_step < oracle.proxies.size()) same_in = &oracle.proxies[oracle_step];
    }
    last_sequence = sequence;
    const ContactProxy* own_proxy = own.at(own_in, run.tick_time_ns[j]);
    const ContactProxy* same_proxy = same.at(same_in, run.tick_time_ns[j]);
    if (own_proxy != nullptr) {
      out.unblended[j] = run.fade_gain[j] * raw_proxy_force(*own_proxy, mapping, run.tool[j]);
      if (j > 0) out.motion[j] = out.unblended[j] - run.fade_gain[j] * raw_proxy_force(*own_proxy, mapping, run.tool[j - 1]);
    }
    if (same_proxy != nullptr) out.oracle_same[j] = run.fade_gain[j] * raw_proxy_force(*same_proxy, mapping, run.tool[j]);
  }
  return out;
}

Decomposition decompose(const RunResult& run, const RunResult& oracle, const DeviceMapping& mapping,
                        double peak_oracle_n) {
  ErrorAccumulator blend, divergence, model, host_divergence, model_vs_host, oracle_vs_host;
  Decomposition d;
  const ReplayedForces replayed = replay_proxies(run, oracle, mapping);
  const std::size_t n = replayed.unblended.size();
  for (std::size_t j = 0; j < n; ++j) {
    const Eigen::Vector3d& unblended = replayed.unblended[j];
    const Eigen::Vector3d& oracle_same = replayed.oracle_same[j];
    blend.add(run.contact_force_n[j] - unblended);
    divergence.add(unblended - oracle_same);
    model.add(oracle_same - oracle.contact_force_n[j]);
    // The oracle's host stepped to every tick's pose: host_force_n[j] is its force at tick j.
    if (j < oracle.host_force_n.size()) {
      model_vs_host.add(oracle_same - oracle.host_force_n[j]);
      oracle_vs_host.add(oracle.contact_force_n[j] - oracle.host_force_n[j]);
    }
    if (j > 0) {
      const Eigen::Vector3d step = run.contact_force_n[j] - run.contact_force_n[j - 1];
      d.max_dforce_motion_n = std::max(d.max_dforce_motion_n, replayed.motion[j].norm());
      d.max_dforce_swap_share_n = std::max(d.max_dforce_swap_share_n, (step - replayed.motion[j]).norm());
      d.max_dforce_unblended_n = std::max(d.max_dforce_unblended_n, (unblended - replayed.unblended[j - 1]).norm());
      if (run.proxy_sequence[j] != run.proxy_sequence[j - 1]) {
        d.max_dforce_swap_n = std::max(d.max_dforce_swap_n, step.norm());
      } else {
        d.max_dforce_between_n = std::max(d.max_dforce_between_n, step.norm());
      }
    }
  }
  for (std::size_t m = 0; m < run.host_force_n.size(); ++m) {
    const std::size_t tick = run.host_tick[m];
    if (tick < oracle.host_force_n.size()) host_divergence.add(run.host_force_n[m] - oracle.host_force_n[tick]);
  }
  d.blend_rms_pct = blend.rms_pct(peak_oracle_n);
  d.blend_peak_pct = blend.peak_pct(peak_oracle_n);
  d.divergence_rms_pct = divergence.rms_pct(peak_oracle_n);
  d.divergence_peak_pct = divergence.peak_pct(peak_oracle_n);
  d.model_rms_pct = model.rms_pct(peak_oracle_n);
  d.model_peak_pct = model.peak_pct(peak_oracle_n);
  d.host_divergence_rms_pct = host_divergence.rms_pct(peak_oracle_n);
  d.host_divergence_peak_pct = host_divergence.peak_pct(peak_oracle_n);
  d.model_vs_host_rms_pct = model_vs_host.rms_pct(peak_oracle_n);
  d.model_vs_host_peak_pct = model_vs_host.peak_pct(peak_oracle_n);
  d.oracle_vs_host_rms_pct = oracle_vs_host.rms_pct(peak_oracle_n);
  return d;
}

// Per-tick CSV of one row (diagnosis): rendered, unblended, oracle-same-tick proxy, oracle rendered,
// oracle host force (|F| of each, device frame) and the tool position.
void write_trace(const std::string& path, const RunResult& run, const RunResult& oracle, const DeviceMapping& mapping) {
  std::ofstream file(path);
  if (!file) throw EvalError("cannot write trace '" + path + "'");
  file << "tick,proxy_sequence,f_row_n,p_row_n,p_oracle_same_n,f_oracle_n,h_oracle_n,h_row_n,tool_x_m,tool_y_m,tool_z_m\n";
  const ReplayedForces replayed = replay_proxies(run, oracle, mapping);
  for (std::size_t j = 0; j < replayed.unblended.size(); ++j) {
    const std::uint64_t sequence = run.proxy_sequence[j];
    const Eigen::Vector3d& unblended = replayed.unblended[j];
    const Eigen::Vector3d& oracle_same = replayed.oracle_same[j];
    const double host = j < oracle.host_force_n.size() ? oracle.host_force_n[j].norm() : 0.0;
    const double row_host = sequence > 0 && sequence <= run.host_force_n.size() ? run.host_force_n[sequence - 1].norm() : 0.0;
    const Eigen::Vector3d& p = run.tool[j].p_tool_world_m;
    file << j << ',' << sequence << ',' << run.contact_force_n[j].norm() << ',' << unblended.norm() << ','
         << oracle_same.norm() << ',' << oracle.contact_force_n[j].norm() << ',' << host << ',' << row_host << ',' << p.x() << ','
         << p.y() << ',' << p.z() << '\n';
  }
}

nlohmann::json run_proxy_bench(const BenchProxyOptions& options) {
  host::SceneDescription base;
  try {
    base = host::load_scene(host::resolve_scene_path(options.scene));
  } catch (const std::exception& e) {
    throw EvalError(e.what());
  }
  // One collision sub-step per rt period for every row (see the file comment).
  host::SceneDescription scene_template = base;
  scene_template.simulation.time_step_s = 1.0 / options.rt_rate_hz;
  scene_template.simulation.substeps_count = 1;
  rt::RtConfig config;
  config.rate_hz = options.rt_rate_hz;
  config.mapping = base.device_mapping;
  const rt::RtModel model = build_rt_model(config);
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
      throw EvalError("host rate " + std::to_string(host_hz) + " Hz does not divide the rt rate " +
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
  const double force_position_lag_s = rt::force_position_lag_s(1.0 / options.rt_rate_hz);
  std::printf("force position (sub-count, every row): previous reading's weight %.3g, added lag %.3g us at %.0f Hz\n",
              rt::kForcePositionPreviousWeight, force_position_lag_s * 1e6, options.rt_rate_hz);
  std::printf("%8s %14s %15s %13s %17s %12s %12s | %9s %9s %9s %9s %9s | %9s %9s %9s %9s %9s\n", "host_hz", "rms_error_pct",
              "peak_error_pct", "max_dforce_n", "host_cpu_s_per_s", "step_ms_med", "step_ms_p99", "blend%", "diverge%",
              "model%", "host_div%", "mdl_v_hst%", "dF_swap", "dF_betw", "dF_unbl", "dF_motion", "dF_blend");
  nlohmann::json rows = nlohmann::json::array();
  const DeviceMapping& mapping = model.config.mapping;
  const auto add_row = [&](double host_hz, RunResult& run) {
    const ErrorFigures e = compare(run.contact_force_n, oracle.contact_force_n);
    const Decomposition d = decompose(run, oracle, mapping, peak_oracle);
    const Quantiles q = quantiles(run.host_step_ms);
    const double cpu_per_s = run.host_cpu_s / run.simulated_s;
    std::printf("%8.0f %14.3f %15.3f %13.4f %17.3f %12.3f %12.3f | %9.3f %9.3f %9.3f %9.3f %9.3f | %9.4f %9.4f %9.4f %9.4f %9.4f\n",
                host_hz, e.rms_pct, e.peak_pct, e.max_dforce_n, cpu_per_s, q.median, q.p99, d.blend_rms_pct,
                d.divergence_rms_pct, d.model_rms_pct, d.host_divergence_rms_pct, d.model_vs_host_rms_pct,
                d.max_dforce_swap_n, d.max_dforce_between_n, d.max_dforce_unblended_n, d.max_dforce_motion_n,
                d.max_dforce_swap_share_n);
    rows.push_back({{"host_hz", host_hz},
                    {"rms_error_pct", e.rms_pct},
                    {"peak_error_pct", e.peak_pct},
                    {"max_dforce_n", e.max_dforce_n},
                    {"host_cpu_s_per_s", cpu_per_s},
                    {"host_step_ms", {{"median", q.median}, {"p99", q.p99}, {"max", q.max}, {"samples", run.host_step_ms.size()}}},
                    {"crossed_nodes_max", run.crossed_nodes_max},
                    {"decomposition",
                     {{"blend_rms_pct", d.blend_rms_pct},
                      {"blend_peak_pct", d.blend_peak_pct},
                      {"divergence_rms_pct", d.divergence_rms_pct},
                      {"divergence_peak_pct", d.divergence_peak_pct},
                      {"model_rms_pct", d.model_rms_pct},
                      {"model_peak_pct", d.model_peak_pct},
                      {"host_divergence_rms_pct", d.host_divergence_rms_pct},
                      {"host_divergence_peak_pct", d.host_divergence_peak_pct},
                      {"model_vs_host_rms_pct", d.model_vs_host_rms_pct},
                      {"model_vs_host_peak_pct", d.model_vs_host_peak_pct},
                      {"max_dforce_swap_n", d.max_dforce_swap_n},
                      {"max_dforce_between_swaps_n", d.max_dforce_between_n},
                      {"max_dforce_unblended_n", d.max_dforce_unblended_n},
                      {"max_dforce_motion_n", d.max_dforce_motion_n},
                      {"max_dforce_swap_share_n", d.max_dforce_swap_share_n}}}});
  };
  const Decomposition oracle_terms = decompose(oracle, oracle, mapping, peak_oracle);
  const double oracle_max_dforce_n = compare(oracle.contact_force_n, oracle.contact_force_n).max_dforce_n;
  {
    std::vector<double> oracle_steps_ms = oracle.host_step_ms;
    const Quantiles q = quantiles(oracle_steps_ms);
    std::printf("%8.0f %14.3f %15.3f %13.4f %17.3f %12.3f %12.3f | %9s %9s %9s %9s %9.3f %11s | %9.4f %9.4f %9.4f %9.4f %9.4f  (oracle)\n",
                options.rt_rate_hz, 0.0, 0.0, oracle_max_dforce_n, oracle.host_cpu_s / oracle.simulated_s, q.median,
                q.p99, "-", "-", "-", "-", oracle_terms.oracle_vs_host_rms_pct, "-", oracle_terms.max_dforce_swap_n,
                oracle_terms.max_dforce_between_n, oracle_terms.max_dforce_unblended_n, oracle_terms.max_dforce_motion_n,
                oracle_terms.max_dforce_swap_share_n);
  }
  for (const double host_hz : options.host_rates_hz) {
    RunResult run = replay_at(host_hz);
    add_row(host_hz, run);
    if (!options.trace_dir.empty()) {
      write_trace(options.trace_dir + "/proxy_trace_" + std::to_string(std::lround(host_hz)) + "hz.csv", run, oracle,
                  mapping);
    }
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
                   {"replay_peak_error_pct", self_error.peak_pct},
                   {"max_dforce_n", oracle_max_dforce_n},
                   {"rendered_vs_host_rms_pct", oracle_terms.oracle_vs_host_rms_pct}};
  out["decomposition_legend"] = {
      {"blend", "rendered force - the row's own proxy evaluated at the tick (no blend): the swap blend's offset"},
      {"divergence", "row's proxy - the oracle's proxy built at the same host tick, both at the tick's pose: the two hosts' soft bodies differ"},
      {"model", "oracle's proxy from the row's host tick, evaluated up to one host period later - oracle's rendered force"},
      {"host_divergence", "row host force at its steps - oracle host force at the same tick"},
      {"model_vs_host", "oracle's proxy from the row's host tick at the tick's pose - oracle host's own force at that pose"},
      {"note", "blend + divergence + model = rendered - oracle exactly (per tick, as vectors); all % of the oracle's peak |F|"}};
  out["force_position"] = {{"previous_weight", rt::kForcePositionPreviousWeight},
                           {"added_lag_s", force_position_lag_s},
                           {"note", "the contact is evaluated at p_k - w*(p_k - p_{k-1}): a constant velocity lags by w*T"}};
  out["targets"] = {{"rms_error_pct_at_100_hz", 2.0}, {"rms_error_pct_at_1000_hz", 0.5}, {"max_dforce_n", 0.05}};
  out["rows"] = rows;
  out["machine"] = machine_info();
  return out;
}

}  // namespace

nlohmann::json run_bench_proxy(const BenchProxyOptions& options) { return run_proxy_bench(options); }

}  // namespace fissure::eval
