// The loop owner in lockstep against SimFalcon: allocation-free ticking, passivity of a
// press-hold-release with the passivity controller on (and activity with it off),
// absolute deadlines and overrun counting, ramp-out at stop, determinism.
#include "fissure/rt_core/rt_loop.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <new>
#include <vector>

#include "fissure/falcon_hw/sim_falcon.hpp"
#include "fissure/rt_core/faults.hpp"
#include "rt_test_support.hpp"

// ---- global allocation counter (replaces operator new/delete in this test binary) ----
namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};

void* counted_alloc(std::size_t size, std::size_t alignment) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (size == 0) size = 1;
  void* p = alignment <= alignof(std::max_align_t)
                ? std::malloc(size)
                : std::aligned_alloc(alignment, (size + alignment - 1) / alignment * alignment);
  if (p == nullptr) throw std::bad_alloc();
  return p;
}
}  // namespace

// GCC 12 at -O1 (the sanitizer presets) inlines these replacements into their callers and then
// reports free() on memory from "operator new" as -Wmismatched-new-delete: a false positive for
// a replaced global operator new that itself allocates with malloc.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t size) { return counted_alloc(size, alignof(std::max_align_t)); }
void* operator new[](std::size_t size) { return counted_alloc(size, alignof(std::max_align_t)); }
void* operator new(std::size_t size, std::align_val_t a) { return counted_alloc(size, static_cast<std::size_t>(a)); }
void* operator new[](std::size_t size, std::align_val_t a) { return counted_alloc(size, static_cast<std::size_t>(a)); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop

namespace fissure::rt {
namespace {

using testing::plane_proxy;

constexpr double kCentreZ_m = 0.125;

HandScript press_hold_release(double depth_below_centre_m, double hold_s, double speed_m_per_s) {
  HandScript hand;
  hand.start_position_device_m = {0.0, 0.0, kCentreZ_m};
  // Wait out the ramp-in (0.5 s) before touching anything.
  hand.waypoints.push_back({{0.0, 0.0, kCentreZ_m}, speed_m_per_s, 0.6});
  hand.waypoints.push_back({{0.0, -depth_below_centre_m, kCentreZ_m}, speed_m_per_s, hold_s});
  hand.waypoints.push_back({{0.0, 0.0, kCentreZ_m}, speed_m_per_s, 0.2});
  hand.release_at_end = true;
  return hand;
}

/// Everything a lockstep session needs, heap-allocated once before the ticks.
struct Session {
  Session(const RtConfig& config, falcon::SimFalconConfig sim_config) {
    if (!build_model(config, model)) throw std::runtime_error("bad config");
    sim = std::make_unique<falcon::SimFalcon>(std::move(sim_config), clock);
    loop = std::make_unique<RtLoop>(model, *sim, clock, proxy_in, state_out, *telemetry);
  }
  LockstepClock clock{0};
  RtModel model;
  std::unique_ptr<falcon::SimFalcon> sim;
  ProxyExchange proxy_in;
  DeviceStateExchange state_out;
  std::unique_ptr<TelemetryRing> telemetry = std::make_unique<TelemetryRing>();
  std::unique_ptr<RtLoop> loop;
};

/// Ground truth energy: Σ F_motor · Δp over SimFalcon's true motion, each interval paired
/// with the motor force that acted during it (truth after the exchange that ended it).
struct EnergyMeter {
  void sample(const falcon::SimFalconTruth& truth) {
    if (primed) energy_j += truth.motor_force_device_n.dot(truth.position_device_m - p_prev);
    p_prev = truth.position_device_m;
    primed = true;
  }
  double energy_j = 0.0;
  Eigen::Vector3d p_prev = Eigen::Vector3d::Zero();
  bool primed = false;
};

TEST(RtLoop, NoHeapAllocationInTenToTheFiveTicks) {
  falcon::SimFalconConfig sim;
  HandScript hand;
  hand.start_position_device_m = {0.0, 0.0, kCentreZ_m};
  for (int i = 0; i < 40; ++i) {  // press and release, over and over (100 s of session)
    hand.waypoints.push_back({{0.0, -0.012, kCentreZ_m}, 0.05, 0.5});
    hand.waypoints.push_back({{0.01, 0.0, kCentreZ_m}, 0.05, 0.5});
  }
  sim.hand = hand;
  Session s(RtConfig{}, sim);
  std::vector<TelemetrySample> trace;
  trace.reserve(1);
  TelemetrySample sample;
  double max_force = 0.0;
  double max_friction = 0.0;
  bool slid = false;
  std::uint64_t popped = 0;

  g_allocations = 0;
  g_counting = true;
  constexpr int kTicks = 100'000;
  for (int k = 0; k < kTicks; ++k) {
    if (k % 10 == 0) {  // a 100 Hz host: plane drifts, HC parameters as for tissue, friction on
      ContactProxy proxy = plane_proxy(static_cast<std::uint64_t>(k / 10 + 1), {0.0, -0.004 - 1e-6 * (k % 1000), 0.0},
                                       {0.0, 1.0, 0.0}, 10000.0, 2000.0, 1.5);
      proxy.flags |= proxy_friction_bit(ToolPart::kTool);
      // A host that slides: its friction opposes the tool's motion, seen where the tool was.
      proxy.friction[0].reference_part_position_world_m = to_vec3(s.loop->data().tool.p_tool_world_m);
      proxy.friction[0].host_force_world_n = to_vec3(-5.0 * s.loop->data().tool.v_tool_world_m_per_s);
      proxy.friction[0].static_ratio = 0.5;
      proxy.friction[0].kinetic_ratio = 0.4;
      s.proxy_in.publish(proxy);
    }
    s.loop->step();
    while (s.telemetry->try_pop(sample)) {
      ++popped;
      max_force = std::max(max_force, as_eigen(sample.force_device_n).norm());
      max_friction = std::max(max_friction, as_eigen(sample.friction_force_device_n).norm());
      slid = slid || sample.parts_sliding > 0;
    }
  }
  g_counting = false;
  EXPECT_EQ(g_allocations.load(), 0) << "heap allocations during " << kTicks << " ticks";
  EXPECT_EQ(s.loop->stats().ticks, static_cast<std::uint64_t>(kTicks));
  EXPECT_EQ(popped, static_cast<std::uint64_t>(kTicks));
  EXPECT_GT(max_force, 1.0);  // it really rendered contact
  EXPECT_GT(max_friction, 0.1);  // and friction, sticking and sliding
  EXPECT_TRUE(slid);
  EXPECT_EQ(s.loop->data().faults.fault_ticks, 0u);
}

TEST(RtLoop, TheAllocationCounterWorks) {
  g_allocations = 0;
  g_counting = true;
  auto* p = new int(3);
  g_counting = false;
  delete p;
  EXPECT_EQ(g_allocations.load(), 1);
}

struct PressResult {
  double truth_energy_j = 0.0;
  double observed_energy_j = 0.0;
  double max_force_n = 0.0;
  double max_damping = 0.0;
};

// An undamped wall (λ = 0, K = 2000 N/m) pressed, held and released at 1 kHz with SimFalcon's
// nominal damping and the default hand. Even where the closed loop is stable, a sampled spring
// behind the ping-pong's command latency returns more energy on release than it absorbed
// while being pressed (it behaves like a negative damper ≈ K·delay at the motor port), so
// Σ F·Δp at the motor port is positive unless the passivity controller takes it out.
PressResult run_press(bool passivity_on) {
  RtConfig config;
  config.passivity.enabled = passivity_on;
  falcon::SimFalconConfig sim;
  sim.hand = press_hold_release(0.012, 1.0, 0.05);
  Session s(config, sim);
  const auto ticks = static_cast<int>(3.0 * config.rate_hz);
  EnergyMeter meter;
  PressResult result;
  TelemetrySample sample;
  for (int k = 0; k < ticks; ++k) {
    if (k % 5 == 0) {
      s.proxy_in.publish(plane_proxy(static_cast<std::uint64_t>(k + 1), {0.0, -0.004, 0.0}, {0.0, 1.0, 0.0}, 2000.0));
    }
    s.loop->step();
    meter.sample(s.sim->truth());
    while (s.telemetry->try_pop(sample)) {
      result.max_force_n = std::max(result.max_force_n, as_eigen(sample.force_device_n).norm());
      result.max_damping = std::max(result.max_damping, sample.passivity_damping_n_s_per_m);
      result.observed_energy_j = sample.energy_j;
    }
  }
  result.truth_energy_j = meter.energy_j;
  return result;
}

TEST(RtLoop, PressHoldReleaseIsPassiveWithThePassivityController) {
  const PressResult on = run_press(true);
  EXPECT_GT(on.max_force_n, 2.0);  // it did press into the wall
  EXPECT_LE(on.observed_energy_j, 0.0);
  EXPECT_LE(on.truth_energy_j, 0.0) << "observer said " << on.observed_energy_j;
  EXPECT_GT(on.max_damping, 0.0);  // and the controller had work to do
}

TEST(RtLoop, TheSameStiffWallIsActiveWithoutThePassivityController) {
  const PressResult off = run_press(false);
  EXPECT_GT(off.max_force_n, 2.0);
  // ≈ +0.19 mJ true, +0.29 mJ observed (the pressed spring stores ≈ 1.5 mJ at most).
  EXPECT_GT(off.truth_energy_j, 1e-4) << "observer said " << off.observed_energy_j;
  EXPECT_GT(off.observed_energy_j, 1e-4);
}

// Issue 26: a hand that hits a 3000 N/m wall (the Falcon's rated stiffness) at 0.5 m/s and then
// rests against it, 8 mm past the surface through its 300 N/m grip (≈ 2.2 N), at 1 kHz. The
// impact makes the sampled wall return a little more than it stored, so the observer's E
// ends above a fixed reference −margin, and a reduction held while the hand rests would render
// the wall near 0 N from then on. The reference follows the wall's stored energy, the device's
// damper is credited with what it dissipated, and g gives the force back once that debt is
// paid, so the hand gets the wall's force within 100 ms of the impact and keeps it.
struct RestingHandResult {
  double contact_s = -1.0;
  double min_ratio_after_100ms = 1e9;  ///< commanded / wall force, from contact + 100 ms on
  double wall_force_end_n = 0.0;
  double max_correction_step_n = 0.0;  ///< largest per-tick change of commanded − wall force
  double max_observed_energy_j = -1e9;
};

RestingHandResult run_resting_hand(bool passivity_on) {
  constexpr double kWall_n_per_m = 3000.0, kWallY_m = -0.004;
  RtConfig config;
  config.passivity.enabled = passivity_on;
  falcon::SimFalconConfig sim;
  HandScript hand;
  hand.start_position_device_m = {0.0, 0.002, kCentreZ_m};
  hand.waypoints.push_back({{0.0, 0.002, kCentreZ_m}, 0.05, 0.6});  // wait out the ramp-in
  hand.waypoints.push_back({{0.0, kWallY_m - 0.008, kCentreZ_m}, 0.5, 1.5});
  hand.release_at_end = false;
  sim.hand = hand;
  Session s(config, sim);
  RestingHandResult result;
  TelemetrySample sample;
  double last_correction_n = 0.0;
  for (int k = 0; k < 1800; ++k) {
    s.proxy_in.publish(plane_proxy(static_cast<std::uint64_t>(k + 1), {0.0, kWallY_m, 0.0}, {0.0, 1.0, 0.0}, kWall_n_per_m));
    s.loop->step();
    while (s.telemetry->try_pop(sample)) {
      const double t_s = to_seconds(sample.time_ns);
      const double wall_n = sample.contact_force_device_n[1];
      const double commanded_n = sample.force_device_n[1];
      if (result.contact_s < 0.0 && wall_n > 0.0) result.contact_s = t_s;
      if (result.contact_s >= 0.0 && t_s >= result.contact_s + 0.1) {
        result.min_ratio_after_100ms = std::min(result.min_ratio_after_100ms, commanded_n / wall_n);
        result.max_correction_step_n =
            std::max(result.max_correction_step_n, std::abs((commanded_n - wall_n) - last_correction_n));
      }
      last_correction_n = commanded_n - wall_n;
      result.max_observed_energy_j = std::max(result.max_observed_energy_j, sample.energy_j);
      result.wall_force_end_n = wall_n;
    }
  }
  return result;
}

TEST(RtLoop, AHandRestingOnAStiffWallAfterAnImpactGetsTheWallsForceWithin100ms) {
  const RestingHandResult on = run_resting_hand(true);
  ASSERT_GT(on.contact_s, 0.6);
  // The hand does rest on the wall: K·x against the grip spring, 8 mm past the surface.
  EXPECT_NEAR(on.wall_force_end_n, 3000.0 * 300.0 * 0.008 / 3300.0, 0.1);
  EXPECT_GE(on.min_ratio_after_100ms, 0.9);
  // Without clicks: what the controller changes is a ramp (its base step 0.05 N per tick, the
  // damper β·v_f, and the urgency factor), never the whole force.
  EXPECT_LE(on.max_correction_step_n, 0.2);
  // And the observer stays passive within the stress bound (25 mJ) — far within it.
  EXPECT_LE(on.max_observed_energy_j, 0.005);
}

// Issue 26: the rt loop stalls for 100 ms (the clock jumps; SimFalcon integrates the gap under
// the last command) while the hand, resting on a 1000 N/m wall, starts a 10 mm press. The proxy
// in use was built before the stall: evaluated at the pose after it, it gives ~10 N no contact
// produced, and the host's first proxy after the stall sees no contact (as the rt-stall stress
// case's host did after the tool's jump), the one after it the wall again. The contact force
// goes on from what the device held through the stall (proxy_blend.hpp, continue_after_break)
// instead of from the stale proxy at the new pose.
TEST(RtLoop, AfterAStallTheContactForceGoesOnFromWhatTheDeviceHeld) {
  constexpr double kWall_n_per_m = 1000.0, kWallY_m = -0.004;
  falcon::SimFalconConfig sim;
  HandScript hand;
  hand.start_position_device_m = {0.0, 0.0, kCentreZ_m};
  hand.waypoints.push_back({{0.0, 0.0, kCentreZ_m}, 0.05, 0.6});                // ramp-in
  hand.waypoints.push_back({{0.0, kWallY_m - 0.006, kCentreZ_m}, 0.05, 0.5});   // rest 6 mm in
  hand.waypoints.push_back({{0.0, kWallY_m - 0.016, kCentreZ_m}, 0.1, 1.0});    // press 10 mm more
  hand.release_at_end = false;
  sim.hand = hand;
  Session s(RtConfig{}, sim);
  // The rest begins at 0.8 s and ends at 1.3 s: the stall covers the first 0.1 s of the press,
  // and the host's first 20 ms of proxies after it see no contact.
  constexpr double kStallStart_s = 1.3, kStall_s = 0.1, kNoContactUntil_s = kStallStart_s + kStall_s + 0.02;
  bool stalled = false;
  double before_n = 0.0, after_max_n = 0.0;
  TelemetrySample sample;
  for (int k = 0; k < 1600; ++k) {
    const double t_s = to_seconds(s.clock.now());
    const bool no_contact = stalled && t_s < kNoContactUntil_s;
    const double plane_y_m = no_contact ? -0.5 : kWallY_m;  // -0.5 m: far below the tool
    s.proxy_in.publish(plane_proxy(static_cast<std::uint64_t>(k + 1), {0.0, plane_y_m, 0.0}, {0.0, 1.0, 0.0}, kWall_n_per_m));
    if (!stalled && t_s >= kStallStart_s) {
      s.clock.advance(static_cast<TimeNs>(kStall_s * 1e9));
      stalled = true;
    }
    s.loop->step();
    while (s.telemetry->try_pop(sample)) {
      const double sample_t_s = to_seconds(sample.time_ns);
      const double contact_n = Eigen::Vector3d(sample.contact_force_device_n[0], sample.contact_force_device_n[1],
                                               sample.contact_force_device_n[2]).norm();
      if (sample_t_s < kStallStart_s) before_n = contact_n;
      if (sample_t_s >= kStallStart_s && sample_t_s < kNoContactUntil_s) after_max_n = std::max(after_max_n, contact_n);
    }
  }
  ASSERT_TRUE(stalled);
  EXPECT_GT(before_n, 1.0);  // resting 6 mm into the wall against the 300 N/m grip: ≈ 1.4 N
  // What the device held, plus the wall's stiffness over the first tick's motion (≤ 0.1 N at
  // 0.1 m/s): not the ~10 N of the old plane 10 mm deeper.
  EXPECT_LE(after_max_n, before_n + 0.2);
}

// Issue 26: the hand rests rest_m into a wall when the loop stalls for 100 ms at the start of a
// press_m press (0.1 m/s, then a 1 s rest, then back out at 0.1 m/s): the device held the rest's
// force while the hand went deeper, so the contact the loop resumes on stores energy the hand did
// not pay for. That debt goes into the stall account (passivity.hpp): not withheld at the rest,
// collected on the way out. Returns the stress check's figure (20 ms means, 200–400 ms after the
// stall) and the observer's energy.
struct StallPressResult {
  double worst_error_200_400ms = 0.0;  ///< |mean F_cmd − mean F_contact| / |mean F_contact|, 20 ms means
  double contact_at_check_n = 0.0;
  double max_observed_energy_j = -1e9;
  double energy_end_j = 0.0;
};

StallPressResult run_stall_press(double kWall_n_per_m, double rest_m, double press_m) {
  constexpr double kWallY_m = -0.004;
  falcon::SimFalconConfig sim;
  HandScript hand;
  hand.start_position_device_m = {0.0, 0.0, kCentreZ_m};
  hand.waypoints.push_back({{0.0, kWallY_m - rest_m, kCentreZ_m}, 0.05, 0.62 - rest_m / 0.05});
  hand.waypoints.push_back({{0.0, kWallY_m - rest_m - press_m, kCentreZ_m}, 0.1, 1.0});
  hand.waypoints.push_back({{0.0, 0.0, kCentreZ_m}, 0.1, 0.5});                  // leave
  hand.release_at_end = false;
  sim.hand = hand;
  Session s(RtConfig{}, sim);
  // The press starts at 0.08 + 0.62 = 0.7 s: the stall covers its first 100 ms.
  constexpr double kStallStart_s = 0.7, kStall_s = 0.1, kStallEnd_s = kStallStart_s + kStall_s;
  constexpr int kMean = 20;  // ticks: 20 ms at 1 kHz, as the stress check
  bool stalled = false;
  StallPressResult result;
  std::vector<double> commanded, contact;
  TelemetrySample sample;
  for (int k = 0; k < 2600; ++k) {
    s.proxy_in.publish(plane_proxy(static_cast<std::uint64_t>(k + 1), {0.0, kWallY_m, 0.0}, {0.0, 1.0, 0.0}, kWall_n_per_m));
    if (!stalled && to_seconds(s.clock.now()) >= kStallStart_s) {
      s.clock.advance(static_cast<TimeNs>(kStall_s * 1e9));
      stalled = true;
    }
    s.loop->step();
    while (s.telemetry->try_pop(sample)) {
      const double t_s = to_seconds(sample.time_ns);
      commanded.push_back(sample.force_device_n[1]);
      contact.push_back(sample.contact_force_device_n[1]);
      if (t_s >= kStallEnd_s + 0.2 && t_s <= kStallEnd_s + 0.4) {
        double c = 0.0, e = 0.0;
        for (int i = 0; i < kMean; ++i) {
          c += commanded[commanded.size() - 1 - i];
          e += contact[contact.size() - 1 - i];
        }
        result.worst_error_200_400ms = std::max(result.worst_error_200_400ms, std::abs(c - e) / std::abs(e));
        result.contact_at_check_n = e / kMean;
      }
      result.max_observed_energy_j = std::max(result.max_observed_energy_j, sample.energy_j);
      result.energy_end_j = sample.energy_j;
    }
  }
  EXPECT_TRUE(stalled);
  return result;
}

TEST(RtLoop, AWallPressedIntoDuringAStallIsRenderedWithin5PercentFrom200msAfterIt) {
  // 300 N/m, resting 3 mm in (0.9 N), pressing 6 mm more: the stall leaves the device near the rest
  // the press ends in (1.35 N against the 300 N/m grip). The controller held 4.9 % of the force back
  // at the check before the stall account; now none.
  const StallPressResult r = run_stall_press(300.0, 0.003, 0.006);
  EXPECT_NEAR(r.contact_at_check_n, 1.35, 0.05);
  EXPECT_LE(r.worst_error_200_400ms, 0.01);
  // And the debt is collected on the way out: the observer stays far within the stress bound
  // (25 mJ) through the rest and the exit.
  EXPECT_LE(r.max_observed_energy_j, 0.005);
}

// A device whose exchange takes 2.5 periods of (lockstep) time.
class SlowDevice final : public falcon::HapticDevice {
 public:
  SlowDevice(LockstepClock& clock, TimeNs delay_ns) : inner_(Eigen::Vector3d(0.0, 0.0, kCentreZ_m)), clock_(clock), delay_ns_(delay_ns) {}
  [[nodiscard]] const char* name() const noexcept override { return "slow"; }
  falcon::IoStatus try_exchange(const falcon::DeviceCommand& c, falcon::DeviceReading& r) noexcept override {
    clock_.advance(delay_ns_);
    return inner_.try_exchange(c, r);
  }

 private:
  testing::StillDevice inner_;
  LockstepClock& clock_;
  TimeNs delay_ns_;
};

TEST(RtLoop, OverrunsAreCountedAndSkippedWithoutDrift) {
  RtModel model;
  ASSERT_TRUE(build_model(RtConfig{}, model));
  const TimeNs period = model.period_ns;
  LockstepClock clock(123);
  SlowDevice device(clock, period * 5 / 2);
  ProxyExchange proxy_in;
  DeviceStateExchange state_out;
  auto telemetry = std::make_unique<TelemetryRing>();
  auto loop = std::make_unique<RtLoop>(model, device, clock, proxy_in, state_out, *telemetry);
  loop->run_ticks(10);
  // Each tick ends 1.5 periods past its next deadline: 2 periods are skipped per tick and
  // every wake-up stays on the start + n·period grid.
  EXPECT_EQ(loop->stats().overruns, 20u);
  TelemetrySample sample;
  int n = 0;
  while (telemetry->try_pop(sample)) {
    EXPECT_EQ((sample.time_ns - 123) % period, 0) << "tick " << n;
    EXPECT_EQ(sample.time_ns, 123 + period * (1 + 3 * n));
    EXPECT_EQ(sample.overruns, static_cast<std::uint64_t>(2 * n));
    ++n;
  }
  EXPECT_EQ(n, 10);
}

TEST(RtLoop, LockstepDeadlinesAreExactPeriods) {
  RtConfig config;
  config.rate_hz = 4000.0;
  falcon::SimFalconConfig sim;
  Session s(config, sim);
  s.loop->run_ticks(100);
  EXPECT_EQ(s.clock.now(), 100 * s.model.period_ns);
  EXPECT_EQ(s.loop->stats().overruns, 0u);
  EXPECT_EQ(s.loop->stats().wakeup.max_ns, 0);
}

TEST(RtLoop, RendersTheSameWallAtEveryRateFrom500HzTo10kHz) {
  for (const double rate : {500.0, 1000.0, 2000.0, 4000.0, 8000.0, 10000.0}) {
    RtConfig config;
    config.rate_hz = rate;
    falcon::SimFalconConfig sim;
    sim.hand = press_hold_release(0.01, 0.5, 0.05);
    Session s(config, sim);
    const auto ticks = static_cast<int>(1.2 * rate);  // to the middle of the hold
    for (int k = 0; k < ticks; ++k) {
      if (k % std::max(1, static_cast<int>(rate / 1000.0)) == 0) {
        s.proxy_in.publish(plane_proxy(static_cast<std::uint64_t>(k + 1), {0.0, -0.004, 0.0}, {0.0, 1.0, 0.0}, 500.0));
      }
      s.loop->step();
    }
    EXPECT_EQ(s.clock.now(), ticks * s.model.period_ns) << rate;
    EXPECT_EQ(s.loop->data().faults.fault_ticks, 0u) << rate;
    // Hand spring 300 N/m pulling 6 mm past the wall against 500 N/m: x ≈ 2.25 mm, F ≈ 1.1 N.
    const double penetration = -0.004 - s.loop->data().p_device_m.y();
    EXPECT_NEAR(penetration, 300.0 * 0.006 / 800.0, 0.4e-3) << rate;
    EXPECT_NEAR(s.loop->data().force_device_n.y(), 500.0 * penetration, 0.05) << rate;
  }
}

TEST(RtLoop, StopRampsOutAndLeavesTheDeviceWithoutForce) {
  falcon::SimFalconConfig sim;
  sim.hand = press_hold_release(0.01, 5.0, 0.05);
  Session s(RtConfig{}, sim);
  for (int k = 0; k < 1500; ++k) {  // pressed into the wall by now
    s.proxy_in.publish(plane_proxy(static_cast<std::uint64_t>(k + 1), {0.0, -0.004, 0.0}, {0.0, 1.0, 0.0}, 500.0));
    s.loop->step();
  }
  ASSERT_GT(s.loop->data().force_device_n.norm(), 1.0);
  s.loop->request_stop();
  const std::uint64_t ticks = s.loop->run_ticks(10'000);
  EXPECT_TRUE(s.loop->stopped());
  EXPECT_NEAR(static_cast<double>(ticks), s.model.config.safety.ramp_out_s * s.model.config.rate_hz, 2.0);
  s.loop->send_zero_command();
  s.clock.advance(s.model.period_ns);
  falcon::DeviceReading reading;
  s.sim->try_exchange(falcon::DeviceCommand{}, reading);
  EXPECT_EQ(s.sim->truth().motor_torque_nm, Eigen::Vector3d::Zero());
}

TEST(RtLoop, SimFalconFaultsEndInZeroForceAndRecover) {
  falcon::SimFalconConfig sim;
  sim.hand = press_hold_release(0.01, 5.0, 0.05);
  sim.faults.dropped_replies.push_back({1500, 5});
  sim.faults.torn_packets.push_back({2000, 3});
  sim.faults.encoder_jumps.push_back({1, 2500, 600});
  Session s(RtConfig{}, sim);
  std::vector<std::uint32_t> faults;
  std::vector<double> force;
  TelemetrySample sample;
  for (int k = 0; k < 3500; ++k) {
    s.proxy_in.publish(plane_proxy(static_cast<std::uint64_t>(k + 1), {0.0, -0.004, 0.0}, {0.0, 1.0, 0.0}, 500.0));
    s.loop->step();
    while (s.telemetry->try_pop(sample)) {
      faults.push_back(sample.fault_bits);
      force.push_back(as_eigen(sample.force_device_n).norm());
    }
  }
  // Exchange k happens in tick k (the loop's ticks are numbered from 0 like the exchanges).
  for (int k = 1500; k < 1505; ++k) {
    EXPECT_NE(faults[k] & kFaultDeviceIo, 0u) << k;
    EXPECT_EQ(force[k], 0.0) << k;
  }
  for (int k = 2000; k < 2003; ++k) EXPECT_EQ(force[k], 0.0) << k;
  EXPECT_NE(faults[2500] & kFaultEncoderJump, 0u);
  EXPECT_EQ(force[2500], 0.0);
  EXPECT_GT(force[1499], 1.0);
  EXPECT_GT(force[1999], 1.0);
  EXPECT_GT(force[2499], 1.0);
  // The jumped counts persist (lost counts), so the device now reads a shifted position and
  // the force there is whatever the wall gives; what matters is that the fault cleared.
  for (int k = 2500; k < 2500 + RtConfig{}.faults.recovery_ticks; ++k) EXPECT_EQ(force[k], 0.0) << k;
  EXPECT_EQ(faults[3499] & kDeviceSideFaults, 0u);
  EXPECT_EQ(faults[2499] & kDeviceSideFaults, 0u);
}

TEST(RtLoop, SimFalconDisconnectStaysAtZeroForce) {
  falcon::SimFalconConfig sim;
  sim.hand = press_hold_release(0.01, 5.0, 0.05);
  sim.faults.disconnect_at_exchange = 1200;
  Session s(RtConfig{}, sim);
  TelemetrySample sample;
  for (int k = 0; k < 2000; ++k) {
    s.proxy_in.publish(plane_proxy(static_cast<std::uint64_t>(k + 1), {0.0, -0.004, 0.0}, {0.0, 1.0, 0.0}, 500.0));
    s.loop->step();
    while (s.telemetry->try_pop(sample)) {
      if (sample.tick >= 1200) {
        ASSERT_EQ(as_eigen(sample.force_device_n).norm(), 0.0) << sample.tick;
        ASSERT_NE(sample.fault_bits & kFaultDeviceDisconnected, 0u);
      }
    }
  }
}

TEST(RtLoop, LockstepRunsAreBitwiseDeterministic) {
  const auto run = [] {
    falcon::SimFalconConfig sim;
    sim.hand = press_hold_release(0.01, 0.5, 0.1);
    Session s(RtConfig{}, sim);
    std::vector<double> trace;
    TelemetrySample sample;
    for (int k = 0; k < 1500; ++k) {
      if (k % 7 == 0) {
        s.proxy_in.publish(plane_proxy(static_cast<std::uint64_t>(k + 1), {0.0, -0.004, 0.0}, {0.0, 1.0, 0.0}, 900.0, 100.0, 1.5));
      }
      s.loop->step();
      while (s.telemetry->try_pop(sample)) trace.push_back(sample.force_device_n[1] + sample.energy_j);
    }
    return trace;
  };
  EXPECT_EQ(run(), run());
}

}  // namespace
}  // namespace fissure::rt
