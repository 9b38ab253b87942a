// Proxy builder: the proxy, evaluated by rt_core's own evaluate_proxy at the host's part positions
// and speeds, reproduces the host's force (issue 6: within 1 %), on synthetic contact sets and on
// every paper scene's host simulation.
#include "fissure/host_sim/proxy_builder.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "../falcon_hw/allocation_counter.hpp"
#include "fissure/host_sim/host_simulation.hpp"
#include "fissure/host_sim/proxy_model.hpp"
#include "fissure/host_sim/scene_loader.hpp"
#include "fissure/shared/device_mapping.hpp"
#include "fissure/rt_core/hunt_crossley.hpp"
#include "fissure/rt_core/proxy_intake.hpp"
#include "fissure/shared/message_validation.hpp"

namespace fissure::host {
namespace {

constexpr double kRelativeTolerance = 0.01;  // issue 6: within 1 % of the host force

// A host-side Hunt-Crossley record exactly as hunt_crossley_force.cpp writes it.
ContactRecord make_record(const HuntCrossleyParams& hc, int jaw, int plane, const Eigen::Vector3d& face_normal_world,
                          double x, double x_dot, double weight) {
  ContactRecord r;
  r.jaw = jaw;
  r.tool_plane = plane;
  r.normal_world = face_normal_world.normalized();
  r.penetration_m = x;
  r.penetration_rate_m_s = x_dot;
  r.weight = weight;
  const double x_n = std::pow(x, hc.n);
  r.force_n = std::max(0.0, weight * (hc.k * x_n + hc.lambda * x_n * x_dot));
  return r;
}

Eigen::Vector3d host_force(const std::vector<ContactRecord>& records) {
  Eigen::Vector3d f = Eigen::Vector3d::Zero();
  for (const ContactRecord& r : records) f -= r.force_n * r.normal_world;
  return f;
}

// Everything the rt side needs to evaluate a proxy at one tool state.
struct RtSide {
  DeviceMapping mapping{};
  ToolState tool{};

