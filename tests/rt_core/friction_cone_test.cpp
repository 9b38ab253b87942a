// The friction cone alone (exact numbers on a hand moved by hand), then through evaluate_proxy.
#include "fissure/rt_core/friction_cone.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "fissure/rt_core/hunt_crossley.hpp"

namespace fissure::rt {
namespace {

constexpr double kStickStiffness_n_per_m = 1000.0;
constexpr double kNormal_n = 2.0;
constexpr double kMuStatic = 0.5;
constexpr double kMuKinetic = 0.4;
constexpr double kPeriod_s = 1e-3;

// A tool pressed onto a floor (normal force along +y on the tool).
PartNormalLoad floor_load(double normal_n = kNormal_n, ToolPart part = ToolPart::kTool) {
  PartNormalLoad load;
  const auto i = static_cast<std::size_t>(part);
  load.elastic_force_world_n[i] = Eigen::Vector3d(0.0, normal_n, 0.0);
  load.elastic_sum_n[i] = normal_n;
  return load;
}

// A proxy carrying friction for `part`: the host saw its friction `host_force` with the part at
// `reference` and the tissue under it moving at `surface_velocity`.
ContactProxy friction_proxy(std::uint64_t sequence, const Eigen::Vector3d& reference,
                            const Eigen::Vector3d& host_force = Eigen::Vector3d::Zero(),
                            const Eigen::Vector3d& surface_velocity = Eigen::Vector3d::Zero(),
                            ToolPart part = ToolPart::kTool, double mu_s = kMuStatic, double mu_k = kMuKinetic) {
  ContactProxy proxy;
  proxy.sequence = sequence;
  proxy.flags = kProxyValid | proxy_friction_bit(part);
  PartFriction& f = proxy.friction[static_cast<std::size_t>(part)];
  f.host_force_world_n = to_vec3(host_force);
  f.reference_part_position_world_m = to_vec3(reference);
  f.surface_velocity_world_m_per_s = to_vec3(surface_velocity);
  f.static_ratio = mu_s;
  f.kinetic_ratio = mu_k;
  return proxy;
}

ToolState tool_at(double x, double y = 0.0, double z = 0.0, const Eigen::Vector3d& v = Eigen::Vector3d::Zero()) {
  ToolState tool;
  tool.p_tool_world_m = Eigen::Vector3d(x, y, z);
  tool.v_tool_world_m_per_s = v;
  return tool;
}

// The cone alone (no walk towards the host), and the stage as rt_core runs it (τ = 50 ms).
constexpr FrictionModel kConeOnly{.stick_stiffness_world_n_per_m = kStickStiffness_n_per_m,
                                  .walk_share = 0.0,
                                  .max_walk_m = 0.0,
                                  .max_step_world_n = std::numeric_limits<double>::infinity(),
                                  .period_s = kPeriod_s};
constexpr FrictionModel kWithWalk{.stick_stiffness_world_n_per_m = kStickStiffness_n_per_m,
                                  .walk_share = kPeriod_s / kDefaultFrictionHostFollow_s,
                                  .max_walk_m = kDefaultFrictionMaxStep_n / kStickStiffness_n_per_m,
                                  .max_step_world_n = kDefaultFrictionMaxStep_n,
                                  .period_s = kPeriod_s};

FrictionEvaluation tick(FrictionState& state, const ContactProxy& proxy, const ToolState& tool,
                        const PartNormalLoad& load = floor_load(), const DeviceMapping& mapping = DeviceMapping{},
                        const FrictionModel& model = kConeOnly) {
  return evaluate_friction(model, state, proxy, load, mapping, tool);
}

TEST(FrictionCone, WithoutHostFrictionTheAnchorIsTheReferenceSoFrictionStartsAtZero) {
  FrictionState state;
  const ContactProxy proxy = friction_proxy(1, Eigen::Vector3d::Zero());
  const FrictionEvaluation e = tick(state, proxy, tool_at(0.0));
  EXPECT_TRUE(state.anchored[0]);
  EXPECT_EQ(e.force_world_n.force_world_n[0], Eigen::Vector3d::Zero());
  EXPECT_EQ(e.parts_sticking, 1);
  EXPECT_EQ(e.stored_energy_world_j, 0.0);
}

TEST(FrictionCone, StickingIsASpringToTheAnchorInTheTangentPlaneOnly) {
  FrictionState state;
  const ContactProxy proxy = friction_proxy(1, Eigen::Vector3d::Zero());
  tick(state, proxy, tool_at(0.0));
  // 0.3 mm along x and 2 mm into the surface: only the tangential 0.3 mm stretches the spring.
  const FrictionEvaluation e = tick(state, proxy, tool_at(3e-4, -2e-3));
  EXPECT_NEAR(e.force_world_n.force_world_n[0].x(), -0.3, 1e-12);
  EXPECT_NEAR(e.force_world_n.force_world_n[0].y(), 0.0, 1e-12);
  EXPECT_NEAR(e.force_world_n.force_world_n[0].z(), 0.0, 1e-12);
  EXPECT_NEAR(e.stored_energy_world_j, 0.5 * kStickStiffness_n_per_m * 3e-4 * 3e-4, 1e-15);
  EXPECT_FALSE(state.sliding[0]);
}

TEST(FrictionCone, TheHostsFrictionSeatsTheAnchorAndTheHandsMotionSinceStretchesIt) {
  FrictionState state;
  // The host felt 0.3 N of friction towards −x with the tool at x = 0; the hand is now at 0.2 mm.
  const ContactProxy proxy = friction_proxy(1, Eigen::Vector3d::Zero(), Eigen::Vector3d(-0.3, 0.05, 0.0));
  const FrictionEvaluation e = tick(state, proxy, tool_at(2e-4));
  // Only the tangential part of the host's force seats the anchor (its 0.05 N along n̂ is normal).
  EXPECT_NEAR(e.force_world_n.force_world_n[0].x(), -0.3 - 0.2, 1e-12);
  EXPECT_NEAR(e.force_world_n.force_world_n[0].y(), 0.0, 1e-12);
}

TEST(FrictionCone, BreaksAwayAtStaticTimesNormalAndSlidesAtKineticTimesNormal) {
  FrictionState state;
  const ContactProxy proxy = friction_proxy(1, Eigen::Vector3d::Zero());
  double largest_stick_n = 0.0;
  bool slid = false;
  // The hand moves along +z in 10 µm steps for 3 mm; the proxy stays the same.
  for (int i = 0; i <= 300; ++i) {
    const FrictionEvaluation e = tick(state, proxy, tool_at(0.0, 0.0, 1e-5 * i));
    const Eigen::Vector3d f = e.force_world_n.force_world_n[0];
    EXPECT_LE(f.z(), 0.0) << "friction opposes the slide";
    if (!state.sliding[0]) {
      ASSERT_FALSE(slid) << "a steady slide does not stick again, step " << i;
      largest_stick_n = std::max(largest_stick_n, f.norm());
    } else {
      slid = true;
      EXPECT_NEAR(f.norm(), kMuKinetic * kNormal_n, 1e-12) << "step " << i;
    }
  }
  EXPECT_TRUE(slid);
  // The last stuck step is within one step's spring of the static bound, never above it.
  EXPECT_LE(largest_stick_n, kMuStatic * kNormal_n + 1e-12);
  EXPECT_GT(largest_stick_n, kMuStatic * kNormal_n - kStickStiffness_n_per_m * 1e-5 - 1e-12);
}

TEST(FrictionCone, TheDropFromStaticToKineticAtBreakAwayIsSpreadAtTheStepBound) {
  FrictionState state;
  const ContactProxy proxy = friction_proxy(1, Eigen::Vector3d::Zero());
  double previous = 0.0;
  double largest_step = 0.0;
  bool slid = false;
  for (int i = 0; i <= 300; ++i) {
    const double f = tick(state, proxy, tool_at(1e-5 * i), floor_load(), DeviceMapping{}, kWithWalk).force_world_n.force_world_n[0].norm();
    largest_step = std::max(largest_step, std::abs(f - previous));
    previous = f;
    slid = slid || state.sliding[0];
  }
  ASSERT_TRUE(slid);
  // The stick spring's own step (K_t × 10 µm) and the drop's 0.05 N: never the whole 0.2 N.
  EXPECT_LE(largest_step, kDefaultFrictionMaxStep_n + 1e-12);
  EXPECT_NEAR(previous, kMuKinetic * kNormal_n, 1e-12) << "it ends on the kinetic cone";
}

TEST(FrictionCone, AHandThatStopsAfterASlideSticksAndBacksOffAlongTheSpring) {
  FrictionState state;
  const ContactProxy proxy = friction_proxy(1, Eigen::Vector3d::Zero());
  for (int i = 0; i <= 200; ++i) tick(state, proxy, tool_at(1e-5 * i));
  ASSERT_TRUE(state.sliding[0]);
  // Stopped: the cone holds μ_k·F_n as static friction.
  FrictionEvaluation e = tick(state, proxy, tool_at(2e-3));
  EXPECT_FALSE(state.sliding[0]);
  EXPECT_NEAR(e.force_world_n.force_world_n[0].x(), -kMuKinetic * kNormal_n, 1e-12);
  // Backing off 0.5 mm unloads the spring linearly: −0.8 N + 0.5 N.
  e = tick(state, proxy, tool_at(1.5e-3));
  EXPECT_NEAR(e.force_world_n.force_world_n[0].x(), -kMuKinetic * kNormal_n + 0.5, 1e-12);
}

TEST(FrictionCone, ASlideGoesOnAtKineticTimesNormalWhateverTheHostsFrictionSays) {
  // A 100 Hz host: every 10 ticks a proxy whose friction is the host's (nothing for 40 ticks, then
  // μ_k·F_n against the motion) at the pose the host stepped to, two ticks behind the hand.
  FrictionState state;
  const double speed = 0.05;
  for (int i = 0; i <= 400; ++i) {
    const double x = speed * kPeriod_s * i;
    const int host_tick = std::max(0, (i / 10) * 10 - 2);
    const ContactProxy proxy = friction_proxy(static_cast<std::uint64_t>(i / 10 + 1),
                                              Eigen::Vector3d(speed * kPeriod_s * host_tick, 0.0, 0.0),
                                              Eigen::Vector3d(i >= 40 ? -kMuKinetic * kNormal_n : 0.0, 0.0, 0.0));
    const FrictionEvaluation e =
        tick(state, proxy, tool_at(x, 0.0, 0.0, Eigen::Vector3d(speed, 0.0, 0.0)), floor_load(), DeviceMapping{}, kWithWalk);
    if (i >= 50) {
      EXPECT_NEAR(e.force_world_n.force_world_n[0].x(), -kMuKinetic * kNormal_n, 1e-12) << "tick " << i;
      EXPECT_TRUE(state.sliding[0]) << "tick " << i;
    }
  }
}

TEST(FrictionCone, TissueMovingWithThePartKeepsTheHostsPullInsteadOfASawtooth) {
  // A lifted vessel: the tissue moves up with the jaw at 2 cm/s and pulls 0.3 N down. A 100 Hz
  // host; each proxy is 3 ticks old when it arrives. Without the surface's velocity the rendered
  // force would swing by K_t × 0.2 mm = 0.2 N per host step.
  FrictionState state;
  const double speed = 0.02;
  const Eigen::Vector3d up(0.0, speed, 0.0);
  PartNormalLoad load;  // the jaw's normal is along z (the closing axis)
  load.elastic_force_world_n[0] = Eigen::Vector3d(0.0, 0.0, kNormal_n);
  load.elastic_sum_n[0] = kNormal_n;
  double lowest = 0.0, highest = -1.0;
  for (int i = 0; i <= 300; ++i) {
    const double y = speed * kPeriod_s * i;
    const int host_tick = std::max(0, (i / 10) * 10 - 3);
    const ContactProxy proxy = friction_proxy(static_cast<std::uint64_t>(i / 10 + 1),
                                              Eigen::Vector3d(0.0, speed * kPeriod_s * host_tick, 0.0),
                                              Eigen::Vector3d(0.0, -0.3, 0.0), up);
    const FrictionEvaluation e = tick(state, proxy, tool_at(0.0, y, 0.0, up), load, DeviceMapping{}, kWithWalk);
    if (i < 20) continue;
    lowest = std::min(lowest, e.force_world_n.force_world_n[0].y());
    highest = std::max(highest, e.force_world_n.force_world_n[0].y());
  }
  EXPECT_NEAR(lowest, -0.3, 1e-9);
  EXPECT_NEAR(highest, -0.3, 1e-9);
  EXPECT_FALSE(state.sliding[0]);
}

TEST(FrictionCone, AtRestTheForceWalksToTheHostsFrictionWithinItsTimeConstantAndStepBound) {
  FrictionState state;
  tick(state, friction_proxy(1, Eigen::Vector3d::Zero()), tool_at(0.0), floor_load(), DeviceMapping{}, kWithWalk);
  // The host now says the tissue pulls 0.3 N towards −x (e.g. it stuck to the part and stretched).
  const ContactProxy pulled = friction_proxy(2, Eigen::Vector3d::Zero(), Eigen::Vector3d(-0.3, 0.0, 0.0));
  double previous = 0.0;
  double at_tau = 0.0;
  const int tau_ticks = static_cast<int>(kDefaultFrictionHostFollow_s / kPeriod_s);
  for (int i = 1; i <= 5 * tau_ticks; ++i) {
    const double f = tick(state, pulled, tool_at(0.0), floor_load(), DeviceMapping{}, kWithWalk).force_world_n.force_world_n[0].x();
    EXPECT_LE(std::abs(f - previous), kDefaultFrictionMaxStep_n + 1e-12) << "tick " << i;
    previous = f;
    if (i == tau_ticks) at_tau = f;
  }
  EXPECT_NEAR(at_tau, -0.3 * (1.0 - std::exp(-1.0)), 0.01) << "first order with τ";
  EXPECT_NEAR(previous, -0.3, 0.3 * 0.01);
  // A host whose friction jumps by 0.9 N moves the force by at most the step bound per tick.
  const ContactProxy jumped = friction_proxy(3, Eigen::Vector3d::Zero(), Eigen::Vector3d(0.6, 0.0, 0.0));
  for (int i = 0; i < 20; ++i) {
    const double f = tick(state, jumped, tool_at(0.0), floor_load(), DeviceMapping{}, kWithWalk).force_world_n.force_world_n[0].x();
    EXPECT_LE(std::abs(f - previous), kDefaultFrictionMaxStep_n + 1e-12) << "tick " << i;
    previous = f;
  }
}

TEST(FrictionCone, ACycleOfTheHandNeverGainsEnergyFromFriction) {
  // Work the friction force does on the hand over closed loops, stick and slide: ≤ 0 (Coulomb
  // friction with a stick spring only dissipates), counted with the force held over each step
  // as a sampled device holds it.
  FrictionState state;
  const ContactProxy proxy = friction_proxy(1, Eigen::Vector3d::Zero());
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  Eigen::Vector3d held_force = Eigen::Vector3d::Zero();
  double work_on_hand_j = 0.0;
  for (int i = 0; i <= 4000; ++i) {
    const double phase = 2.0 * M_PI * i / 1000.0;
    const Eigen::Vector3d p(2e-3 * std::sin(phase), 0.0, 1e-3 * std::sin(2.0 * phase));
    work_on_hand_j += held_force.dot(p - previous);
    previous = p;
    // The normal force breathes with the loop: the cone widens and narrows under the anchor.
    held_force = tick(state, proxy, tool_at(p.x(), p.y(), p.z()), floor_load(kNormal_n * (1.0 + 0.5 * std::cos(phase))))
                     .force_world_n.force_world_n[0];
  }
  // The stick spring may still hold energy it gives back; that is bounded by ½·(μ_s F_n)²/K.
  const double spring_bound_j = 0.5 * std::pow(kMuStatic * 1.5 * kNormal_n, 2) / kStickStiffness_n_per_m;
  EXPECT_LT(work_on_hand_j, spring_bound_j);
  EXPECT_LT(work_on_hand_j, -0.005) << "four loops of ±2 mm at ~0.8 N dissipate several mJ";
}

TEST(FrictionCone, LiftingOffDropsTheAnchorAndTheNextContactStartsFresh) {
  FrictionState state;
  const ContactProxy proxy = friction_proxy(1, Eigen::Vector3d::Zero());
  tick(state, proxy, tool_at(0.0));
  tick(state, proxy, tool_at(3e-4));
  FrictionEvaluation e = tick(state, proxy, tool_at(3e-4), PartNormalLoad{});
  EXPECT_FALSE(state.anchored[0]);
  EXPECT_EQ(e.force_world_n.force_world_n[0], Eigen::Vector3d::Zero());
  // Touching down again on the same proxy re-seats at its reference: the spring from there.
  e = tick(state, proxy, tool_at(3e-4));
  EXPECT_NEAR(e.force_world_n.force_world_n[0].x(), -0.3, 1e-12);
}

TEST(FrictionCone, NoFlagNoMuOrZeroStiffnessRenderNothing) {
  FrictionState state;
  ContactProxy unflagged = friction_proxy(1, Eigen::Vector3d::Zero(), Eigen::Vector3d(-0.3, 0.0, 0.0));
  unflagged.flags = kProxyValid;
  const ContactProxy frictionless = friction_proxy(2, Eigen::Vector3d::Zero(), Eigen::Vector3d(-0.3, 0.0, 0.0),
                                                   Eigen::Vector3d::Zero(), ToolPart::kTool, 0.0, 0.0);
  const ContactProxy normal = friction_proxy(3, Eigen::Vector3d::Zero(), Eigen::Vector3d(-0.3, 0.0, 0.0));
  for (int i = 0; i < 10; ++i) {
    EXPECT_EQ(tick(state, unflagged, tool_at(1e-3 * i)).force_world_n.force_world_n[0], Eigen::Vector3d::Zero());
    EXPECT_EQ(tick(state, frictionless, tool_at(1e-3 * i)).force_world_n.force_world_n[0], Eigen::Vector3d::Zero());
    FrictionModel no_stiffness = kConeOnly;
    no_stiffness.stick_stiffness_world_n_per_m = 0.0;
    const FrictionEvaluation off = evaluate_friction(no_stiffness, state, normal, floor_load(), DeviceMapping{}, tool_at(1e-3 * i));
    EXPECT_EQ(off.force_world_n.force_world_n[0], Eigen::Vector3d::Zero());
  }
}

TEST(FrictionCone, NonFiniteInputGivesZeroForceAndDropsTheAnchor) {
  FrictionState state;
  const ContactProxy proxy = friction_proxy(1, Eigen::Vector3d::Zero());
  tick(state, proxy, tool_at(0.0));
  PartNormalLoad bad = floor_load();
  bad.elastic_sum_n[0] = std::numeric_limits<double>::quiet_NaN();
  FrictionEvaluation e = tick(state, proxy, tool_at(1e-4), bad);
  EXPECT_EQ(e.force_world_n.force_world_n[0], Eigen::Vector3d::Zero());
  EXPECT_FALSE(state.anchored[0]);
  e = tick(state, proxy, tool_at(std::numeric_limits<double>::infinity()));
  EXPECT_EQ(e.force_world_n.force_world_n[0], Eigen::Vector3d::Zero());
  ContactProxy nan_velocity = friction_proxy(2, Eigen::Vector3d::Zero());
  nan_velocity.friction[0].surface_velocity_world_m_per_s[0] = std::numeric_limits<double>::quiet_NaN();
  e = tick(state, nan_velocity, tool_at(1e-4));
  EXPECT_EQ(e.force_world_n.force_world_n[0], Eigen::Vector3d::Zero());
  EXPECT_FALSE(state.anchored[0]);
}

TEST(FrictionCone, EachClampJawHasItsOwnAnchorAndTheyHoldTwiceMuTimesTheGrip) {
  DeviceMapping clamp;
  clamp.clamp_mode = true;
  clamp.closing_axis_world = 2;
  PartNormalLoad load;
  // Jaw A (−z side) is pushed towards −z by the tissue between the jaws, jaw B towards +z.
  load.elastic_force_world_n[1] = Eigen::Vector3d(0.0, 0.0, -kNormal_n);
  load.elastic_force_world_n[2] = Eigen::Vector3d(0.0, 0.0, kNormal_n);
  load.elastic_sum_n[1] = load.elastic_sum_n[2] = kNormal_n;
  ContactProxy proxy = friction_proxy(1, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), ToolPart::kJawA);
  proxy.flags |= proxy_friction_bit(ToolPart::kJawB);
  proxy.friction[2] = proxy.friction[1];
  FrictionState state;
  // The clamp rises 5 mm along y through tissue that stays: both jaws slide, each at μ_k·F_n, down.
  FrictionEvaluation e;
  for (int i = 0; i <= 500; ++i) e = tick(state, proxy, tool_at(0.0, 1e-5 * i), load, clamp);
  EXPECT_EQ(e.parts_sliding, 2);
  EXPECT_NEAR(e.force_world_n.force_world_n[1].y(), -kMuKinetic * kNormal_n, 1e-12);
  EXPECT_NEAR(e.force_world_n.force_world_n[2].y(), -kMuKinetic * kNormal_n, 1e-12);
  EXPECT_EQ(e.force_world_n.force_world_n[0], Eigen::Vector3d::Zero());
  const Eigen::Vector3d device = part_forces_to_device(clamp, e.force_world_n);
  EXPECT_NEAR(device.norm(), 2.0 * kMuKinetic * kNormal_n * clamp.force_scale, 1e-9);
}

TEST(FrictionCone, TheProxyGivesEachPartItsElasticNormalForce) {
  ContactProxy proxy;
  proxy.flags = kProxyValid;
  proxy.patch_count = 2;
  for (int i = 0; i < 2; ++i) {
    ContactPatch& p = proxy.patches[static_cast<std::size_t>(i)];
    p.plane_point_world_m = {0.0, 0.002 * (i + 1), 0.0};  // 2 mm and 4 mm deep
    p.normal_world = {0.0, 1.0, 0.0};
    p.stiffness_k = 500.0;
    p.damping_lambda = 100.0;
    p.exponent_n = 1.0;
  }
  ToolState tool;
  tool.v_tool_world_m_per_s = Eigen::Vector3d(0.0, -0.1, 0.0);  // damping on: not in the load
  PartForces forces;
  PartNormalLoad load;
  evaluate_proxy(proxy, DeviceMapping{}, tool, forces, DampingCap{}, &load);
  EXPECT_NEAR(load.elastic_force_world_n[0].y(), 500.0 * 0.002 + 500.0 * 0.004, 1e-12);
  EXPECT_NEAR(load.elastic_sum_n[0], 3.0, 1e-12);
  EXPECT_GT(forces.force_world_n[0].y(), load.elastic_force_world_n[0].y());
}

}  // namespace
}  // namespace fissure::rt
