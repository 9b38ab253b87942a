// `fissure bench rt --json FILE [--seconds N]`: rt_core measured three ways.
//
// 1. Tick compute time: rt::tick() alone, in a tight loop, for proxies of 1 and 8 patches
//    (every patch in contact, n = 1.5, λ > 0; a new proxy every 10 ticks so swap blending is
//    exercised). The device is a replay of encoder counts computed through the real IK from a
//    0.2 m/s circular hand motion sampled at 1 kHz, so FK warm starts see real motion and
//    try_exchange costs a few ns. Each tick is timed on its own with steady_clock; the cost of
//    the clock pair is measured the same way and reported (not subtracted).
// 2. A real SCHED_FIFO run against SimFalcon on the MonotonicClock at 1 kHz and 4 kHz for N
//    seconds each: RtLoop::run_until on a thread set up by RtThreadSetup (priority 80,
//    mlockall, stack pre-fault, /dev/cpu_dma_latency = 0, pinned to CPU 0), a normal-priority
//    host thread publishing a wall proxy at 100 Hz and draining telemetry. cyclictest (Debian
//    rt-tests) runs concurrently on CPU 1 with the same priority, interval and duration
//    (back to back on the same CPU when there is only one). Wake-up latency = woke − deadline,
//    1 µs histogram bins for both (cyclictest's -h), quantiles truncated to whole µs the way
//    cyclictest reports them; ours also has the exact max.
// 3. Z-width (lockstep, deterministic): for 500 Hz … 10 kHz, the largest stiffness K of an
//    undamped wall (λ = 0, n = 1) that a press-hold-release against SimFalcon (its nominal
//    damping b, a hand with no damping of its own) renders stably and passively, on a ×1.25
//    grid, with the passivity controller off and on; beside the Colgate–Schenkel bound
//    K < 2b/T. Stable: peak-to-peak position over the last 0.3 s of the hold ≤ 0.25 mm (5
//    encoder counts). Passive: Σ F_motor·Δp − Σ b·|v|²·T ≤ 0 over the run, the damper counted
//    only while the wall pushes (virtual wall plus the device's physical damper, the port
//    Colgate & Schenkel's bound is about), from SimFalcon's ground truth. Renders: the wall's
//    mean force over the hold window is ≥ 90 % of its equilibrium force against the hand spring
//    (a wall held back to nothing is passive and still, and not a wall).
// 4. Resting hand (lockstep, deterministic, 1 kHz, passivity controller on): the hand target
//    moves at 0.5 m/s from 6 mm above a 3000 N/m wall to 8 mm past it and rests there (SimFalcon
//    nominal, the default hand). Reported: the time from first contact until the commanded force
//    is ≥ 90 % of the wall's force at the current penetration (the proxy's HC force) and stays
//    so to the end of the 1 s rest, and the lowest commanded/wall ratio from 100 ms after contact.
#include "fissure/eval/bench_rt.hpp"
#include "fissure/eval/eval_error.hpp"
#include "fissure/session/machine_info.hpp"

#include <sys/utsname.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <functional>
#include <fstream>
#include <memory>
#include <numbers>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <spdlog/spdlog.h>

#include "fissure/falcon_hw/encoder_mapping.hpp"
#include "fissure/falcon_hw/kinematics.hpp"
#include "fissure/falcon_hw/sim_falcon.hpp"
#include "fissure/rt_core/faults.hpp"
#include "fissure/rt_core/rt_loop.hpp"
#include "fissure/rt_core/rt_thread.hpp"
#include "fissure/rt_core/tick.hpp"
#include "fissure/shared/clock.hpp"
#include "fissure/session/rt_stack.hpp"

namespace fissure::eval {
using namespace fissure::session;  // the session library: SessionHost, run_session, LinkBridge, …
namespace {

using rt::RtConfig;
using rt::RtModel;

const Eigen::Vector3d kCentre_device_m(falcon::kWorkspaceCentre_device_m[0], falcon::kWorkspaceCentre_device_m[1],
                                       falcon::kWorkspaceCentre_device_m[2]);
/// Ticks timed per patch count (≈ 0.2–0.5 s each at ~1 µs).
constexpr int kTimedTicks = 300'000;
constexpr int kWarmupTicks = 20'000;
/// The replayed hand: a 2 cm circle at 0.2 m/s, sampled at 1 kHz.
constexpr double kCircleRadius_m = 0.02;
constexpr double kCircleSpeed_m_per_s = 0.2;
/// Z-width grid and criteria (file comment).
constexpr double kZwidthFirstK_n_per_m = 250.0;
constexpr double kZwidthGridRatio = 1.25;
constexpr double kZwidthMaxK_n_per_m = 400'000.0;
constexpr double kStablePeakToPeak_m = 0.25e-3;
/// The resting-hand wall [N/m]: the Falcon's rated stiffness (CHAI3D, BRIEF §5), issue 26's case.
constexpr double kFalconRestingWall_n_per_m = 3000.0;
/// A wall "renders" when its mean force over the hold window is at least this share of the
/// equilibrium force it should hold the hand with. Without it a passivity controller that holds
/// the wall back to 0 N counts as stable and passive, and the Z-width reports stiffnesses that
/// are not rendered at all. 90 %: issue 26's criterion (a rendered wall sits within a few % of
/// the equilibrium).
constexpr double kMinHeldForceShare = 0.9;

double quantile_sorted(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return 0.0;
  const auto index = static_cast<std::size_t>(std::ceil(q * static_cast<double>(sorted.size()))) - 1;
  return sorted[std::min(index, sorted.size() - 1)];
}

nlohmann::json distribution(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return {{"median", quantile_sorted(values, 0.5)},
          {"p99", quantile_sorted(values, 0.99)},
          {"p999", quantile_sorted(values, 0.999)},
          {"max", values.empty() ? 0.0 : values.back()},
          {"samples", values.size()}};
}

// ---------------------------------------------------------------- 1. tick compute time

/// Replays precomputed encoder counts: try_exchange costs a copy.
class ReplayDevice final : public falcon::HapticDevice {
 public:
  explicit ReplayDevice(std::vector<std::array<std::int16_t, 3>> counts) : counts_(std::move(counts)) {}
  [[nodiscard]] const char* name() const noexcept override { return "replay"; }
  falcon::IoStatus try_exchange(const falcon::DeviceCommand&, falcon::DeviceReading& reading) noexcept override {
    reading.encoder_counts = counts_[next_];
    reading.homed_mask = 0x7;
    next_ = next_ + 1 == counts_.size() ? 0 : next_ + 1;
    return falcon::IoStatus::kOk;
  }

