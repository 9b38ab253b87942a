// The split deployment's bridge logic (app/link_bridge.cpp), in lockstep: rt side (SimFalcon +
// RtLoop + LinkBridge role rt) and host side (SessionHost + LinkBridge role host) joined by a
// LoopbackLink (optionally through FaultInjectingCarriers) on a LockstepClock, one thread,
// deterministic. The reference is the in-process session (`fissure run --lockstep`'s order:
// N rt ticks, one host step) on the same scene and hand script.
#include "fissure/session/link_bridge.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "fissure/falcon_hw/sim_falcon.hpp"
#include "fissure/host_sim/scene_loader.hpp"
#include "fissure/rt_core/rt_config.hpp"
#include "fissure/rt_core/rt_loop.hpp"
#include "fissure/shared/fault_injecting_carrier.hpp"
#include "fissure/shared/loopback_carrier.hpp"
#include "fissure/shared/wire_codec.hpp"
#include "fissure/shared/wire_reassembler.hpp"
#include "fissure/session/session_host.hpp"

namespace fissure::session {
namespace {

/// Settling before the run [s]: short (test time), the same in every compared run.
constexpr double kSettle_s = 0.2;
constexpr TimeNs kTickNs = 1'000'000;  // 1 kHz rt, spatula-sphere's 1 kHz host: one tick per host step

/// kInProcess: `fissure run --lockstep`. kInProcessWireRounded: the same, but each message is
/// encoded and decoded by the wire codec on its way (float32 geometry, smallest-three
/// quaternion) — the split session's numerics without any link. kLoopback: the split session.
enum class Joint { kInProcess, kInProcessWireRounded, kLoopback };

/// The message as the other end of the wire sees it (encode → reassemble → decode).
template <typename Message>
Message through_the_wire(const Message& message, wire::MessageType type) {
  wire::FrameBatch batch;
  EXPECT_EQ(wire::encode(message, 0, batch), wire::EncodeStatus::kOk);
  wire::Reassembler reassembler;
  for (std::size_t i = 0; i < batch.count; ++i) {
    if (reassembler.push(batch.frames[i], 0) == type) {
      if constexpr (std::is_same_v<Message, DeviceState>) return reassembler.device_state();
      else return reassembler.contact_proxy();
    }
  }
  ADD_FAILURE() << "message did not survive the codec";
  return message;
}

struct RunSpec {
  Joint joint = Joint::kInProcess;
  double seconds = 2.4;                    ///< spatula-sphere's hand script: down, hold 1 s, up
  std::optional<transport::FaultConfig> faults;  ///< on both receive paths
  TimeNs host_dies_at_ns = -1;             ///< host stops stepping and pumping
  TimeNs rt_dies_at_ns = -1;               ///< rt stops ticking and pumping
};

struct RunTrace {
  std::vector<TimeNs> time_ns;
  std::vector<double> force_n;          ///< |commanded force| per tick
  std::vector<double> contact_force_n;  ///< |proxy force after blend and fade| per tick
  std::vector<double> fade_gain;
  std::vector<TimeNs> proxy_age_ns;
  std::uint64_t proxies_rejected = 0;
  std::uint64_t host_steps = 0;
  std::uint64_t host_steps_after_rt_death = 0;
  TimeNs host_noticed_rt_silence_at_ns = -1;  ///< first host period with peer_silent() after the rt died
  BridgeStatus rt_link{};
  BridgeStatus host_link{};
  transport::FaultCounts rt_faults{};
  transport::FaultCounts host_faults{};
};

const host::SceneDescription& spatula_scene() {
  static const host::SceneDescription scene = host::load_scene(host::resolve_scene_path("spatula-sphere"));
  return scene;
}

RunTrace run(const RunSpec& spec) {
  const host::SceneDescription& scene = spatula_scene();
  LockstepClock clock(0);
  rt::RtConfig config;
  config.rate_hz = 1e9 / static_cast<double>(kTickNs);
  config.mapping = scene.device_mapping;
  rt::RtModel model;
  EXPECT_TRUE(rt::build_model(config, model, nullptr));
  struct Exchanges {
    ProxyExchange rt_proxy;
    DeviceStateExchange rt_state;
    rt::TelemetryRing telemetry;
    ProxyExchange host_proxy;
    DeviceStateExchange host_state;
  };
  auto ex = std::make_unique<Exchanges>();
  SessionHost host(scene);
  host.settle(kSettle_s);

  const bool split = spec.joint == Joint::kLoopback;
  auto link = std::make_unique<transport::LoopbackLink>(clock);
  std::optional<transport::FaultInjectingCarrier> rt_faulty;
  std::optional<transport::FaultInjectingCarrier> host_faulty;
  transport::FrameCarrier* rt_carrier = &link->a();
  transport::FrameCarrier* host_carrier = &link->b();
  if (spec.faults) {
    transport::FaultConfig host_side = *spec.faults;
    host_side.seed = spec.faults->seed + 1;  // independent damage in the two directions
    rt_faulty.emplace(link->a(), clock, *spec.faults);
    host_faulty.emplace(link->b(), clock, host_side);
    rt_carrier = &*rt_faulty;
    host_carrier = &*host_faulty;
  }
  transport::LinkConfig rt_config_link;
  rt_config_link.role = wire::Role::kRt;
  rt_config_link.session_id = 11;
  transport::LinkConfig host_config_link;
  host_config_link.role = wire::Role::kHost;
  host_config_link.session_id = 22;
  LinkBridge rt_bridge(*rt_carrier, clock, rt_config_link, kHostSilentAfter_ns);
  LinkBridge host_bridge(*host_carrier, clock, host_config_link, kRtSilentAfter_ns);
  const bool rounded = spec.joint == Joint::kInProcessWireRounded;
  DeviceStateExchange& host_in = split || rounded ? ex->host_state : ex->rt_state;
  ProxyExchange& host_out = split || rounded ? ex->host_proxy : ex->rt_proxy;
  DeviceState state_scratch;
  ContactProxy proxy_scratch;

  if (split) {
    // Handshake before the session starts (as the two commands do while waiting for each
    // other): without faults it takes zero simulated time; lost Hellos repeat every 100 ms.
    // The device and the loop start afterwards, so every run's schedule is the in-process one.
    for (int i = 0; i < 400 && !(rt_bridge.established() && host_bridge.established()); ++i) {
      rt_bridge.pump_rt(ex->rt_state, ex->rt_proxy);
      host_bridge.pump_host(ex->host_state, ex->host_proxy);
      if (i % 4 == 3) clock.advance(10 * kTickNs);
    }
    EXPECT_TRUE(rt_bridge.established());
    EXPECT_TRUE(host_bridge.established());
  }
  falcon::SimFalconConfig sim_config;
  sim_config.hand = scene.hand;
  falcon::SimFalcon device(sim_config, clock);
  rt::RtLoop loop(model, device, clock, ex->rt_proxy, ex->rt_state, ex->telemetry);

  RunTrace trace;
  const TimeNs start_ns = clock.now();
  const TimeNs end_ns = start_ns + static_cast<TimeNs>(spec.seconds * 1e9);
  rt::TelemetrySample sample;
  while (clock.now() < end_ns) {
    const TimeNs t = clock.now() - start_ns;
    const bool rt_alive = spec.rt_dies_at_ns < 0 || t < spec.rt_dies_at_ns;
    const bool host_alive = spec.host_dies_at_ns < 0 || t < spec.host_dies_at_ns;
    if (rt_alive) {
      loop.step();
      if (split) rt_bridge.pump_rt(ex->rt_state, ex->rt_proxy);
      if (rounded && ex->rt_state.try_fetch(state_scratch)) {
        ex->host_state.publish(through_the_wire(state_scratch, wire::MessageType::kDeviceState));
      }
    } else {
      clock.advance(kTickNs);
    }
    if (host_alive) {
      bool live = true;
      if (split) {
        host_bridge.pump_host(ex->host_state, ex->host_proxy);
        live = host_bridge.established() && !host_bridge.peer_silent();
      }
      if (live) {
        host.step(host_in, host_out);
        ++trace.host_steps;
        if (!rt_alive) ++trace.host_steps_after_rt_death;
        if (split) host_bridge.pump_host(ex->host_state, ex->host_proxy);
      } else if (!rt_alive && trace.host_noticed_rt_silence_at_ns < 0) {
        trace.host_noticed_rt_silence_at_ns = clock.now() - start_ns;
      }
    }
    if (split && rt_alive) rt_bridge.pump_rt(ex->rt_state, ex->rt_proxy);
    if (rounded && ex->host_proxy.try_fetch(proxy_scratch)) {
      ex->rt_proxy.publish(through_the_wire(proxy_scratch, wire::MessageType::kContactProxy));
    }
    while (ex->telemetry.try_pop(sample)) {
      trace.time_ns.push_back(sample.time_ns - start_ns);
      trace.force_n.push_back(as_eigen(sample.force_device_n).norm());
      trace.contact_force_n.push_back(as_eigen(sample.contact_force_device_n).norm());
      trace.fade_gain.push_back(sample.fade_gain);
      trace.proxy_age_ns.push_back(sample.proxy_age_ns);
    }
  }
  trace.proxies_rejected = loop.data().proxy.rejected_count;
  trace.rt_link = rt_bridge.status();
  trace.host_link = host_bridge.status();
  if (rt_faulty) trace.rt_faults = rt_faulty->counts();
  if (host_faulty) trace.host_faults = host_faulty->counts();
  return trace;
}

double peak(const std::vector<double>& values) {
  double out = 0.0;
  for (const double v : values) out = std::max(out, v);
  return out;
}

struct Difference {
  double max_abs_n = 0.0;
  double rms_n = 0.0;
};

Difference difference(const RunTrace& a, const RunTrace& b) {
  EXPECT_EQ(a.force_n.size(), b.force_n.size());
  const std::size_t n = std::min(a.force_n.size(), b.force_n.size());
  Difference d;
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_EQ(a.time_ns[i], b.time_ns[i]);
    const double e = std::abs(a.contact_force_n[i] - b.contact_force_n[i]);
    d.max_abs_n = std::max(d.max_abs_n, e);
    d.rms_n += e * e;
  }
  d.rms_n = n > 0 ? std::sqrt(d.rms_n / static_cast<double>(n)) : 0.0;
  return d;
}

// The reference run is shared by the tests (it takes a few seconds of Bullet).
const RunTrace& in_process() {
  static const RunTrace trace = run(RunSpec{});
  return trace;
}

struct HoldFigures {
  TimeNs contact_start_ns = -1;  ///< first tick with contact force
  TimeNs contact_end_ns = -1;    ///< last tick with contact force
  double hold_mean_n = 0.0;      ///< mean contact force while the hand holds still
};

/// spatula-sphere's hand: 0.6 s down, 1 s hold, 0.6 s up. The hold window leaves 0.1 s after
/// the arrival for the soft body to take the load.
HoldFigures hold_figures(const RunTrace& trace) {
  constexpr TimeNs kHoldFrom_ns = 700'000'000;
  constexpr TimeNs kHoldTo_ns = 1'600'000'000;
  HoldFigures f;
  double sum = 0.0;
  int n = 0;
  for (std::size_t i = 0; i < trace.time_ns.size(); ++i) {
    if (trace.contact_force_n[i] > 0.0) {
      if (f.contact_start_ns < 0) f.contact_start_ns = trace.time_ns[i];
      f.contact_end_ns = trace.time_ns[i];
    }
    if (trace.time_ns[i] >= kHoldFrom_ns && trace.time_ns[i] < kHoldTo_ns) {
      sum += trace.contact_force_n[i];
      ++n;
    }
  }
  f.hold_mean_n = n > 0 ? sum / n : 0.0;
  return f;
}

const RunTrace& wire_rounded() {
  RunSpec spec;
  spec.joint = Joint::kInProcessWireRounded;
  static const RunTrace trace = run(spec);
  return trace;
}

TEST(LinkBridgeLockstep, LoopbackSplitReproducesTheInProcessForce) {
  const RunTrace& reference = in_process();
  const RunTrace& rounded = wire_rounded();
  RunSpec spec;
  spec.joint = Joint::kLoopback;
  const RunTrace split = run(spec);
  const double peak_n = peak(reference.contact_force_n);
  ASSERT_GT(peak_n, 1.0) << "the hand script must press the spatula into the sphere";
  // 1. The bridge adds nothing but the wire's float32: the split session is tick for tick
  //    the in-process session whose messages pass the codec (same schedule, nothing lost,
  //    nothing late). Exact, not a tolerance.
  const Difference exact = difference(rounded, split);
  EXPECT_EQ(exact.max_abs_n, 0.0) << "the link changed more than the codec's rounding";
  // 2. Against the unrounded in-process session: identical until the soft body's contact
  //    dynamics amplify the ~6e-8 relative rounding (the reference itself jitters by ±0.5 N
  //    while the hand holds still), so the stated tolerance is on what the hand feels:
  //    contact starts within 1 ms, the mean force over the hold is within 5 % of peak, and the
  //    release (the soft surface letting go of the rising spatula, the most sensitive moment)
  //    within 50 ms. The release is a chaotic event, not a property of the link: 12 ms apart
  //    with the first host_sim weighting, 28 ms after the contacted-share area weighting
  //    (87d0dc4) changed the physics — the exactness of the link is check 1, not this one.
  const HoldFigures a = hold_figures(reference);
  const HoldFigures b = hold_figures(split);
  EXPECT_LE(std::abs(a.contact_start_ns - b.contact_start_ns), kTickNs);
  EXPECT_LE(std::abs(a.contact_end_ns - b.contact_end_ns), 50 * kTickNs) << a.contact_end_ns << " vs " << b.contact_end_ns;
  EXPECT_NEAR(a.hold_mean_n, b.hold_mean_n, 0.05 * peak_n);
  std::size_t identical_ticks = 0;
  while (identical_ticks < split.time_ns.size() && split.contact_force_n[identical_ticks] == reference.contact_force_n[identical_ticks]) {
    ++identical_ticks;
  }
  EXPECT_GT(identical_ticks, 0u);
  EXPECT_EQ(split.proxies_rejected, 0u);
  EXPECT_EQ(split.rt_link.messages_discarded, 0u);
  EXPECT_EQ(split.host_link.messages_discarded, 0u);
  EXPECT_EQ(split.host_steps, reference.host_steps);
  const Difference d = difference(reference, split);
  std::printf("split vs wire-rounded in-process: max |dF| %.3g N; vs in-process: first difference at tick %zu, contact %.3f-%.3f s "
              "vs %.3f-%.3f s, hold mean %.3f vs %.3f N, per-tick max |dF| %.3g N rms %.3g N (peak %.3f N)\n",
              exact.max_abs_n, identical_ticks, to_seconds(a.contact_start_ns), to_seconds(a.contact_end_ns),
              to_seconds(b.contact_start_ns), to_seconds(b.contact_end_ns), a.hold_mean_n, b.hold_mean_n, d.max_abs_n, d.rms_n, peak_n);
}

// Index of the tick with the largest contact force (the host dies / rt dies while pressing).
std::size_t peak_tick(const RunTrace& trace) {
  std::size_t best = 0;
  for (std::size_t i = 0; i < trace.contact_force_n.size(); ++i) {
    if (trace.contact_force_n[i] > trace.contact_force_n[best]) best = i;
  }
  return best;
}

TEST(LinkBridgeLockstep, HostDeathFadesTheRtForceToZeroWithinTheStaleBound) {
  const RunTrace& reference = in_process();
  RunSpec spec;
  spec.joint = Joint::kLoopback;
  spec.host_dies_at_ns = reference.time_ns[peak_tick(reference)];
  spec.seconds = to_seconds(spec.host_dies_at_ns) + 0.4;
  const RunTrace split = run(spec);
  // rt_core's bound (staleness.hpp): proxy age ≤ stale_after + fade (+ one tick). The last
  // proxy was accepted at most one host period before the host died.
  const rt::ProxyConfig proxy_config{};
  const TimeNs bound_ns = static_cast<TimeNs>((proxy_config.stale_after_s + proxy_config.fade_s) * 1e9) + 2 * kTickNs;
  bool pressing_at_death = false;
  TimeNs zero_at_ns = -1;
  for (std::size_t i = 0; i < split.time_ns.size(); ++i) {
    if (split.time_ns[i] == spec.host_dies_at_ns - kTickNs) pressing_at_death = split.contact_force_n[i] > 1.0;
    if (split.time_ns[i] < spec.host_dies_at_ns) continue;
    if (split.contact_force_n[i] == 0.0 && zero_at_ns < 0) zero_at_ns = split.time_ns[i];
    if (zero_at_ns >= 0) {
      EXPECT_EQ(split.contact_force_n[i], 0.0) << "force came back at t = " << split.time_ns[i];
      EXPECT_EQ(split.fade_gain[i], 0.0);
    }
  }
  EXPECT_TRUE(pressing_at_death);
  ASSERT_GE(zero_at_ns, 0) << "the force never faded";
  EXPECT_LE(zero_at_ns - spec.host_dies_at_ns, bound_ns);
  // … and not abruptly: the fade takes fade_s, so the force is still on shortly after death.
  EXPECT_GT(zero_at_ns - spec.host_dies_at_ns, static_cast<TimeNs>(proxy_config.stale_after_s * 1e9));
  EXPECT_TRUE(split.rt_link.peer_silent);
  std::printf("host died at %.3f s, rt contact force zero %.1f ms later (bound %.1f ms)\n", to_seconds(spec.host_dies_at_ns),
              to_seconds(zero_at_ns - spec.host_dies_at_ns) * 1e3, to_seconds(bound_ns) * 1e3);
}

TEST(LinkBridgeLockstep, RtDeathIsNoticedByTheHostWithinItsBoundAndPausesTheScene) {
  const RunTrace& reference = in_process();
  RunSpec spec;
  spec.joint = Joint::kLoopback;
  spec.rt_dies_at_ns = reference.time_ns[peak_tick(reference)];
  spec.seconds = to_seconds(spec.rt_dies_at_ns) + 0.3;
  const RunTrace split = run(spec);
  ASSERT_GE(split.host_noticed_rt_silence_at_ns, 0) << "the host never noticed";
  const TimeNs noticed_after_ns = split.host_noticed_rt_silence_at_ns - spec.rt_dies_at_ns;
  // The last DeviceState left one tick before the death; silent once older than the bound.
  EXPECT_LE(noticed_after_ns, kRtSilentAfter_ns + 2 * kTickNs);
  EXPECT_GE(noticed_after_ns, kRtSilentAfter_ns - kTickNs) << "no false alarm before the bound";
  // Paused: after noticing, the host does not step (it stepped only inside the bound).
  EXPECT_LE(split.host_steps_after_rt_death, static_cast<std::uint64_t>(kRtSilentAfter_ns / kTickNs) + 2);
  EXPECT_TRUE(split.host_link.peer_silent);
  std::printf("rt died at %.3f s, host noticed %.1f ms later\n", to_seconds(spec.rt_dies_at_ns), to_seconds(noticed_after_ns) * 1e3);
}

TEST(LinkBridge, AVersionMismatchedPeerIsRefusedWithBothVersionsNamed) {
  LockstepClock clock(0);
  transport::LoopbackLink link(clock);
  transport::LinkConfig config;
  config.role = wire::Role::kRt;
  config.session_id = 5;
  LinkBridge bridge(link.a(), clock, config, kHostSilentAfter_ns);
  // The peer: a host speaking the next protocol version (its Hello layout is frozen, so we
  // can still read it and name its version).
  transport::LinkSender peer(link.b());
  wire::Hello hello;
  hello.protocol_version = static_cast<std::uint16_t>(kProtocolVersion + 1);
  hello.role = wire::Role::kHost;
  hello.session_id = 77;
  hello.publish_rate_hz = 1000.0f;
  ASSERT_EQ(peer.publish(hello), wire::EncodeStatus::kOk);
  peer.service();
  DeviceStateExchange state;
  ProxyExchange proxy;
  DeviceState sample;
  sample.sequence = 1;
  state.publish(sample);
  bridge.pump_rt(state, proxy);
  ASSERT_TRUE(bridge.failed());
  EXPECT_FALSE(bridge.established());
  const std::string error = bridge.status().error;
  EXPECT_NE(error.find("version " + std::to_string(kProtocolVersion)), std::string::npos) << error;
  EXPECT_NE(error.find("version " + std::to_string(kProtocolVersion + 1)), std::string::npos) << error;
  EXPECT_NE(error.find("mismatch"), std::string::npos) << error;
  EXPECT_EQ(bridge.status().messages_out, 0u) << "no data to a refused peer";
  ContactProxy taken;
  EXPECT_FALSE(proxy.try_fetch(taken)) << "nothing reaches rt_core from a refused peer";
  std::printf("%s\n", error.c_str());
}

/// rt and host bridges linked up over a loopback, both exchanging data, then the host either
/// closes cleanly or stops dead; the rt bridge after 0.2 s of silence.
BridgeStatus rt_view_after_host_stops(bool host_closes) {
  LockstepClock clock(0);
  transport::LoopbackLink link(clock);
  transport::LinkConfig rt_config_link;
  rt_config_link.role = wire::Role::kRt;
  rt_config_link.session_id = 1;
  rt_config_link.identity = wire::session_identity("spatula-sphere", DeviceMapping{});
  transport::LinkConfig host_config_link = rt_config_link;
  host_config_link.role = wire::Role::kHost;
  host_config_link.session_id = 2;
  LinkBridge rt_bridge(link.a(), clock, rt_config_link, kHostSilentAfter_ns);
  DeviceStateExchange rt_state;
  ProxyExchange rt_proxy;
  {
    LinkBridge host_bridge(link.b(), clock, host_config_link, kRtSilentAfter_ns);
    DeviceStateExchange host_state;
    ProxyExchange host_proxy;
    for (std::uint64_t sequence = 1; sequence <= 50; ++sequence) {
      DeviceState sample;
      sample.sequence = sequence;
      rt_state.publish(sample);
      ContactProxy p;
      p.sequence = sequence;
      p.flags = kProxyValid;
      host_proxy.publish(p);
      rt_bridge.pump_rt(rt_state, rt_proxy);
      host_bridge.pump_host(host_state, host_proxy);
      clock.advance(kTickNs);
    }
    EXPECT_TRUE(rt_bridge.established());
    EXPECT_FALSE(rt_bridge.status().peer_silent);
    if (host_closes) host_bridge.close();
  }
  for (int i = 0; i < 200; ++i) {
    rt_bridge.pump_rt(rt_state, rt_proxy);
    clock.advance(kTickNs);
  }
  return rt_bridge.status();
}

TEST(LinkBridge, AHostThatClosesCleanlyIsNotReportedAsLost) {
  const BridgeStatus closed = rt_view_after_host_stops(true);
  EXPECT_TRUE(closed.peer_closed);
  EXPECT_TRUE(closed.peer_silent) << "no proxies after the goodbye: rt_core fades as always";
  EXPECT_NE(format_bridge_status(closed, wire::Role::kRt).find("link closed by the peer"), std::string::npos)
      << format_bridge_status(closed, wire::Role::kRt);
  EXPECT_EQ(format_bridge_status(closed, wire::Role::kRt).find("LOST"), std::string::npos);

  const BridgeStatus crashed = rt_view_after_host_stops(false);
  EXPECT_FALSE(crashed.peer_closed);
  EXPECT_TRUE(crashed.peer_silent);
  EXPECT_NE(format_bridge_status(crashed, wire::Role::kRt).find("link LOST"), std::string::npos)
      << format_bridge_status(crashed, wire::Role::kRt);
}

TEST(LinkBridge, ARestartedHostKeepsTheProxySequenceIncreasingForRtCore) {
  LockstepClock clock(0);
  transport::LoopbackLink link(clock);
  transport::LinkConfig rt_config_link;
  rt_config_link.role = wire::Role::kRt;
  rt_config_link.session_id = 1;
  LinkBridge rt_bridge(link.a(), clock, rt_config_link, kHostSilentAfter_ns);
  DeviceStateExchange rt_state;
  ProxyExchange rt_proxy;
  std::uint64_t last_seen = 0;
  for (const std::uint32_t host_session : {100u, 200u}) {  // the host process, then its restart
    transport::LinkConfig host_config_link;
    host_config_link.role = wire::Role::kHost;
    host_config_link.session_id = host_session;
    LinkBridge host_bridge(link.b(), clock, host_config_link, kRtSilentAfter_ns);
    DeviceStateExchange host_state;
    ProxyExchange host_proxy;
    for (std::uint64_t sequence = 1; sequence <= 5; ++sequence) {
      ContactProxy p;
      p.sequence = sequence;  // a restarted host counts from 1 again
      p.flags = kProxyValid;
      host_proxy.publish(p);
      for (int i = 0; i < 3; ++i) {
        rt_bridge.pump_rt(rt_state, rt_proxy);
        host_bridge.pump_host(host_state, host_proxy);
        clock.advance(kTickNs);
      }
      rt_bridge.pump_rt(rt_state, rt_proxy);
      ContactProxy got;
      if (rt_proxy.try_fetch(got)) {
        EXPECT_GT(got.sequence, last_seen) << "rt_core would ignore it as out of order";
        last_seen = got.sequence;
      }
    }
  }
  EXPECT_GE(last_seen, 9u);
  EXPECT_EQ(rt_bridge.status().peer_restarts, 1u);
}

TEST(LinkBridge, APausedHostKeepsAnnouncingSoARestartedRtFindsItAndTheSceneResumes) {
  LockstepClock clock(0);
  transport::LoopbackLink link(clock);
  transport::LinkConfig host_config_link;
  host_config_link.role = wire::Role::kHost;
  host_config_link.session_id = 7;
  LinkBridge host_bridge(link.b(), clock, host_config_link, kRtSilentAfter_ns);
  DeviceStateExchange host_state;
  ProxyExchange host_proxy;
  DeviceStateExchange rt_state;
  ProxyExchange rt_proxy;
  DeviceState state;
  DeviceState received;
  auto run_rt_for = [&](LinkBridge& rt_bridge, int ticks) {
    for (int i = 0; i < ticks; ++i) {
      ++state.sequence;
      state.sample_time_ns = clock.now();
      rt_state.publish(state);
      rt_bridge.pump_rt(rt_state, rt_proxy);
      host_bridge.pump_host(host_state, host_proxy);
      clock.advance(kTickNs);
    }
  };
  {
    transport::LinkConfig rt_config_link;
    rt_config_link.role = wire::Role::kRt;
    rt_config_link.session_id = 1;
    LinkBridge first_rt(link.a(), clock, rt_config_link, kHostSilentAfter_ns);
    run_rt_for(first_rt, 20);
    ASSERT_TRUE(host_bridge.established());
    ASSERT_FALSE(host_bridge.peer_silent());
  }  // the rt process dies
  // The host, paused, keeps pumping for 1 s: it must keep saying Hello (on UDP that is how a
  // restarted rt end learns where the host is), about one per 100 ms hello period.
  for (int i = 0; i < 1000; ++i) {
    host_bridge.pump_host(host_state, host_proxy);
    clock.advance(kTickNs);
  }
  EXPECT_TRUE(host_bridge.peer_silent());
  int hellos = 0;
  transport::ReceivedFrame frame;
  while (link.a().try_receive(frame) == transport::CarrierStatus::kOk) {
    if (wire::parse_header(frame.frame).type == static_cast<std::uint8_t>(wire::MessageType::kHello)) ++hellos;
  }
  EXPECT_GE(hellos, 9);
  EXPECT_LE(hellos, 12);
  // A restarted rt (new session): the link comes back, the host hears it as a restart and
  // resumes. (On the loopback the new rt's own Hellos would reach the host anyway; on UDP
  // only the announcements counted above tell the new rt where the host is.)
  transport::LinkConfig rt_config_link;
  rt_config_link.role = wire::Role::kRt;
  rt_config_link.session_id = 2;
  LinkBridge second_rt(link.a(), clock, rt_config_link, kHostSilentAfter_ns);
  state.sequence = 0;  // its sequence numbers start over
  run_rt_for(second_rt, 150);
  EXPECT_TRUE(second_rt.established());
  EXPECT_FALSE(host_bridge.peer_silent()) << "the scene resumes";
  EXPECT_EQ(host_bridge.status().peer_restarts, 1u);
  ASSERT_TRUE(host_state.try_fetch(received));
  EXPECT_GT(received.sequence, 100u) << "the restarted rt's states are accepted from sequence 1 on";
}

TEST(LinkBridgeLockstep, TenPercentFrameLossStillConverges) {
  const RunTrace& reference = in_process();
  RunSpec spec;
  spec.joint = Joint::kLoopback;
  transport::FaultConfig faults;
  faults.drop_probability = 0.10;
  faults.seed = 2026;
  spec.faults = faults;
  const RunTrace lossy = run(spec);
  const double peak_n = peak(reference.contact_force_n);
  const Difference d = difference(reference, lossy);
  const std::uint64_t dropped = lossy.rt_faults.dropped + lossy.host_faults.dropped;
  const std::uint64_t frames = lossy.rt_faults.frames_in + lossy.host_faults.frames_in;
  EXPECT_GT(static_cast<double>(dropped), 0.08 * static_cast<double>(frames)) << "the carrier really lost ~10 %";
  // Lost DeviceStates make the host step towards a pose ≤ a few ms old; lost proxy segments
  // make rt_core keep the previous proxy a few ms longer: never stale, never faded.
  TimeNs max_age_ns = 0;
  for (std::size_t i = 0; i < lossy.proxy_age_ns.size(); ++i) {
    if (lossy.time_ns[i] > 50 * kTickNs) max_age_ns = std::max(max_age_ns, lossy.proxy_age_ns[i]);
  }
  EXPECT_LT(max_age_ns, static_cast<TimeNs>(rt::ProxyConfig{}.stale_after_s * 1e9) / 4);
  EXPECT_EQ(lossy.proxies_rejected, 0u) << "a damaged proxy is never applied";
  // Converges: what the hand feels stays the lossless session's — contact starts within 5 ms,
  // the mean force over the hold is within 10 % of peak (measured 5.5 %: a host step towards a
  // pose 1–2 ms old, a proxy kept 1–2 ms longer), the release within 50 ms (measured 20 ms) —
  // and the force ends at rest.
  const HoldFigures a = hold_figures(reference);
  const HoldFigures b = hold_figures(lossy);
  EXPECT_LE(std::abs(a.contact_start_ns - b.contact_start_ns), 5 * kTickNs);
  EXPECT_LE(std::abs(a.contact_end_ns - b.contact_end_ns), 50 * kTickNs);
  EXPECT_NEAR(a.hold_mean_n, b.hold_mean_n, 0.10 * peak_n);
  EXPECT_EQ(lossy.contact_force_n.back(), 0.0);
  EXPECT_GT(lossy.rt_link.messages_discarded + lossy.host_link.messages_discarded, 0u) << "losses are counted";
  std::printf("10 %% loss: %llu/%llu frames dropped, max proxy age %.1f ms, contact %.3f-%.3f s vs %.3f-%.3f s, "
              "hold mean %.3f vs %.3f N (peak %.2f N), per-tick rms |dF| %.3g N\n",
              static_cast<unsigned long long>(dropped), static_cast<unsigned long long>(frames), to_seconds(max_age_ns) * 1e3,
              to_seconds(a.contact_start_ns), to_seconds(a.contact_end_ns), to_seconds(b.contact_start_ns),
              to_seconds(b.contact_end_ns), a.hold_mean_n, b.hold_mean_n, peak_n, d.rms_n);
}

}  // namespace
}  // namespace fissure::session