  [[nodiscard]] ProxyPartMotion parts() const {
    ProxyPartMotion m;
    for (ToolPart part : {ToolPart::kTool, ToolPart::kJawA, ToolPart::kJawB}) {
      const PartMotion pm = part_motion(mapping, tool, part);
      m.p_world_m[static_cast<std::size_t>(part)] = pm.p_world_m;
      m.v_world_m_per_s[static_cast<std::size_t>(part)] = pm.v_world_m_per_s;
    }
    return m;
  }
  [[nodiscard]] PartForces evaluate(const ContactProxy& proxy) const {
    PartForces forces;
    rt::evaluate_proxy(proxy, mapping, tool, forces);
    return forces;
  }
  [[nodiscard]] Eigen::Vector3d total(const ContactProxy& proxy) const {
    const PartForces f = evaluate(proxy);
    return f.force_world_n[0] + f.force_world_n[1] + f.force_world_n[2];
  }
};

void expect_within_one_percent(const Eigen::Vector3d& rt_force, const Eigen::Vector3d& host, const std::string& what) {
  const double error = (rt_force - host).norm();
  EXPECT_LE(error, kRelativeTolerance * host.norm() + 1e-9)
      << what << ": rt " << rt_force.transpose() << " host " << host.transpose();
}

ProxyBuilderModel spatula_model(const HuntCrossleyParams& hc, int planes = 6) {
  ProxyBuilderModel model;
  model.hunt_crossley = hc;
  model.plane_count = {planes, 0};
  model.jaw_count = 1;
  return model;
}

TEST(ProxyBuilder, FlatContactSetIsTheHostLawExactlyAtAndAroundTheHostPose) {
  HuntCrossleyParams hc;
  hc.k = 1.0e7;
  hc.lambda = 1.0e6;
  hc.n = 1.5;
  // Spatula pressing down (its bottom face, normal −y) 4 mm into a flat slab: 20 triangles of
  // 1 cm² each, all with the same depth; the tool moves down at 5 cm/s, the host's filtered rate
  // equals the tool speed.
  const Eigen::Vector3d face_normal(0.0, -1.0, 0.0);
  const double depth = 0.004;
  const double speed = 0.05;
  std::vector<ContactRecord> records;
  for (int i = 0; i < 20; ++i) records.push_back(make_record(hc, 0, 2, face_normal, depth, speed, 1.0e-4));
  RtSide rt;
  rt.tool.p_tool_world_m = Eigen::Vector3d(0.01, 0.09, -0.02);
  rt.tool.v_tool_world_m_per_s = Eigen::Vector3d(0.0, -speed, 0.0);
  ProxyBuilder builder(spatula_model(hc));
  ContactProxy proxy;
  builder.build(records, ToolPose{}, rt.parts(), 1'000'000, proxy);

  ASSERT_EQ(validate(proxy), ProxyError::kNone);
  ASSERT_EQ(proxy.patch_count, 1);
  EXPECT_NEAR(proxy.patches[0].exponent_n, 1.5, 0.0);
  EXPECT_NEAR(proxy.patches[0].normal_world[1], 1.0, 1e-12);  // pushes the tool up
  expect_within_one_percent(rt.total(proxy), host_force(records), "at the host pose");
  // The same law when the tool goes 1 mm deeper (and when it is at rest): k·Σw·xⁿ, λ·Σw.
  rt.tool.p_tool_world_m.y() -= 0.001;
  const double deeper = 20 * 1.0e-4 * (hc.k * std::pow(depth + 0.001, 1.5) + hc.lambda * std::pow(depth + 0.001, 1.5) * speed);
  EXPECT_NEAR(rt.total(proxy).y(), deeper, 1e-9 * deeper);
  rt.tool.v_tool_world_m_per_s.setZero();
  const double at_rest = 20 * 1.0e-4 * hc.k * std::pow(depth + 0.001, 1.5);
  EXPECT_NEAR(rt.total(proxy).y(), at_rest, 1e-9 * at_rest);
}

TEST(ProxyBuilder, MixedDepthsRatesAndFacesReproduceTheHostForceAtTheHostSpeed) {
  std::mt19937 rng(7);  // fixed seed
  std::uniform_real_distribution<double> depth(0.0, 0.008);
  std::uniform_real_distribution<double> rate(-0.2, 0.2);
  std::uniform_real_distribution<double> area(2.0e-5, 2.0e-4);
  std::uniform_real_distribution<double> velocity(-0.15, 0.15);
  HuntCrossleyParams hc;
  hc.k = 2.0e6;
  hc.lambda = 3.0e5;
  hc.n = 1.5;
  // Six faces of a box tool (outward normals ±x, ±y, ±z).
  const std::array<Eigen::Vector3d, 6> faces{Eigen::Vector3d::UnitX(), -Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                             -Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitZ()};
  ProxyBuilder builder(spatula_model(hc));
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<ContactRecord> records;
    const int used_faces = 1 + trial % 3;
    for (int f = 0; f < used_faces; ++f) {
      for (int i = 0; i < 12; ++i) {
        records.push_back(make_record(hc, 0, (f * 2 + trial) % 6, faces[static_cast<std::size_t>((f * 2 + trial) % 6)],
                                      depth(rng), rate(rng), area(rng)));
      }
    }
    RtSide rt;
    rt.tool.p_tool_world_m = Eigen::Vector3d(0.0, 0.1, 0.0);
    rt.tool.v_tool_world_m_per_s = Eigen::Vector3d(velocity(rng), velocity(rng), velocity(rng));
    ContactProxy proxy;
    builder.build(records, ToolPose{}, rt.parts(), trial, proxy);
    ASSERT_EQ(validate(proxy), ProxyError::kNone) << "trial " << trial;
    EXPECT_EQ(proxy.patch_count, used_faces);
    // Per patch the force matches; the per-face host sums are what the patches stand for.
    const PartForces forces = rt.evaluate(proxy);
    expect_within_one_percent(forces.force_world_n[0], host_force(records), "trial " + std::to_string(trial));
  }
}

TEST(ProxyBuilder, RetreatingFasterThanTheHostDampingAllowsStillMatches) {
  // Host: half the triangles' forces clamped to zero (pulled back fast), the tool itself moving
  // in — the case where k would go negative and λ carries the force instead.
  HuntCrossleyParams hc;
  hc.k = 1.0e6;
  hc.lambda = 1.0e6;  // k/λ = 1 m/s
  hc.n = 1.0;
  const Eigen::Vector3d face(0.0, -1.0, 0.0);
  std::vector<ContactRecord> records;
  for (int i = 0; i < 5; ++i) records.push_back(make_record(hc, 0, 0, face, 0.003, -2.0, 1e-4));  // clamped to 0
  for (int i = 0; i < 5; ++i) records.push_back(make_record(hc, 0, 0, face, 0.001, 0.0, 1e-4));
  ProxyBuilder builder(spatula_model(hc, 1));
  for (const double tool_speed_down : {-3.0, -0.5, 0.0, 0.5, 3.0}) {
    RtSide rt;
    rt.tool.v_tool_world_m_per_s = Eigen::Vector3d(0.0, -tool_speed_down, 0.0);
    ContactProxy proxy;
    builder.build(records, ToolPose{}, rt.parts(), 0, proxy);
    ASSERT_EQ(validate(proxy), ProxyError::kNone);
    EXPECT_GE(proxy.patches[0].stiffness_k, 0.0);
    EXPECT_GE(proxy.patches[0].damping_lambda, 0.0);
    expect_within_one_percent(rt.total(proxy), host_force(records), "tool speed " + std::to_string(tool_speed_down));
  }
}

TEST(ProxyBuilder, TouchingWithoutDepthGivesZeroNowAndTheHostLawWhenPushed) {
  HuntCrossleyParams hc;
  hc.k = 1.0e7;
  hc.lambda = 0.0;
  hc.n = 1.5;
  std::vector<ContactRecord> records;
  for (int i = 0; i < 4; ++i) records.push_back(make_record(hc, 0, 3, Eigen::Vector3d(0.0, -1.0, 0.0), 0.0, 0.0, 1e-4));
  RtSide rt;
  ProxyBuilder builder(spatula_model(hc));
  ContactProxy proxy;
  builder.build(records, ToolPose{}, rt.parts(), 0, proxy);
  ASSERT_EQ(proxy.patch_count, 1);
  EXPECT_EQ(rt.total(proxy).norm(), 0.0);
  rt.tool.p_tool_world_m.y() = -0.002;
  EXPECT_NEAR(rt.total(proxy).y(), 4e-4 * hc.k * std::pow(0.002, 1.5), 1e-9);
}

TEST(ProxyBuilder, ClampJawsGetTheirOwnPatchesOnTheirOwnParts) {
  HuntCrossleyParams hc;
  hc.k = 1.0e7;
  hc.lambda = 1.0e6;
  hc.n = 1.5;
  ProxyBuilderModel model;
  model.hunt_crossley = hc;
  model.jaw_count = 2;
  model.plane_count = {6, 6};
  model.part_of_jaw = {ToolPart::kJawB, ToolPart::kJawA};  // host jaw 0 is on +z = +e_c
  RtSide rt;
  rt.mapping.clamp_mode = true;
  rt.mapping.closing_axis_world = 2;
  rt.tool.p_tool_world_m = Eigen::Vector3d(0.0, 0.06, 0.0);
  rt.tool.jaw_closing_m = 0.02;
  rt.tool.jaw_closing_rate_m_per_s = 0.02;
  // Jaw 0 (+z side) squeezes with its inner face (outward normal −z): force on it +z; jaw 1 mirror.
  std::vector<ContactRecord> records;
  for (int i = 0; i < 8; ++i) records.push_back(make_record(hc, 0, 1, Eigen::Vector3d(0, 0, -1), 0.002 + 1e-4 * i, 0.01, 1e-4));
  for (int i = 0; i < 6; ++i) records.push_back(make_record(hc, 1, 0, Eigen::Vector3d(0, 0, 1), 0.003 - 1e-4 * i, 0.01, 1e-4));
  ProxyBuilder builder(model);
  ContactProxy proxy;
  builder.build(records, ToolPose{}, rt.parts(), 0, proxy);
  ASSERT_EQ(validate(proxy), ProxyError::kNone);
  ASSERT_EQ(proxy.patch_count, 2);
  const PartForces forces = rt.evaluate(proxy);
  const std::vector<ContactRecord> jaw0(records.begin(), records.begin() + 8);
  const std::vector<ContactRecord> jaw1(records.begin() + 8, records.end());
  expect_within_one_percent(forces.force_world_n[static_cast<std::size_t>(ToolPart::kJawB)], host_force(jaw0), "jaw 0");
  expect_within_one_percent(forces.force_world_n[static_cast<std::size_t>(ToolPart::kJawA)], host_force(jaw1), "jaw 1");
  EXPECT_EQ(forces.force_world_n[0].norm(), 0.0);
  // Closing further (jaws move towards each other) squeezes harder on both.
  rt.tool.jaw_closing_m += 0.001;
  const PartForces tighter = rt.evaluate(proxy);
  EXPECT_GT(tighter.force_world_n[2].z(), forces.force_world_n[2].z());
  EXPECT_LT(tighter.force_world_n[1].z(), forces.force_world_n[1].z());
}

TEST(ProxyBuilder, MoreThanEightFacesAreMergedKeepingTheTotalForce) {
  // A convex rim: 16 planes whose normals fan over 90°, all contacted.
  HuntCrossleyParams hc;
  hc.k = 5.0e6;
  hc.lambda = 2.0e5;
  hc.n = 1.5;
  std::vector<ContactRecord> records;
  for (int p = 0; p < 16; ++p) {
    const double angle = 0.5 * M_PI * p / 15.0;
    const Eigen::Vector3d normal(std::cos(angle), -std::sin(angle), 0.0);
    for (int i = 0; i < 3; ++i) records.push_back(make_record(hc, 0, p, normal, 0.001 + 0.0002 * (p % 5) + 1e-4 * i, 0.02, 5e-5));
  }
  RtSide rt;
  rt.tool.v_tool_world_m_per_s = Eigen::Vector3d(-0.01, 0.03, 0.0);
  ProxyBuilder builder(spatula_model(hc, 16));
  ContactProxy proxy;
  const ProxyBuildReport& report = builder.build(records, ToolPose{}, rt.parts(), 0, proxy);
  ASSERT_EQ(validate(proxy), ProxyError::kNone);
  EXPECT_EQ(proxy.patch_count, kMaxContactPatches);
  EXPECT_EQ(report.groups, 16);
  EXPECT_EQ(report.merged_groups, 8);
  EXPECT_EQ(report.dropped_groups, 0);
  expect_within_one_percent(rt.total(proxy), host_force(records), "merged rim");
}

TEST(ProxyBuilder, ProxyCarriesSequenceTimeReferencePoseAndFlags) {
  HuntCrossleyParams hc;
  ProxyBuilder builder(spatula_model(hc));
  ToolPose pose;
  pose.position_world_m = Eigen::Vector3d(0.1, 0.2, 0.3);
  pose.orientation_world = Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitX()));
  RtSide rt;
  ContactProxy proxy;
  builder.build({}, pose, rt.parts(), 5, proxy);
  EXPECT_EQ(proxy.sequence, 1u);
  EXPECT_EQ(proxy.patch_count, 0);
  EXPECT_EQ(proxy.flags, static_cast<std::uint32_t>(kProxyValid));
  const std::vector<ContactRecord> records{make_record(hc, 0, 2, Eigen::Vector3d(0, -1, 0), 0.001, 0.0, 1e-4)};
  builder.build(records, pose, rt.parts(), 7, proxy);
  EXPECT_EQ(proxy.sequence, 2u);
  EXPECT_EQ(proxy.host_time_ns, 7);
  EXPECT_EQ(proxy.flags, static_cast<std::uint32_t>(kProxyValid | kProxyHostInContact));
  EXPECT_EQ(proxy.patches[0].reference_time_ns, 7);
  EXPECT_EQ(proxy.patches[0].reference_tool_position_world_m, (Vec3{0.1, 0.2, 0.3}));
  EXPECT_NEAR(proxy.patches[0].reference_tool_orientation_world[0], std::cos(0.25), 1e-12);
  EXPECT_NEAR(proxy.patches[0].reference_tool_orientation_world[1], std::sin(0.25), 1e-12);
}