 private:
  std::vector<std::array<std::int16_t, 3>> counts_;
  std::size_t next_ = 0;
};

std::vector<std::array<std::int16_t, 3>> circle_counts() {
  const double period_s = 1e-3;
  const double circumference_m = 2.0 * std::numbers::pi * kCircleRadius_m;
  const auto samples = static_cast<std::size_t>(circumference_m / kCircleSpeed_m_per_s / period_s);
  std::vector<std::array<std::int16_t, 3>> counts;
  counts.reserve(samples);
  const falcon::FalconGeometry geometry;
  const falcon::EncoderMapping encoder;
  for (std::size_t i = 0; i < samples; ++i) {
    const double angle = 2.0 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(samples);
    const Eigen::Vector3d p = kCentre_device_m + kCircleRadius_m * Eigen::Vector3d(std::cos(angle), std::sin(angle), 0.0);
    Eigen::Vector3d theta;
    if (!falcon::inverse_kinematics(geometry, p, theta)) throw EvalError("bench rt: replay circle leaves the workspace");
    counts.push_back(falcon::theta_to_encoders(encoder, theta));
  }
  return counts;
}

/// `patches` planes, all in contact for every point of the circle (3 cm beyond the centre
/// along their normals, so the penetration stays between 1 and 5 cm), normals spread
/// over the sphere; k small enough that the sum stays inside the 8 N clamp.
ContactProxy contact_proxy(int patches, std::uint64_t sequence) {
  ContactProxy proxy;
  proxy.sequence = sequence;
  proxy.flags = kProxyValid | kProxyHostInContact;
  proxy.patch_count = static_cast<std::uint16_t>(patches);
  for (int i = 0; i < patches; ++i) {
    // Fibonacci sphere directions.
    const double z = 1.0 - (2.0 * i + 1.0) / (2.0 * patches);
    const double r = std::sqrt(1.0 - z * z);
    const double phi = i * std::numbers::pi * (3.0 - std::sqrt(5.0));
    const Eigen::Vector3d n(r * std::cos(phi), r * std::sin(phi), z);
    ContactPatch& patch = proxy.patches[static_cast<std::size_t>(i)];
    patch.normal_world = to_vec3(n);
    patch.plane_point_world_m = to_vec3(kCentre_device_m + 0.03 * n + Eigen::Vector3d(0, 0, 1e-6 * (sequence % 7)));
    patch.stiffness_k = 60.0;
    patch.damping_lambda = 30.0;
    patch.exponent_n = 1.5;
  }
  return proxy;
}

struct TickTiming {
  std::vector<double> tick_ns;
  double clock_pair_median_ns = 0.0;
  std::uint64_t faults = 0;
  double max_force_n = 0.0;
};

TickTiming time_ticks(int patches) {
  RtModel model;
  if (!rt::build_model(RtConfig{}, model)) throw EvalError("bench rt: default RtConfig does not build");
  ReplayDevice device(circle_counts());
  auto proxy_in = std::make_unique<ProxyExchange>();
  auto state_out = std::make_unique<DeviceStateExchange>();
  auto telemetry = std::make_unique<rt::TelemetryRing>();
  auto data = std::make_unique<rt::RtData>();
  rt::reset_data(model, *data);
  rt::TickIo io{device, *proxy_in, *state_out, *telemetry};
  TickTiming result;
  result.tick_ns.reserve(kTimedTicks);
  rt::TelemetrySample sample;
  rt::TickTiming timing;
  using Clock = std::chrono::steady_clock;
  for (int k = 0; k < kWarmupTicks + kTimedTicks; ++k) {
    if (k % 10 == 0) proxy_in->publish(contact_proxy(patches, static_cast<std::uint64_t>(k / 10 + 1)));
    timing.now_ns += model.period_ns;
    const auto start = Clock::now();
    const rt::TickResult tick_result = rt::tick(model, *data, io, timing);
    const auto stop = Clock::now();
    while (telemetry->try_pop(sample)) {
    }
    if (k < kWarmupTicks) continue;
    result.tick_ns.push_back(static_cast<double>(std::chrono::duration_cast<std::chrono::nanoseconds>(stop - start).count()));
    if ((tick_result.fault_bits & rt::kAnyFault) != 0u) ++result.faults;
    result.max_force_n = std::max(result.max_force_n, tick_result.force_device_n.norm());
  }
  std::vector<double> pair_ns;
  pair_ns.reserve(100'000);
  for (int k = 0; k < 100'000; ++k) {
    const auto start = Clock::now();
    const auto stop = Clock::now();
    pair_ns.push_back(static_cast<double>(std::chrono::duration_cast<std::chrono::nanoseconds>(stop - start).count()));
  }
  std::sort(pair_ns.begin(), pair_ns.end());
  result.clock_pair_median_ns = quantile_sorted(pair_ns, 0.5);
  return result;
}

/// The machine's own noise: a fixed arithmetic workload of about a tick's length timed the
/// same way, on the same thread. Its tail is preemption, interrupts and hypervisor steal —
/// what the tick's tail contains on top of the tick itself.
std::vector<double> time_reference_workload(int samples) {
  using Clock = std::chrono::steady_clock;
  std::vector<double> ns;
  ns.reserve(static_cast<std::size_t>(samples));
  volatile double sink = 0.0;
  for (int k = 0; k < samples; ++k) {
    const auto start = Clock::now();
    double x = 1.0 + 1e-9 * k;
    for (int i = 0; i < 400; ++i) x = x * 1.0000001 + 1e-12;  // dependent chain: not vectorisable
    sink = sink + x;
    const auto stop = Clock::now();
    ns.push_back(static_cast<double>(std::chrono::duration_cast<std::chrono::nanoseconds>(stop - start).count()));
  }
  return ns;
}

// ---------------------------------------------------------------- 2. SCHED_FIFO vs cyclictest

struct CyclictestResult {
  bool available = false;
  std::string reason;
  std::string command;
  std::vector<std::uint64_t> histogram_us;
  std::uint64_t overflows = 0;
  double max_us = 0.0;
  std::uint64_t samples = 0;
  [[nodiscard]] double quantile_us(double q) const {
    if (samples == 0) return 0.0;
    const auto rank = static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(samples)));
    std::uint64_t seen = 0;
    for (std::size_t i = 0; i < histogram_us.size(); ++i) {
      seen += histogram_us[i];
      if (seen >= rank) return static_cast<double>(i);
    }
    return max_us;
  }
};

std::string find_cyclictest() {
  for (const char* dir : {"/usr/bin", "/usr/sbin", "/usr/local/bin", "/bin", "/sbin"}) {
    const std::string path = std::string(dir) + "/cyclictest";
    if (access(path.c_str(), X_OK) == 0) return path;
  }
  return {};
}

CyclictestResult run_cyclictest(const std::string& binary, int priority, int interval_us, double seconds, int cpu) {
  CyclictestResult result;
  if (binary.empty()) {
    result.reason = "cyclictest not found (install Debian package rt-tests)";
    return result;
  }
  std::ostringstream command;
  command << binary << " -m -q -p " << priority << " -i " << interval_us << " -D " << static_cast<int>(std::ceil(seconds))
          << "s -h " << rt::kLatencyHistogramBins;
  if (cpu >= 0) command << " -a " << cpu;
  command << " 2>&1";
  result.command = command.str();
  FILE* pipe = popen(result.command.c_str(), "r");
  if (pipe == nullptr) {
    result.reason = "could not start: " + result.command;
    return result;
  }
  result.histogram_us.assign(rt::kLatencyHistogramBins, 0);
  char line[512];
  std::string errors;
  while (std::fgets(line, sizeof line, pipe) != nullptr) {
    unsigned long bin = 0, count = 0;
    if (line[0] != '#' && std::sscanf(line, "%lu %lu", &bin, &count) == 2) {
      if (bin < result.histogram_us.size()) result.histogram_us[bin] += count;
      result.samples += count;
    } else if (std::sscanf(line, "# Max Latencies: %lu", &count) == 1) {
      result.max_us = static_cast<double>(count);
    } else if (std::sscanf(line, "# Histogram Overflows: %lu", &count) == 1) {
      result.overflows = count;
      result.samples += count;
    } else if (line[0] != '#') {
      errors += line;
    }
  }
  const int status = pclose(pipe);
  if (status != 0 || result.samples == 0) {
    result.reason = "cyclictest failed (status " + std::to_string(status) + "): " + errors.substr(0, 300);
    return result;
  }
  result.available = true;
  return result;
}

struct RtRunResult {
  rt::RtSetupReport setup{};
  std::unique_ptr<rt::LoopStats> stats = std::make_unique<rt::LoopStats>();
  std::uint64_t fault_ticks = 0;
  std::uint64_t telemetry_dropped = 0;
  double max_force_n = 0.0;
  std::uint64_t telemetry_samples = 0;
};

HandScript cyclic_press(double seconds) {
  HandScript hand;
  hand.start_position_device_m = to_vec3(kCentre_device_m);
  const Eigen::Vector3d down = kCentre_device_m + Eigen::Vector3d(0.0, -0.012, 0.0);
  for (double t = 0.0; t < seconds + 1.0; t += 1.0) {
    hand.waypoints.push_back({to_vec3(down), 0.05, 0.3});
    hand.waypoints.push_back({to_vec3(kCentre_device_m), 0.05, 0.22});
  }
  return hand;
}

RtRunResult run_sched_fifo(double rate_hz, double seconds, const rt::RtThreadConfig& thread_config) {
  RtConfig config;
  config.rate_hz = rate_hz;
  const RtModel model = build_rt_model(config);
  MonotonicClock clock;
  falcon::SimFalconConfig sim_config;
  sim_config.hand = cyclic_press(seconds);
  falcon::SimFalcon sim(sim_config, clock);
  RtStack rt(model, sim, clock);
  rt::RtLoop& loop = rt.loop();
  RtChannels& channels = rt.channels();

  RtRunResult result;
  std::atomic<bool> stop{false};
  RtThread rt_thread(thread_config, [&] {
    const TimeNs end_ns = clock.now() + from_seconds(seconds);
    loop.run_until(end_ns, stop);
  });
  // The host: a 100 Hz wall proxy and the telemetry consumer (normal priority).
  std::thread host([&] {
    std::uint64_t sequence = 0;
    rt::TelemetrySample sample;
    while (!rt_thread.done()) {
      ContactProxy proxy;
      proxy.sequence = ++sequence;
      proxy.flags = kProxyValid;
      proxy.patch_count = 1;
      proxy.patches[0].plane_point_world_m = to_vec3(kCentre_device_m + Eigen::Vector3d(0.0, -0.004, 0.0));
      proxy.patches[0].normal_world = {0.0, 1.0, 0.0};
      proxy.patches[0].stiffness_k = 1000.0;
      proxy.patches[0].damping_lambda = 200.0;
      channels.proxy.publish(proxy);
      while (channels.telemetry.try_pop(sample)) {
        ++result.telemetry_samples;
        result.max_force_n = std::max(result.max_force_n, as_eigen(sample.force_device_n).norm());
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  });
  rt_thread.join();
  host.join();
  result.setup = rt_thread.setup_report();
  if (!result.setup.ok) throw EvalError(std::string("bench rt: real-time setup refused: ") + result.setup.message);
  *result.stats = loop.stats();
  result.fault_ticks = loop.data().faults.fault_ticks;
  result.telemetry_dropped = loop.data().telemetry_dropped;
  return result;
}

nlohmann::json wakeup_json(const RtRunResult& run) {
  const rt::LatencyHistogram& h = run.stats->wakeup;
  return {{"median", h.quantile_us(0.5)},
          {"p99", h.quantile_us(0.99)},
          {"p999", h.quantile_us(0.999)},
          {"max", h.quantile_us(1.0)},
          {"overruns", run.stats->overruns},
          {"ticks", run.stats->ticks},
          {"max_tick_us", static_cast<double>(run.stats->max_tick_ns) * 1e-3},
          {"device_fault_ticks", run.fault_ticks},
          {"telemetry_dropped", run.telemetry_dropped},
          {"max_force_n", run.max_force_n},
          {"sched_fifo", run.setup.sched_fifo},
          {"memory_locked", run.setup.memory_locked},
          {"affinity_set", run.setup.affinity_set},
          {"dma_latency_held", run.setup.dma_latency_held},
          {"setup_warnings", run.setup.message}};
}

nlohmann::json cyclictest_json(const CyclictestResult& c) {
  if (!c.available) return {{"available", false}, {"reason", c.reason}, {"command", c.command}};
  return {{"available", true},     {"median", c.quantile_us(0.5)}, {"p99", c.quantile_us(0.99)},
          {"p999", c.quantile_us(0.999)}, {"max", c.max_us},            {"samples", c.samples},
          {"overflows", c.overflows}, {"command", c.command},
          {"overruns", nullptr}};  // cyclictest does not count missed periods
}

// ---------------------------------------------------------------- 3. Z-width

struct WallRun {
  bool stable = false;
  bool passive = false;
  bool renders = false;          ///< the wall holds the hand back with at least kMinHeldForceShare of its force
  double peak_to_peak_m = 0.0;
  double port_energy_j = 0.0;    ///< Σ F_motor·Δp − Σ b|v|²T
  double held_force_n = 0.0;     ///< mean motor force along the wall normal over the hold window
  double expected_force_n = 0.0; ///< the wall's force at the hand–wall equilibrium
};

WallRun run_wall(double rate_hz, double stiffness, bool passivity_on) {
  RtConfig config;
  config.rate_hz = rate_hz;
  config.passivity.enabled = passivity_on;
  const RtModel model = build_rt_model(config);
  LockstepClock clock;
  falcon::SimFalconConfig sim_config;
  HandScript hand;
  hand.start_position_device_m = to_vec3(kCentre_device_m);
  hand.grip_damping_n_s_per_m = 0.0;  // only the device's b counts against the bound
  const Eigen::Vector3d inside = kCentre_device_m + Eigen::Vector3d(0.0, -0.012, 0.0);
  hand.waypoints.push_back({to_vec3(kCentre_device_m), 0.05, 0.6});  // wait out the ramp-in
  hand.waypoints.push_back({to_vec3(inside), 0.1, 0.8});
  hand.waypoints.push_back({to_vec3(kCentre_device_m), 0.1, 0.1});
  hand.release_at_end = true;
  sim_config.hand = hand;
  const double b = sim_config.dynamics.viscous_damping_n_s_per_m;
  falcon::SimFalcon sim(sim_config, clock);
  RtStack rt(model, sim, clock);
  rt::RtLoop& loop = rt.loop();
  RtChannels& channels = rt.channels();

  // The hand spring pulls towards 12 mm inside the centre, the wall surface is 4 mm inside: at
  // equilibrium K·x = k_grip·(8 mm − x), so the wall should hold F = K·k_grip·8 mm / (K + k_grip)
  // (→ 2.4 N for a stiff wall), capped by safety's force limit.
  const double hand_past_wall_m = 0.012 - 0.004;
  const double k_grip = hand.grip_stiffness_n_per_m;
  const double hold_start_s = 0.6 + 0.012 / 0.1;
  const double window_start_s = hold_start_s + 0.8 - 0.3;
  const double window_end_s = hold_start_s + 0.8;
  const auto ticks = static_cast<int>((window_end_s + 0.12 + 0.2) * rate_hz);
  const auto publish_every = std::max(1, static_cast<int>(rate_hz / 1000.0));  // a 1 kHz host
  WallRun run;
  run.expected_force_n = std::min(config.safety.max_force_n, stiffness * k_grip * hand_past_wall_m / (stiffness + k_grip));
  double held_force_sum_n = 0.0;
  long held_samples = 0;
  double y_min = 1e9, y_max = -1e9;
  double motor_work_j = 0.0, damper_work_j = 0.0;
  Eigen::Vector3d p_prev = sim.truth().position_device_m;
  rt::TelemetrySample sample;
  for (int k = 0; k < ticks; ++k) {
    if (k % publish_every == 0) {
      ContactProxy proxy;
      proxy.sequence = static_cast<std::uint64_t>(k + 1);
      proxy.flags = kProxyValid;
      proxy.patch_count = 1;
      proxy.patches[0].plane_point_world_m = to_vec3(kCentre_device_m + Eigen::Vector3d(0.0, -0.004, 0.0));
      proxy.patches[0].normal_world = {0.0, 1.0, 0.0};
      proxy.patches[0].stiffness_k = stiffness;
      channels.proxy.publish(proxy);
    }
    loop.step();
    while (channels.telemetry.try_pop(sample)) {
    }
    const falcon::SimFalconTruth& truth = sim.truth();
    motor_work_j += truth.motor_force_device_n.dot(truth.position_device_m - p_prev);
    // The device's damper is credited only while the wall pushes: the port Colgate &
    // Schenkel's bound is about is the wall plus that damper, not the free approach.
    if (!truth.motor_force_device_n.isZero(0.0)) {
      damper_work_j += b * truth.velocity_device_m_per_s.squaredNorm() * model.period_s;
    }
    p_prev = truth.position_device_m;
    const double t = to_seconds(clock.now());
    if (t >= window_start_s && t <= window_end_s) {
      y_min = std::min(y_min, truth.position_device_m.y());
      y_max = std::max(y_max, truth.position_device_m.y());
      held_force_sum_n += truth.motor_force_device_n.y();
      ++held_samples;
    }
  }
  run.peak_to_peak_m = y_max - y_min;
  run.port_energy_j = motor_work_j - damper_work_j;
  run.stable = run.peak_to_peak_m <= kStablePeakToPeak_m;
  run.passive = run.port_energy_j <= 0.0;
  run.held_force_n = held_samples > 0 ? held_force_sum_n / static_cast<double>(held_samples) : 0.0;
  run.renders = run.held_force_n >= kMinHeldForceShare * run.expected_force_n;
  return run;
}

/// What ended a Z-width column: the criteria the first failing grid point missed.
std::string failure_text(const WallRun& run) {
  std::string text;
  if (!run.stable) text += "unstable";
  if (!run.passive) text += text.empty() ? "active" : "+active";
  if (!run.renders) text += text.empty() ? "held back" : "+held back";
  return text.empty() ? "grid top" : text;
}

/// Largest K on the grid before the first unstable, active or held-back one.
double zwidth_k(double rate_hz, bool passivity_on, WallRun& first_failure) {
  double last_good = 0.0;
  for (double k = kZwidthFirstK_n_per_m; k <= kZwidthMaxK_n_per_m; k *= kZwidthGridRatio) {
    const WallRun run = run_wall(rate_hz, k, passivity_on);
    if (!run.stable || !run.passive || !run.renders) {
      first_failure = run;
      return last_good;
    }
    last_good = k;
  }
  return last_good;
}

// ---------------------------------------------------------------- 4. resting hand

struct RestingHandRun {
  double contact_s = -1.0;           ///< first tick with the wall in contact
  double rendered_after_s = -1.0;    ///< from contact until ≥ 90 % from then to the end (−1: never)
  double min_ratio_after_100ms = 0.0;  ///< lowest commanded/wall force from contact + 100 ms on
  double wall_force_end_n = 0.0;
  double commanded_force_end_n = 0.0;
  double max_energy_j = 0.0;
};

RestingHandRun run_resting_hand(double stiffness_n_per_m, bool passivity_on) {
  RtConfig config;
  config.rate_hz = 1000.0;
  config.passivity.enabled = passivity_on;
  const RtModel model = build_rt_model(config);
  LockstepClock clock;
  falcon::SimFalconConfig sim_config;
  HandScript hand;
  hand.start_position_device_m = to_vec3(kCentre_device_m + Eigen::Vector3d(0.0, 0.006, 0.0));
  const double wall_y_m = kCentre_device_m.y();
  hand.waypoints.push_back({hand.start_position_device_m, 0.05, 0.6});  // wait out the ramp-in
  hand.waypoints.push_back({to_vec3(kCentre_device_m + Eigen::Vector3d(0.0, -0.008, 0.0)), 0.5, 1.2});
  hand.release_at_end = false;
  sim_config.hand = hand;
  falcon::SimFalcon sim(sim_config, clock);
  RtStack rt(model, sim, clock);
  rt::RtLoop& loop = rt.loop();
  RtChannels& channels = rt.channels();
  const int ticks = static_cast<int>(1.6 * config.rate_hz);
  RestingHandRun run;
  double last_below_s = -1.0;
  rt::TelemetrySample sample;
  for (int k = 0; k < ticks; ++k) {
    ContactProxy proxy;
    proxy.sequence = static_cast<std::uint64_t>(k + 1);
    proxy.flags = kProxyValid;
    proxy.patch_count = 1;
    proxy.patches[0].plane_point_world_m = to_vec3(kCentre_device_m);
    proxy.patches[0].normal_world = {0.0, 1.0, 0.0};
    proxy.patches[0].stiffness_k = stiffness_n_per_m;
    channels.proxy.publish(proxy);
    loop.step();
    while (channels.telemetry.try_pop(sample)) {
      const double t_s = to_seconds(sample.time_ns);
      const double wall_n = sample.contact_force_device_n[1];
      const double commanded_n = sample.force_device_n[1];
      run.max_energy_j = std::max(run.max_energy_j, sample.energy_j);
      if (run.contact_s < 0.0 && sample.position_device_m[1] < wall_y_m) run.contact_s = t_s;
      if (run.contact_s < 0.0) continue;
      const double ratio = wall_n > 0.0 ? commanded_n / wall_n : 1.0;
      if (ratio < 0.9) last_below_s = t_s;
      if (t_s >= run.contact_s + 0.1) {
        run.min_ratio_after_100ms = run.min_ratio_after_100ms == 0.0 ? ratio : std::min(run.min_ratio_after_100ms, ratio);
      }
      run.wall_force_end_n = wall_n;
      run.commanded_force_end_n = commanded_n;
    }
  }
  if (run.contact_s >= 0.0) run.rendered_after_s = std::max(0.0, last_below_s - run.contact_s);
  return run;
}

// 4. The resting hand after an impact, controller on and off, into `out`.
void measure_resting_hand(nlohmann::json& out) {
  std::printf("\n4. Resting hand (lockstep, 1 kHz): 0.5 m/s onto a 3000 N/m wall, then 1 s at rest 8 mm past it\n");
  std::printf("   %-8s %12s %22s %14s %14s %12s\n", "PC", "contact [s]", ">=90% from contact +", "min ratio>100ms",
              "wall F end", "cmd F end");
  nlohmann::json rows = nlohmann::json::array();
  for (const bool on : {true, false}) {
    const RestingHandRun r = run_resting_hand(kFalconRestingWall_n_per_m, on);
    std::printf("   %-8s %12.3f %20.1f ms %14.3f %12.3f N %10.3f N\n", on ? "on" : "off", r.contact_s,
                1e3 * r.rendered_after_s, r.min_ratio_after_100ms, r.wall_force_end_n, r.commanded_force_end_n);
    rows.push_back({{"passivity", on},
                    {"contact_s", r.contact_s},
                    {"rendered_90pct_after_contact_s", r.rendered_after_s},
                    {"min_commanded_over_wall_after_100ms", r.min_ratio_after_100ms},
                    {"wall_force_end_n", r.wall_force_end_n},
                    {"commanded_force_end_n", r.commanded_force_end_n},
                    {"max_observed_energy_j", r.max_energy_j}});
  }
  out["resting_hand"] = rows;
  out["resting_hand_method"] =
      "1 kHz lockstep, SimFalcon nominal, default hand (300 N/m, 5 N·s/m); target 6 mm above a 3000 N/m wall "
      "(n=1, lambda=0, proxy every tick) moves at 0.5 m/s to 8 mm past it and rests 1.2 s; "
      "rendered_90pct_after_contact_s: from first contact until commanded >= 90 % of the wall's HC force for the rest "
      "of the run; min ratio from contact + 100 ms";
}

// ---------------------------------------------------------------- command


// Runs `body` on a thread set up like the rt loop's (SCHED_FIFO at `priority` on CPU 0, best
// effort: the body runs whatever the set-up achieved), so that what is timed is the work and not
// the other processes of a shared machine preempting it. Returns what the set-up achieved.
rt::RtSetupReport run_on_timing_thread(int priority, std::function<void()> body) {
  rt::RtThreadConfig thread_config;
  thread_config.policy = rt::RtPolicy::kBestEffort;
  thread_config.priority = priority;
  thread_config.cpu = 0;
  RtThread thread(thread_config, std::move(body));
  thread.join();
  return thread.setup_report();
}

// 1. Tick compute time: rt::tick alone, 1 and 8 patches, and the machine's reference workload.
nlohmann::json measure_tick_ns(const BenchRtOptions& args) {
  std::printf("1. tick compute time (rt::tick alone on a thread set up as the rt loop's, %d ticks, replayed 0.2 m/s circle, "
              "proxy swap every 10 ticks)\n",
              kTimedTicks);
  std::printf("   %-10s %10s %10s %10s %10s   (ns)\n", "patches", "median", "p99", "p99.9", "max");
  nlohmann::json tick_json;
  double clock_pair_ns = 0.0;
  rt::RtSetupReport tick_setup;
  for (const int patches : {1, 8}) {
    // On a SCHED_FIFO thread (best effort) like the real loop, so that what is timed is the
    // tick and not the other processes of a shared machine preempting it.
    TickTiming timing;
    std::exception_ptr failure;
    tick_setup = run_on_timing_thread(args.priority, [&] {
      try {
        timing = time_ticks(patches);
      } catch (...) {
        failure = std::current_exception();
      }
    });
    if (failure) std::rethrow_exception(failure);
    nlohmann::json d = distribution(timing.tick_ns);
    d["faults"] = timing.faults;
    d["max_force_n"] = timing.max_force_n;
    std::printf("   %-10d %10.0f %10.0f %10.0f %10.0f\n", patches, d["median"].get<double>(), d["p99"].get<double>(),
                d["p999"].get<double>(), d["max"].get<double>());
    tick_json["patches_" + std::to_string(patches)] = d;
    clock_pair_ns = timing.clock_pair_median_ns;
  }
  {
    std::vector<double> reference;
    (void)run_on_timing_thread(args.priority, [&] { reference = time_reference_workload(kTimedTicks); });
    const nlohmann::json d = distribution(reference);
    std::printf("   %-10s %10.0f %10.0f %10.0f %10.0f   (fixed arithmetic, same thread: the machine's noise)\n",
                "reference", d["median"].get<double>(), d["p99"].get<double>(), d["p999"].get<double>(),
                d["max"].get<double>());
    tick_json["reference_workload"] = d;
  }
  tick_json["clock_pair_overhead_median_ns"] = clock_pair_ns;
  tick_json["note"] = "each tick timed alone with steady_clock; the clock pair overhead is included, not subtracted";
  tick_json["sched_fifo"] = tick_setup.sched_fifo;
  tick_json["setup_warnings"] = tick_setup.message;
  std::printf("   (steady_clock pair overhead, median: %.0f ns, included above)\n", clock_pair_ns);
  // What the set-up achieved, not what it asked for: without the privilege the thread is an
  // ordinary one and the figures carry the other processes' preemptions.
  if (tick_setup.sched_fifo) {
    std::printf("   (timing thread: SCHED_FIFO priority %d)\n", args.priority);
  } else {
    std::printf("   (timing thread: an ordinary thread, SCHED_FIFO not granted: %s)\n", tick_setup.message);
  }

  return tick_json;
}

// 2. The SCHED_FIFO wake-up latency against cyclictest, at 1 and 4 kHz, into `out`.
void measure_wakeups(const BenchRtOptions& args, nlohmann::json& out) {
  if (!args.skip_sched_fifo) {
    const unsigned cpus = std::thread::hardware_concurrency();
    const bool concurrent = cpus >= 2;
    const std::string cyclictest = find_cyclictest();
    rt::RtThreadConfig thread_config;
    thread_config.policy = args.rt_policy;
    thread_config.priority = args.priority;
    thread_config.cpu = 0;
    nlohmann::json wakeup, cyclic, ratio_p99, ratio_max;
    std::printf("\n2. SCHED_FIFO run against SimFalcon, %.0f s per rate, priority %d, %s\n", args.seconds, args.priority,
                concurrent ? "cyclictest concurrently on CPU 1 (ours on CPU 0)" : "cyclictest back to back (1 CPU)");
    std::printf("   %-8s %-11s %8s %8s %8s %10s %9s   (µs)\n", "rate", "who", "median", "p99", "p99.9", "max", "overruns");
    for (const double rate : {1000.0, 4000.0}) {
      const std::string key = std::to_string(static_cast<int>(rate)) + "hz";
      const int interval_us = static_cast<int>(std::lround(1e6 / rate));
      CyclictestResult c;
      RtRunResult ours;
      if (concurrent) {
        std::thread cyclic_thread([&] { c = run_cyclictest(cyclictest, args.priority, interval_us, args.seconds, 1); });
        ours = run_sched_fifo(rate, args.seconds, thread_config);
        cyclic_thread.join();
      } else {
        ours = run_sched_fifo(rate, args.seconds, thread_config);
        c = run_cyclictest(cyclictest, args.priority, interval_us, args.seconds, -1);
      }
      if (ours.setup.message[0] != '\0') spdlog::warn("bench rt: real-time setup: {}", ours.setup.message);
      wakeup[key] = wakeup_json(ours);
      cyclic[key] = cyclictest_json(c);
      const auto& w = wakeup[key];
      std::printf("   %-8s %-11s %8.0f %8.0f %8.0f %10.1f %9llu\n", key.c_str(), "rt_core", w["median"].get<double>(),
                  w["p99"].get<double>(), w["p999"].get<double>(), w["max"].get<double>(),
                  static_cast<unsigned long long>(w["overruns"].get<std::uint64_t>()));
      if (c.available) {
        std::printf("   %-8s %-11s %8.0f %8.0f %8.0f %10.0f %9s\n", key.c_str(), "cyclictest", c.quantile_us(0.5),
                    c.quantile_us(0.99), c.quantile_us(0.999), c.max_us, "-");
        const double c_p99 = c.quantile_us(0.99);
        ratio_p99[key] = c_p99 > 0.0 ? nlohmann::json(w["p99"].get<double>() / c_p99) : nlohmann::json(nullptr);
        ratio_max[key] = c.max_us > 0.0 ? nlohmann::json(w["max"].get<double>() / c.max_us) : nlohmann::json(nullptr);
      } else {
        std::printf("   %-8s %-11s %s\n", key.c_str(), "cyclictest", c.reason.c_str());
        ratio_p99[key] = nullptr;
        ratio_max[key] = nullptr;
      }
    }
    out["wakeup_us"] = wakeup;
    out["cyclictest_us"] = cyclic;
    out["ratio_vs_cyclictest"] = {{"p99", ratio_p99}, {"max", ratio_max}};
    out["sched_fifo_mode"] = concurrent ? "concurrent: rt_core on CPU 0, cyclictest on CPU 1"
                                        : "back to back on one CPU";
  } else {
    out["wakeup_us"] = {{"skipped", "--skip-sched-fifo"}};
    out["cyclictest_us"] = {{"skipped", "--skip-sched-fifo"}};
  }

}

// 3. The Z-width per rate, passivity controller off and on, into `out`.
void measure_zwidth(nlohmann::json& out) {
  std::printf("\n3. Z-width (lockstep): largest stable and passive wall stiffness vs Colgate–Schenkel K < 2b/T, b = %.1f N·s/m\n",
              falcon::kSimViscousDamping_n_s_per_m);
  std::printf("   %-8s %14s %16s %16s %10s   %s\n", "rate", "bound 2b/T", "K max (PC off)", "K max (PC on)", "off/bound",
              "next K fails: off | on");
  nlohmann::json zwidth = nlohmann::json::array();
  for (const double rate : {500.0, 1000.0, 2000.0, 4000.0, 8000.0, 10000.0}) {
    const double b = falcon::kSimViscousDamping_n_s_per_m;
    const double bound = 2.0 * b * rate;
    WallRun failure_off, failure_on;
    const double k_off = zwidth_k(rate, false, failure_off);
    const double k_on = zwidth_k(rate, true, failure_on);
    std::printf("   %-8.0f %14.0f %16.0f %16.0f %10.2f   %s | %s\n", rate, bound, k_off, k_on, k_off / bound,
                failure_text(failure_off).c_str(), failure_text(failure_on).c_str());
    zwidth.push_back({{"rate_hz", rate},
                      {"period_s", 1.0 / rate},
                      {"device_damping_n_s_per_m", b},
                      {"colgate_bound_k_n_per_m", bound},
                      {"k_max_passivity_off_n_per_m", k_off},
                      {"k_max_passivity_on_n_per_m", k_on},
                      {"ratio_off_to_bound", k_off / bound},
                      {"first_failure_off", {{"peak_to_peak_m", failure_off.peak_to_peak_m},
                                             {"port_energy_j", failure_off.port_energy_j},
                                             {"stable", failure_off.stable}, {"passive", failure_off.passive},
                                             {"renders", failure_off.renders}, {"held_force_n", failure_off.held_force_n},
                                             {"expected_force_n", failure_off.expected_force_n}}},
                      {"first_failure_on", {{"peak_to_peak_m", failure_on.peak_to_peak_m},
                                            {"port_energy_j", failure_on.port_energy_j},
                                            {"stable", failure_on.stable}, {"passive", failure_on.passive},
                                             {"renders", failure_on.renders}, {"held_force_n", failure_on.held_force_n},
                                             {"expected_force_n", failure_on.expected_force_n}}}});
  }
  out["zwidth"] = zwidth;
  out["zwidth_method"] =
      "undamped wall (n=1, lambda=0) pressed 8 mm deep by a hand spring (300 N/m, no damping), held 0.8 s, released; "
      "grid K = 250·1.25^i N/m; stable: peak-to-peak over the last 0.3 s of the hold <= 0.25 mm; passive: "
      "sum F_motor·dp - sum b|v|^2 T (the damper counted only while the motor force is non-zero) <= 0 (SimFalcon ground truth); "
      "renders: mean motor force along the normal over the hold window >= 90 % of the equilibrium wall force K·k·8mm/(K+k) "
      "(a wall the passivity controller holds back to nothing is not a rendered wall); proxy refreshed at min(rate, 1 kHz)";

}

nlohmann::json run_rt_bench(const BenchRtOptions& args) {
  nlohmann::json out;
  out["benchmark"] = "rt";
  out["machine"] = machine_info();
  out["seconds"] = args.seconds;
  out["tick_ns"] = measure_tick_ns(args);
  measure_wakeups(args, out);
  measure_zwidth(out);
  measure_resting_hand(out);
  return out;
}

}  // namespace

nlohmann::json run_bench_rt(const BenchRtOptions& options) { return run_rt_bench(options); }

}  // namespace fissure::eval
