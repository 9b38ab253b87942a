// The host half of a session (app/session_host.cpp): which DeviceStates move the tool how. The
// device position epoch (messages.hpp) decides sweep or re-seat: a position rt_core marks as not
// continuous with the last one (its encoder-jump/lost-count acceptance, the first sample after a
// device fault) re-seats the tool, a continuous one is swept to. States are published by hand
// into the exchange (no rt loop): every field is chosen, nothing depends on timing.
#include "fissure/session/session_host.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "fissure/host_sim/scene_loader.hpp"
#include "../host_sim/anchored_scene_fixture.hpp"

namespace fissure::session {
namespace {

constexpr double kSettle_s = 0.3;

using host::fixture::anchored_spatula_sphere;
using host::fixture::max_distance_m;

struct Host {
  explicit Host(const host::SceneDescription& s) : scene(s), session(scene) { session.settle(kSettle_s); }
  /// Publishes a DeviceState at the scene's device origin + offset with this epoch, then steps.
  const HostStatus& step(const Eigen::Vector3d& offset_device_m, std::uint8_t epoch) {
    DeviceState state;
    state.sequence = ++sequence;
    state.position_device_m = to_vec3(as_eigen(scene.device_mapping.device_origin_m) + offset_device_m);
    state.status_flags = with_position_epoch(kDeviceHomed | kDeviceSimulated, epoch);
    states.publish(state);
    return session.step(states, proxies);
  }
  [[nodiscard]] double tool_y() const { return session.simulation().tool_pose().position_world_m.y(); }

  host::SceneDescription scene;
  SessionHost session;
  DeviceStateExchange states;
  ProxyExchange proxies;
  std::uint64_t sequence = 0;
};

TEST(SessionHost, HoldsTheToolAtTheStartPoseUntilRtCoreAcceptedASample) {
  Host h(anchored_spatula_sphere());
  const double start_y = h.tool_y();
  // Epoch 0: position_device_m is not a reading (rt_core has accepted none yet).
  const HostStatus& status = h.step(Eigen::Vector3d(0.0, -0.08, 0.0), 0);
  EXPECT_EQ(h.tool_y(), start_y);
  EXPECT_EQ(status.tool_reseats, 0u);
  h.step(Eigen::Vector3d(0.0, 0.001, 0.0), 1);
  EXPECT_EQ(h.session.status().tool_reseats, 1u) << "the first accepted sample is re-seated to, not swept to";
  EXPECT_NEAR(h.tool_y(), start_y + 0.001, 1e-12);
}

// The stress case encoder_jumps in one step: the published position steps 10 cm down (the plate
// from 2 cm above the ball to inside it) with a new epoch, and back 0.1 s later with the next.
// Re-seated, the ball is not touched; the same step with the epoch unchanged (what the host did
// before the epoch existed) sweeps the plate through the ball's top and drags it down.
TEST(SessionHost, ANewPositionEpochReseatsTheToolAContinuousOneSweepsIt) {
  const host::SceneDescription scene = anchored_spatula_sphere();
  const Eigen::Vector3d jump_device_m(0.0, -0.10, 0.0);
  Host reseat(scene);
  Host sweep(scene);
  for (int i = 0; i < 20; ++i) {
    reseat.step(Eigen::Vector3d::Zero(), 1);
    sweep.step(Eigen::Vector3d::Zero(), 1);
  }
  const std::vector<Eigen::Vector3d> before = reseat.session.simulation().node_positions_world_m();
  ASSERT_EQ(max_distance_m(before, sweep.session.simulation().node_positions_world_m()), 0.0);
  const HostStatus& jumped = reseat.step(jump_device_m, 2);
  (void)sweep.step(jump_device_m, 1);
  EXPECT_EQ(jumped.tool_reseats, 2u);
  EXPECT_EQ(jumped.crossed_nodes, 0);
  const double reseat_moved_m = max_distance_m(reseat.session.simulation().node_positions_world_m(), before);
  const double sweep_moved_m = max_distance_m(sweep.session.simulation().node_positions_world_m(), before);
  EXPECT_LT(reseat_moved_m, 1e-4) << "one step of the anchored, settled ball";
  EXPECT_GT(sweep_moved_m, 0.01) << "the swept plate drags the ball's top";
  int crossed_max = 0;
  for (int i = 0; i < 100; ++i) crossed_max = std::max(crossed_max, reseat.step(jump_device_m, 2).crossed_nodes);
  for (int i = 0; i < 100; ++i) crossed_max = std::max(crossed_max, reseat.step(Eigen::Vector3d::Zero(), 3).crossed_nodes);
  EXPECT_EQ(reseat.session.status().tool_reseats, 3u);
  EXPECT_EQ(crossed_max, 0);
  EXPECT_GT(reseat.session.status().soft_volume_ratio, 0.95);
  EXPECT_FALSE(reseat.session.status().soft_everted);
}

// A lost or reordered DeviceState cannot hide a discontinuity: the host compares epochs, so a
// jump whose first sample never arrived (epoch 2 lost, the next one seen carries 3) still re-seats.
TEST(SessionHost, ALostFirstSampleOfAnEpochStillReseats) {
  Host h(anchored_spatula_sphere());
  h.step(Eigen::Vector3d::Zero(), 1);
  h.step(Eigen::Vector3d(0.0, -0.10, 0.0), 3);
  EXPECT_EQ(h.session.status().tool_reseats, 2u);
  EXPECT_EQ(h.session.status().crossed_nodes, 0);
  // The epoch wraps 255 → 1: a change, whatever the values.
  h.step(Eigen::Vector3d::Zero(), 255);
  h.step(Eigen::Vector3d(0.0, -0.10, 0.0), 1);
  EXPECT_EQ(h.session.status().tool_reseats, 4u);
}

TEST(SessionHost, ARestartedRtCoreReseatsEvenWithTheSameEpoch) {
  Host h(anchored_spatula_sphere());
  h.step(Eigen::Vector3d::Zero(), 1);
  h.step(Eigen::Vector3d::Zero(), 1);
  EXPECT_EQ(h.session.status().tool_reseats, 1u);
  h.sequence = 0;  // a new rt_core process: its sequence and epochs start again
  h.step(Eigen::Vector3d(0.0, -0.10, 0.0), 1);
  EXPECT_EQ(h.session.status().tool_reseats, 2u);
  EXPECT_EQ(h.session.status().crossed_nodes, 0);
}

}  // namespace
}  // namespace fissure::session