TEST(ProxyBuilder, RecordsOutsideTheModelAreSkippedAndCounted) {
  HuntCrossleyParams hc;
  ProxyBuilder builder(spatula_model(hc, 2));
  std::vector<ContactRecord> records{make_record(hc, 0, 5, Eigen::Vector3d(0, -1, 0), 0.001, 0.0, 1e-4),
                                     make_record(hc, 1, 0, Eigen::Vector3d(0, -1, 0), 0.001, 0.0, 1e-4),
                                     make_record(hc, 0, 1, Eigen::Vector3d(0, -1, 0), 0.001, 0.0, 1e-4)};
  records[2].penetration_m = std::nan("");
  ContactProxy proxy;
  const ProxyBuildReport& report = builder.build(records, ToolPose{}, RtSide{}.parts(), 0, proxy);
  EXPECT_EQ(report.skipped_records, 3);
  EXPECT_EQ(proxy.patch_count, 0);
}

TEST(ProxyBuilder, RejectsABadModel) {
  ProxyBuilderModel model;
  model.jaw_count = 3;
  EXPECT_THROW(ProxyBuilder{model}, std::invalid_argument);
  model.jaw_count = 1;
  model.hunt_crossley.n = 0.0;
  EXPECT_THROW(ProxyBuilder{model}, std::invalid_argument);
  model.hunt_crossley.n = 1.5;
  model.plane_count = {-1, 0};
  EXPECT_THROW(ProxyBuilder{model}, std::invalid_argument);
}

TEST(ProxyBuilder, BuildDoesNotAllocate) {
  HuntCrossleyParams hc;
  std::vector<ContactRecord> records;
  for (int p = 0; p < 12; ++p) records.push_back(make_record(hc, 0, p, Eigen::Vector3d(std::cos(p * 0.1), -1, 0), 0.002, 0.01, 1e-4));
  ProxyBuilder builder(spatula_model(hc, 12));
  ContactProxy proxy;
  const ProxyPartMotion parts = RtSide{}.parts();
  builder.build(records, ToolPose{}, parts, 0, proxy);
  const long before = testing::allocation_count();
  for (int i = 0; i < 100; ++i) builder.build(records, ToolPose{}, parts, i, proxy);
  EXPECT_EQ(testing::allocation_count(), before);
}

// ---- Paper scenes: the real host contact sets. -------------------------------------------------

class PaperSceneProxy : public ::testing::TestWithParam<std::string> {};

// The host's in-solver friction on the tool, summed over its parts (zero without friction).
Eigen::Vector3d host_friction_n(const HostStepResult& step) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int p = 0; p < step.part_count; ++p) sum += step.part_results[static_cast<std::size_t>(p)].friction_force_on_tool_world_n;
  return sum;
}

TEST_P(PaperSceneProxy, RtEvaluationAtTheHostPoseIsWithinOnePercentOfTheHostForce) {
  const SceneDescription scene = load_scene(resolve_scene_path(GetParam()));
  HostSimulation sim(scene);
  sim.settle(0.2);
  const bool clamp = scene.tool.kind == ToolKind::kClamp;
  const ProxyBuilderModel model = proxy_model_for(scene, sim).value();
  ProxyBuilder builder(model);

  RtSide rt;
  rt.mapping = scene.device_mapping;
  const double dt = scene.simulation.time_step_s;
  const double duration = trajectory_duration_s(scene);
  TrajectorySample previous = sample_trajectory(scene, 0.0);
  int steps_in_contact = 0;
  double peak_force = 0.0;
  ContactProxy proxy;
  for (double t = dt; t <= duration + 1e-9; t += dt) {
    const TrajectorySample target = sample_trajectory(scene, t);
    ToolPose pose;
    pose.position_world_m = as_eigen(target.pose.position_world_m);
    const Quat& q = target.pose.orientation_world;
    pose.orientation_world = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
    const HostStepResult& step = sim.step(pose, target.jaw_gap_m);
    // rt's view of the same instant: tool at the host pose, speed of the scripted motion; a clamp's
    // closing is the gap change (closing = (open − gap)/scale, shared/device_mapping.hpp).
    rt.tool.p_tool_world_m = pose.position_world_m;
    rt.tool.v_tool_world_m_per_s = (pose.position_world_m - as_eigen(previous.pose.position_world_m)) / dt;
    if (clamp) {
      rt.tool.jaw_closing_m = (scene.tool.clamp.jaw_gap_open_m - step.jaw_gap_m) / rt.mapping.scale;
      rt.tool.jaw_closing_rate_m_per_s = (previous.jaw_gap_m - target.jaw_gap_m) / dt / rt.mapping.scale;
    }
    previous = target;
    builder.build(step.contacts, pose, rt.parts(), static_cast<TimeNs>(std::llround(step.time_s * 1e9)), proxy);
    ASSERT_EQ(validate(proxy), ProxyError::kNone) << "t = " << t;
    ASSERT_EQ(builder.last_report().dropped_groups, 0);
    const PartForces forces = rt.evaluate(proxy);
    Eigen::Vector3d host_total = Eigen::Vector3d::Zero();
    for (int jaw = 0; jaw < model.jaw_count; ++jaw) {
      const auto j = static_cast<std::size_t>(jaw);
      // The patch carries the normal (Hunt-Crossley) law; in-solver friction is rendered by
      // rt_core's friction cone from the part's friction state (bench grasp), not by the patch.
      const Eigen::Vector3d host_part = step.part_force_world_n[j] - step.part_results[j].friction_force_on_tool_world_n;
      host_total += host_part;
      const Eigen::Vector3d rt_part = forces.force_world_n[static_cast<std::size_t>(model.part_of_jaw[j])];
      if (clamp) expect_within_one_percent(rt_part, host_part, GetParam() + " jaw " + std::to_string(jaw) + " t=" + std::to_string(t));
    }
    EXPECT_LE((host_total + host_friction_n(step) - step.force_on_tool_world_n).norm(), 1e-9 * (1.0 + host_total.norm()));
    expect_within_one_percent(forces.force_world_n[0] + forces.force_world_n[1] + forces.force_world_n[2], host_total,
                              GetParam() + " t=" + std::to_string(t));
    if (step.contact_count > 0) ++steps_in_contact;
    peak_force = std::max(peak_force, host_total.norm());
    for (int part = 0; part < step.part_count; ++part) peak_force = std::max(peak_force, step.part_force_world_n[static_cast<std::size_t>(part)].norm());
    if (::testing::Test::HasFailure()) break;
  }
  // The scene must actually exercise contact (otherwise the comparison says nothing): the tool's
  // force or a jaw's (a clamp's jaws push opposite ways, so its total is their small difference:
  // on clamp-vessel's round vessel the total peaks at 0.18 N, one jaw at 2.1 N).
  EXPECT_GT(steps_in_contact, 50) << GetParam();
  EXPECT_GT(peak_force, 0.5) << GetParam();
}

// Between host updates rt_core evaluates the proxy away from its reference pose and time. Here
// the host steps at the scene's rate (1 kHz) along its scripted trajectory, but rt_core only gets
// every 10th proxy (a 100 Hz host, issue 6's 2 % row) through its own intake (take_latest_proxy)
// and evaluates it at each 1 kHz step's pose and speed; the host's own force at that step is the
// truth. A proxy frozen at its reference pose misses how the soft body keeps moving under a still
// tool (measured: ~20 N/s on spatula-sphere after the press).
struct HeldProxyError {
  double rms_n = 0.0;
  double peak_host_n = 0.0;
  double peak_part_n = 0.0;  ///< the largest force on one part (a clamp's jaw)
  int steps_in_contact = 0;
};

HeldProxyError held_proxy_error(const std::string& scene_name, int steps_per_proxy) {
  const SceneDescription scene = load_scene(resolve_scene_path(scene_name));
  HostSimulation sim(scene);
  sim.settle(0.2);
  const bool clamp = scene.tool.kind == ToolKind::kClamp;
  const ProxyBuilderModel model = proxy_model_for(scene, sim).value();
  ProxyBuilder builder(model);
  auto exchange = std::make_unique<ProxyExchange>();
  auto state = std::make_unique<rt::ProxyState>();

  RtSide rt;
  rt.mapping = scene.device_mapping;
  const double dt = scene.simulation.time_step_s;
  const int steps = static_cast<int>(std::floor(trajectory_duration_s(scene) / dt + 1e-9));
  TrajectorySample previous = sample_trajectory(scene, 0.0);
  HeldProxyError result;
  double sum_sq = 0.0;
  int compared = 0;
  ContactProxy proxy;
  for (int i = 1; i <= steps; ++i) {
    const double t = i * dt;
    const TrajectorySample target = sample_trajectory(scene, t);
    ToolPose pose;
    pose.position_world_m = as_eigen(target.pose.position_world_m);
    const Quat& q = target.pose.orientation_world;
    pose.orientation_world = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
    const HostStepResult& step = sim.step(pose, target.jaw_gap_m);
    rt.tool.p_tool_world_m = pose.position_world_m;
    rt.tool.v_tool_world_m_per_s = (pose.position_world_m - as_eigen(previous.pose.position_world_m)) / dt;
    if (clamp) {
      rt.tool.jaw_closing_m = (scene.tool.clamp.jaw_gap_open_m - step.jaw_gap_m) / rt.mapping.scale;
      rt.tool.jaw_closing_rate_m_per_s = (previous.jaw_gap_m - target.jaw_gap_m) / dt / rt.mapping.scale;
    }
    previous = target;
    const auto now_ns = static_cast<TimeNs>(std::llround(step.time_s * 1e9));
    // rt_core's view of this step, with the proxy it holds (built up to steps_per_proxy − 1 steps ago).
    rt::take_latest_proxy(*exchange, *state, now_ns);
    if (state->have_proxy) {
      // The normal law only, as above: in-solver friction goes to rt_core's friction cone.
      const Eigen::Vector3d error = rt.total(rt::active_proxy(*state)) - (step.force_on_tool_world_n - host_friction_n(step));
      sum_sq += error.squaredNorm();
      ++compared;
    }
    if (i % steps_per_proxy == 0) {
      builder.build(step.contacts, pose, rt.parts(), now_ns, proxy);
      exchange->publish(proxy);
    }
    if (step.contact_count > 0) ++result.steps_in_contact;
    result.peak_host_n = std::max(result.peak_host_n, step.force_on_tool_world_n.norm());
    for (int part = 0; part < step.part_count; ++part) result.peak_part_n = std::max(result.peak_part_n, step.part_force_world_n[static_cast<std::size_t>(part)].norm());
  }
  result.rms_n = compared > 0 ? std::sqrt(sum_sq / compared) : 0.0;
  return result;
}

// Stated tolerance: the proxy held over a 100 Hz host period, with rt_core's default intake,
// stays within 2 % RMS (of the peak host force) of the host's own force at every displaced pose
// (issue 6's 100 Hz target, here for the proxy model alone). For a clamp the peak is the larger of
// the total's and one jaw's: the hand feels a jaw's squeeze on the closing axis, while the total
// is the small difference of two opposing jaw forces (on clamp-vessel's round vessel 0.18 N
// against 2.08 N on one jaw), and 2 % of that difference would hold the proxy to 4 mN.
constexpr double kHeldProxyRmsTolerance = 0.02;

TEST_P(PaperSceneProxy, ProxyHeldOverAHundredHertzPeriodTracksTheHostForceAtTheDisplacedPose) {
  const int steps_per_proxy = 10;  // 1 kHz host steps per proxy: a 100 Hz host
  const HeldProxyError held = held_proxy_error(GetParam(), steps_per_proxy);
  const double peak_n = std::max(held.peak_host_n, held.peak_part_n);
  ASSERT_GT(held.steps_in_contact, 50) << GetParam();
  ASSERT_GT(peak_n, 0.5) << GetParam();
  std::printf("%s: held 10 ms: rms %.4f N, %.3f %% of peak %.3f N (total's peak %.3f N, one part's %.3f N)\n", GetParam().c_str(), held.rms_n,
              100.0 * held.rms_n / peak_n, peak_n, held.peak_host_n, held.peak_part_n);
  EXPECT_LE(held.rms_n, kHeldProxyRmsTolerance * peak_n) << GetParam();
}

INSTANTIATE_TEST_SUITE_P(Scenes, PaperSceneProxy,
                         ::testing::Values("spatula-sphere", "convex-spatula-sphere", "clamp-sphere", "clamp-vessel"),
                         [](const ::testing::TestParamInfo<std::string>& param_info) {
                           std::string name = param_info.param;
                           for (char& c : name) c = c == '-' ? '_' : c;
                           return name;
                         });

}  // namespace
}  // namespace fissure::host
