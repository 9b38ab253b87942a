// SimFalcon on the lockstep clock: dynamics against their analytic solutions, the motor
// force through the Jacobian, saturation, one tick of command latency, real encoder
// quantisation, the scripted hand and buttons, every injected fault, determinism, and no
// heap allocation in try_exchange().
#include "fissure/falcon_hw/sim_falcon.hpp"

#include <cmath>
#include <memory>
#include <stdexcept>
#include <vector>

#include <Eigen/LU>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "fissure/falcon_hw/kinematics.hpp"
#include "fissure/falcon_hw/motor_command.hpp"
#include "allocation_counter.hpp"

namespace fissure::falcon {
namespace {

constexpr TimeNs kTick_ns = 1'000'000;  // the 1 kHz ping-pong
const Eigen::Vector3d kCentre_device_m = as_eigen(kWorkspaceCentre_device_m);

Eigen::Vector3d true_position(const SimFalcon& sim) { return sim.truth().position_device_m; }

std::array<std::int16_t, 3> quantised_ik(const SimFalcon& sim, const Eigen::Vector3d& p_device_m) {
  Eigen::Vector3d theta_rad;
  EXPECT_TRUE(inverse_kinematics(sim.config().geometry, p_device_m, theta_rad));
  return theta_to_encoders(sim.config().encoder, theta_rad);
}

Eigen::Vector3d motor_force_at(const SimFalcon& sim, const Eigen::Vector3d& p_device_m,
                               const std::array<std::int16_t, 3>& counts) {
  Eigen::Matrix3d dp_dtheta;
  EXPECT_TRUE(jacobian(sim.config().geometry, p_device_m, dp_dtheta));
  const Eigen::Vector3d torque_nm = motor_counts_to_torque(counts, kDefaultNewtonMetrePerCount);
  return dp_dtheta.transpose().partialPivLu().solve(torque_nm);
}

// A hand that presses 2 cm down fast, holds, moves diagonally slowly, holds, and lets go.
HandScript press_and_slide_script() {
  HandScript script;
  script.start_position_device_m = {0.0, 0.0, 0.12};
  script.waypoints = {
      HandWaypoint{{0.0, -0.02, 0.12}, 0.5, 1.0},
      HandWaypoint{{0.02, 0.0, 0.13}, 0.1, 0.5},
  };
  script.button_events = {ButtonEvent{0.1005, 0x1}, ButtonEvent{0.5, 0x3}, ButtonEvent{1.25, 0x0}};
  script.grip_stiffness_n_per_m = 300.0;
  script.grip_damping_n_s_per_m = 5.0;
  script.release_at_end = true;
  return script;
}

SimFalconConfig hand_config() {
  SimFalconConfig config;
  config.hand = press_and_slide_script();
  return config;
}

TEST(SimFalcon, LooksLikeAFalconInItsRunningState) {
  LockstepClock clock;
  SimFalcon sim(SimFalconConfig{}, clock);
  EXPECT_STREQ(sim.name(), "sim-falcon");
  EXPECT_TRUE(true_position(sim).isApprox(kCentre_device_m));
  DeviceReading reading;
  clock.advance(kTick_ns);
  ASSERT_EQ(sim.try_exchange(DeviceCommand{}, reading), IoStatus::kOk);
  EXPECT_EQ(reading.homed_mask, 0x7);
  EXPECT_EQ(reading.buttons, 0);
  EXPECT_EQ(reading.receive_time_ns, kTick_ns);
  EXPECT_EQ(reading.encoder_counts, quantised_ik(sim, kCentre_device_m));
  EXPECT_EQ(sim.counters().sub_steps, 20);  // 20 kHz physics under a 1 kHz tick
  // At rest with nobody touching it and no gravity, it stays exactly where it is.
  EXPECT_EQ(true_position(sim), kCentre_device_m);
}

TEST(SimFalcon, ReportedEncodersAreTheQuantisedIkOfTheTruePosition) {
  LockstepClock clock;
  SimFalcon sim(hand_config(), clock);
  DeviceReading reading;
  double max_quantisation_error_m = 0.0;
  Eigen::Vector3d p_fk = kCentre_device_m;
  for (int k = 0; k < 1500; ++k) {
    clock.advance(kTick_ns);
    ASSERT_EQ(sim.try_exchange(DeviceCommand{}, reading), IoStatus::kOk);
    ASSERT_EQ(reading.encoder_counts, quantised_ik(sim, true_position(sim))) << "exchange " << k;
    // What rt_core would see: FK of the counts, which differs from the truth by quantisation.
    const Eigen::Vector3d theta_rad = encoders_to_theta(sim.config().encoder, reading.encoder_counts);
    ASSERT_TRUE(forward_kinematics(sim.config().geometry, theta_rad, p_fk, FkOptions{}).converged);
    max_quantisation_error_m = std::max(max_quantisation_error_m, (p_fk - true_position(sim)).norm());
  }
  // ≈ 0.05 mm per count at the centre (BRIEF §6): the error is real but bounded by a few counts.
  EXPECT_GT(max_quantisation_error_m, 5e-6);
  EXPECT_LT(max_quantisation_error_m, 2e-4);
}

TEST(SimFalcon, FreeMotionDecaysByTheDampingAsPredicted) {
  SimFalconConfig config;
  const Eigen::Vector3d v0(0.12, -0.08, 0.05);
  config.initial_velocity_device_m_per_s = to_vec3(v0);
  LockstepClock clock;
  SimFalcon sim(config, clock);
  const double m = config.dynamics.effective_mass_kg;
  const double b = config.dynamics.viscous_damping_n_s_per_m;
  const double tau_s = m / b;  // 50 ms at the defaults
  DeviceReading reading;
  for (int k = 1; k <= 300; ++k) {
    clock.advance(kTick_ns);
    ASSERT_EQ(sim.try_exchange(DeviceCommand{}, reading), IoStatus::kOk);
    const double t_s = k * 1e-3;
    const Eigen::Vector3d v_expected = v0 * std::exp(-t_s / tau_s);
    const Eigen::Vector3d p_expected = kCentre_device_m + v0 * tau_s * (1.0 - std::exp(-t_s / tau_s));
    ASSERT_LT((sim.truth().velocity_device_m_per_s - v_expected).norm(), 1e-12 + 1e-9 * v0.norm()) << "t " << t_s;
    // Semi-implicit position update: O(h) offset ≤ |v0|·h.
    ASSERT_LT((true_position(sim) - p_expected).norm(), v0.norm() * 5e-5) << "t " << t_s;
  }
  // After 6 time constants it has coasted v0·m/b and (almost) stopped.
  EXPECT_LT(sim.truth().velocity_device_m_per_s.norm(), v0.norm() * 3e-3);
  EXPECT_NEAR((true_position(sim) - kCentre_device_m).norm(), v0.norm() * tau_s, v0.norm() * tau_s * 3e-3);
}

TEST(SimFalcon, ConstantMotorCommandProducesTheJacobianForce) {
  LockstepClock clock;
  SimFalcon sim(SimFalconConfig{}, clock);
  const std::array<std::int16_t, 3> counts{1000, -500, 300};
  const Eigen::Vector3d expected_force_n = motor_force_at(sim, kCentre_device_m, counts);
  ASSERT_GT(expected_force_n.norm(), 0.5);

  DeviceReading reading;
  ASSERT_EQ(sim.try_exchange(DeviceCommand{counts}, reading), IoStatus::kOk);  // at t = 0, at rest
  const TimeNs dt_ns = 200'000;                                                // 0.2 ms later
  clock.advance(dt_ns);
  ASSERT_EQ(sim.try_exchange(DeviceCommand{counts}, reading), IoStatus::kOk);
  const double dt_s = to_seconds(dt_ns);
  const Eigen::Vector3d acceleration = sim.truth().velocity_device_m_per_s / dt_s;
  const Eigen::Vector3d expected_acceleration = expected_force_n / sim.config().dynamics.effective_mass_kg;
  // Damping removes b·dt/(2m) ≈ 0.2 % in 0.2 ms; the Jacobian barely changes over 0.3 µm.
  EXPECT_LT((acceleration - expected_acceleration).norm(), 0.005 * expected_acceleration.norm())
      << "a = " << acceleration.transpose() << ", F/m = " << expected_acceleration.transpose();
  EXPECT_TRUE(sim.truth().motor_force_device_n.isApprox(expected_force_n, 1e-4));
}

TEST(SimFalcon, RendersTheForceTheHostAskedForThroughForceToMotorCounts) {
  LockstepClock clock;
  SimFalcon sim(SimFalconConfig{}, clock);
  Eigen::Matrix3d dp_dtheta;
  ASSERT_TRUE(jacobian(sim.config().geometry, kCentre_device_m, dp_dtheta));
  for (const Eigen::Vector3d& force_n : {Eigen::Vector3d(2.0, 0.0, 0.0), Eigen::Vector3d(0.0, -1.5, 0.0),
                                         Eigen::Vector3d(0.0, 0.0, 3.0), Eigen::Vector3d(-1.0, 1.0, -1.0)}) {
    const MotorCommandResult command = force_to_motor_counts(dp_dtheta, force_n, kDefaultNewtonMetrePerCount);
    ASSERT_FALSE(command.saturated);
    DeviceReading reading;
    clock.advance(kTick_ns);
    ASSERT_EQ(sim.try_exchange(DeviceCommand{command.counts}, reading), IoStatus::kOk);
    clock.advance(1);  // one more nanosecond: one sub-step under the new command
    ASSERT_EQ(sim.try_exchange(DeviceCommand{command.counts}, reading), IoStatus::kOk);
    // Rounding to whole counts (≈ 1e-4 N·m each) is the only difference.
    EXPECT_LT((sim.truth().motor_force_device_n - force_n).norm(), 0.01) << force_n.transpose();
  }
}

TEST(SimFalcon, MotorTorqueSaturates) {
  LockstepClock clock;
  SimFalcon sim(SimFalconConfig{}, clock);
  DeviceReading reading;
  ASSERT_EQ(sim.try_exchange(DeviceCommand{{32767, -32768, 4095}}, reading), IoStatus::kOk);
  const Eigen::Vector3d limit_nm = motor_counts_to_torque({4095, -4095, 4095}, kDefaultNewtonMetrePerCount);
  EXPECT_TRUE(sim.truth().motor_torque_nm.isApprox(limit_nm, 1e-15));

  SimFalconConfig weak;
  weak.motors.max_motor_torque_nm = 0.1;
  LockstepClock clock2;
  SimFalcon weak_sim(weak, clock2);
  ASSERT_EQ(weak_sim.try_exchange(DeviceCommand{{4000, -4000, 200}}, reading), IoStatus::kOk);
  const Eigen::Vector3d torque_nm = weak_sim.truth().motor_torque_nm;
  EXPECT_DOUBLE_EQ(std::abs(torque_nm[0]), 0.1);
  EXPECT_DOUBLE_EQ(std::abs(torque_nm[1]), 0.1);
  EXPECT_NEAR(std::abs(torque_nm[2]), 200 * kDefaultNewtonMetrePerCount, 1e-15);
}

TEST(SimFalcon, ACommandShowsUpOnlyInTheNextReply) {
  LockstepClock clock_a;
  LockstepClock clock_b;
  SimFalcon pushed(SimFalconConfig{}, clock_a);
  SimFalcon untouched(SimFalconConfig{}, clock_b);
  const DeviceCommand push{{3000, 3000, 3000}};
  DeviceReading reading_a;
  DeviceReading reading_b;
  for (int k = 0; k < 10; ++k) {
    clock_a.advance(kTick_ns);
    clock_b.advance(kTick_ns);
    ASSERT_EQ(pushed.try_exchange(k < 5 ? DeviceCommand{} : push, reading_a), IoStatus::kOk);
    ASSERT_EQ(untouched.try_exchange(DeviceCommand{}, reading_b), IoStatus::kOk);
    if (k <= 5) {
      // Including exchange 5, whose own command cannot have acted yet.
      ASSERT_EQ(true_position(pushed), true_position(untouched)) << "exchange " << k;
      ASSERT_EQ(reading_a.encoder_counts, reading_b.encoder_counts) << "exchange " << k;
    } else {
      ASSERT_NE(true_position(pushed), true_position(untouched)) << "exchange " << k;
    }
  }
  // Within a few ticks the push is visible in the encoders too.
  EXPECT_NE(reading_a.encoder_counts, reading_b.encoder_counts);
}

TEST(SimFalcon, TheHandDrivesTheGripThroughTheWaypointsAndLetsGo) {
  LockstepClock clock;
  SimFalcon sim(hand_config(), clock);
  const HandScriptPlayer player(*sim.config().hand);
  DeviceReading reading;
  auto run_until = [&](double t_s) {
    while (to_seconds(clock.now()) < t_s - 1e-12) {
      clock.advance(kTick_ns);
      ASSERT_EQ(sim.try_exchange(DeviceCommand{}, reading), IoStatus::kOk);
    }
  };

  // Leg 1, fast: 2 cm down at 0.5 m/s. Average grip speed between 10 % and 90 % of the way.
  const Eigen::Vector3d start(0.0, 0.0, 0.12);
  const Eigen::Vector3d first(0.0, -0.02, 0.12);
  double t10 = -1.0;
  double t90 = -1.0;
  while (t90 < 0.0 && clock.now() < from_seconds(0.5)) {
    clock.advance(kTick_ns);
    ASSERT_EQ(sim.try_exchange(DeviceCommand{}, reading), IoStatus::kOk);
    const double progress = (true_position(sim) - start).dot(first - start) / (first - start).squaredNorm();
    if (t10 < 0.0 && progress >= 0.1) t10 = to_seconds(clock.now());
    if (t90 < 0.0 && progress >= 0.9) t90 = to_seconds(clock.now());
  }
  ASSERT_GT(t90, 0.0);
  const double fast_speed = 0.8 * 0.02 / (t90 - t10);
  EXPECT_NEAR(fast_speed, 0.5, 0.5 * 0.35) << "a 0.15 kg grip on a 300 N/m hand lags a 40 ms leg";

  // Hold: the grip settles on the waypoint and stays there.
  run_until(player.leg_arrival_s(0) + 0.5);
  EXPECT_LT((true_position(sim) - first).norm(), 5e-4);
  run_until(player.leg_departure_s(0) - 0.001);
  EXPECT_LT((true_position(sim) - first).norm(), 1e-5);
  EXPECT_LT(sim.truth().velocity_device_m_per_s.norm(), 1e-4);

  // Leg 2, slow: 3 cm diagonally at 0.1 m/s. Mid-leg the grip moves at the scripted speed
  // along the leg (steady state: it trails the target by b·v/k ≈ 1 mm).
  const Eigen::Vector3d second(0.02, 0.0, 0.13);
  run_until((player.leg_departure_s(0) + player.leg_arrival_s(1)) / 2.0);
  const Eigen::Vector3d v = sim.truth().velocity_device_m_per_s;
  EXPECT_NEAR(v.norm(), 0.1, 0.1 * 0.05);
  EXPECT_GT(v.normalized().dot((second - first).normalized()), 0.999);
  const Eigen::Vector3d lag = player.target_at(to_seconds(clock.now())).position_device_m - true_position(sim);
  EXPECT_NEAR(lag.norm(), sim.config().dynamics.viscous_damping_n_s_per_m * 0.1 / 300.0, 2e-4);

  run_until(player.script_end_s() - 0.001);
  EXPECT_LT((true_position(sim) - second).norm(), 1e-5);

  // Release: the hand lets go, nothing pushes the grip, and it stays where it was left.
  run_until(player.script_end_s() + 0.5);
  EXPECT_EQ(sim.truth().hand_force_device_n, Eigen::Vector3d::Zero());
  EXPECT_LT((true_position(sim) - second).norm(), 2e-5);
  EXPECT_EQ(sim.counters().kinematics_failures, 0);
}

TEST(SimFalcon, AfterReleaseTheGripCoastsFreely) {
  SimFalconConfig config = hand_config();
  config.hand->waypoints = {HandWaypoint{{0.0, -0.02, 0.12}, 0.5, 0.0}};  // let go while moving
  LockstepClock clock;
  SimFalcon sim(config, clock);
  DeviceReading reading;
  while (to_seconds(clock.now()) < 0.04) {
    clock.advance(kTick_ns);
    ASSERT_EQ(sim.try_exchange(DeviceCommand{}, reading), IoStatus::kOk);
  }
  const Eigen::Vector3d v_release = sim.truth().velocity_device_m_per_s;
  ASSERT_GT(v_release.norm(), 0.05);
  clock.advance(10 * kTick_ns);
  ASSERT_EQ(sim.try_exchange(DeviceCommand{}, reading), IoStatus::kOk);
  const double tau_s = config.dynamics.effective_mass_kg / config.dynamics.viscous_damping_n_s_per_m;
  EXPECT_TRUE(sim.truth().velocity_device_m_per_s.isApprox(v_release * std::exp(-0.01 / tau_s), 1e-9));
}

TEST(SimFalcon, ButtonsChangeAtTheScriptedTimes) {
  LockstepClock clock;
  SimFalcon sim(hand_config(), clock);
  DeviceReading reading;
  for (int k = 1; k <= 1400; ++k) {
    clock.advance(kTick_ns);
    ASSERT_EQ(sim.try_exchange(DeviceCommand{}, reading), IoStatus::kOk);
    const double t_s = k * 1e-3;
    // Events at 0.1005 s (first visible at the 0.101 s exchange), 0.5 s and 1.25 s.
    const std::uint8_t expected = t_s < 0.1005 ? 0x0 : (t_s < 0.5 - 1e-12 ? 0x1 : (t_s < 1.25 - 1e-12 ? 0x3 : 0x0));
    ASSERT_EQ(reading.buttons, expected) << "t = " << t_s;
  }
}

TEST(SimFalcon, EndStopsHoldTheGripInsideTheReachableWorkspace) {
  const std::array<Eigen::Vector3d, 7> directions{
      Eigen::Vector3d(1.0, 0.0, 0.0),  Eigen::Vector3d(-1.0, 0.0, 0.0), Eigen::Vector3d(0.0, 1.0, 0.0),
      Eigen::Vector3d(0.0, -1.0, 0.0), Eigen::Vector3d(0.0, 0.0, 1.0),  Eigen::Vector3d(0.0, 0.0, -1.0),
      Eigen::Vector3d(1.0, 1.0, 1.0).normalized()};
  for (const Eigen::Vector3d& direction : directions) {
    // From rest at the centre, push as hard as the motors can (the command saturates),
    // re-aiming every tick as the Jacobian changes: the grip slams into the stop and stays.
    LockstepClock clock;
    SimFalcon sim(SimFalconConfig{}, clock);
    const double radius_m = sim.config().dynamics.end_stop_radius_m;
    DeviceReading reading;
    double max_distance_m = 0.0;
    double max_speed_m_per_s = 0.0;
    for (int k = 0; k < 800; ++k) {
      Eigen::Matrix3d dp_dtheta;
      ASSERT_TRUE(jacobian(sim.config().geometry, true_position(sim), dp_dtheta));
      const MotorCommandResult command = force_to_motor_counts(dp_dtheta, 100.0 * direction, kDefaultNewtonMetrePerCount);
      ASSERT_TRUE(command.saturated);
      clock.advance(kTick_ns);
      ASSERT_EQ(sim.try_exchange(DeviceCommand{command.counts}, reading), IoStatus::kOk);
      max_distance_m = std::max(max_distance_m, (true_position(sim) - kCentre_device_m).norm());
      max_speed_m_per_s = std::max(max_speed_m_per_s, sim.truth().velocity_device_m_per_s.norm());
    }
    const double resting_m = (true_position(sim) - kCentre_device_m).norm();
    const double push_n = sim.truth().motor_force_device_n.norm();
    const double k_stop = sim.config().dynamics.end_stop_stiffness_n_per_m;
    const double m = sim.config().dynamics.effective_mass_kg;
    // Overshoot of the impact is bounded by v·√(m/k); at rest the wall balances the motors.
    EXPECT_GT(max_distance_m, radius_m) << "pushed " << direction.transpose();
    EXPECT_LT(max_distance_m, radius_m + max_speed_m_per_s * std::sqrt(m / k_stop)) << direction.transpose();
    EXPECT_NEAR(resting_m, radius_m + push_n / k_stop, 1e-5) << direction.transpose();
    EXPECT_LT(sim.truth().velocity_device_m_per_s.norm(), 1e-4) << direction.transpose();
    EXPECT_TRUE(sim.truth().end_stop_force_device_n.isApprox(-sim.truth().motor_force_device_n, 1e-3));
    EXPECT_TRUE(in_workspace(sim.config().geometry, true_position(sim)));
    EXPECT_EQ(sim.counters().kinematics_failures, 0);
  }
}

TEST(SimFalcon, LongStallsAreSkippedNotIntegrated) {
  LockstepClock clock;
  SimFalcon sim(SimFalconConfig{}, clock);
  DeviceReading reading;
  clock.advance(from_seconds(1.0));
  ASSERT_EQ(sim.try_exchange(DeviceCommand{}, reading), IoStatus::kOk);
  EXPECT_EQ(sim.counters().sub_steps, 1000);  // max_catch_up_s = 50 ms at 20 kHz
  EXPECT_EQ(sim.counters().skipped_time_ns, from_seconds(0.95));
  EXPECT_EQ(sim.truth().time_ns, from_seconds(1.0));
}

TEST(SimFalcon, RunsOnTheRealClockToo) {
  // No timing assertions (tests must not depend on machine speed): only that physics time
  // follows the clock it is given and the replies are stamped with it.
  MonotonicClock clock;
  SimFalconConfig config;
  config.initial_velocity_device_m_per_s = {0.01, 0.0, 0.0};
  SimFalcon sim(config, clock);
  DeviceReading reading;
  TimeNs previous_ns = sim.session_start_ns();
  for (int k = 0; k < 50; ++k) {
    ASSERT_EQ(sim.try_exchange(DeviceCommand{}, reading), IoStatus::kOk);
    EXPECT_EQ(sim.truth().time_ns, reading.receive_time_ns);
    EXPECT_GE(reading.receive_time_ns, previous_ns);
    previous_ns = reading.receive_time_ns;
  }
  EXPECT_GT(sim.truth().position_device_m.x(), 0.0);
}

// ---- Fault injection ------------------------------------------------------------------

struct ExchangeLog {
  std::vector<IoStatus> statuses;
  std::vector<std::array<std::int16_t, 3>> counts;        // as reported (unchanged on faults)
  std::vector<std::array<std::int16_t, 3>> ideal_counts;  // the truth's quantised IK
  std::vector<Eigen::Vector3d> positions;
};

ExchangeLog run_exchanges(const SimFalconConfig& config, int exchanges, const DeviceCommand& command = DeviceCommand{}) {
  LockstepClock clock;
  SimFalcon sim(config, clock);
  ExchangeLog run;
  DeviceReading reading;
  reading.encoder_counts = {-1, -1, -1};
  for (int k = 0; k < exchanges; ++k) {
    clock.advance(kTick_ns);
    run.statuses.push_back(sim.try_exchange(command, reading));
    run.counts.push_back(reading.encoder_counts);
    std::array<std::int16_t, 3> ideal{};
    EXPECT_TRUE(sim.ideal_encoder_counts(ideal));
    run.ideal_counts.push_back(ideal);
    run.positions.push_back(true_position(sim));
  }
  return run;
}

TEST(SimFalconFaults, DroppedAndTornRepliesHappenExactlyInTheirWindows) {
  SimFalconConfig config = hand_config();
  config.faults.dropped_replies = {ExchangeWindow{10, 3}, ExchangeWindow{50, 1}};
  config.faults.torn_packets = {ExchangeWindow{20, 2}};
  const ExchangeLog run = run_exchanges(config, 100);
  for (int k = 0; k < 100; ++k) {
    const bool dropped = (k >= 10 && k < 13) || k == 50;
    const bool torn = k == 20 || k == 21;
    const IoStatus expected = dropped ? IoStatus::kTimeout : (torn ? IoStatus::kTornPacket : IoStatus::kOk);
    ASSERT_EQ(run.statuses[k], expected) << "exchange " << k;
    if (expected != IoStatus::kOk) {
      ASSERT_EQ(run.counts[k], run.counts[k - 1]) << "reading written on a fault, exchange " << k;
    } else {
      ASSERT_EQ(run.counts[k], run.ideal_counts[k]) << "exchange " << k;
    }
  }
}

TEST(SimFalconFaults, ALostReplyStillDeliversTheCommand) {
  SimFalconConfig faulty;
  faulty.faults.dropped_replies = {ExchangeWindow{0, 5}};
  faulty.faults.torn_packets = {ExchangeWindow{5, 5}};
  const DeviceCommand push{{2000, -1000, 500}};
  const ExchangeLog with_faults = run_exchanges(faulty, 20, push);
  const ExchangeLog clean = run_exchanges(SimFalconConfig{}, 20, push);
  EXPECT_EQ(with_faults.positions, clean.positions);
  EXPECT_NE(clean.positions.back(), kCentre_device_m);
}

TEST(SimFalconFaults, StuckEncoderRepeatsItsLastReportedCount) {
  SimFalconConfig config = hand_config();
  config.faults.stuck_encoders = {StuckEncoderFault{1, ExchangeWindow{20, 15}}};
  const ExchangeLog run = run_exchanges(config, 60);
  for (int k = 0; k < 60; ++k) {
    ASSERT_EQ(run.statuses[k], IoStatus::kOk);
    const bool stuck = k >= 20 && k < 35;
    ASSERT_EQ(run.counts[k][0], run.ideal_counts[k][0]) << k;
    ASSERT_EQ(run.counts[k][2], run.ideal_counts[k][2]) << k;
    ASSERT_EQ(run.counts[k][1], stuck ? run.ideal_counts[19][1] : run.ideal_counts[k][1]) << k;
  }
  // The arm really moved meanwhile (otherwise "stuck" would prove nothing).
  EXPECT_NE(run.ideal_counts[34][1], run.ideal_counts[19][1]);
}

TEST(SimFalconFaults, EncoderJumpOffsetsTheCountFromItsExchangeOn) {
  SimFalconConfig config = hand_config();
  config.faults.encoder_jumps = {EncoderJumpFault{2, 15, 100}, EncoderJumpFault{0, 30, -40000}};
  const ExchangeLog run = run_exchanges(config, 40);
  for (int k = 0; k < 40; ++k) {
    ASSERT_EQ(run.counts[k][1], run.ideal_counts[k][1]) << k;
    ASSERT_EQ(run.counts[k][2], run.ideal_counts[k][2] + (k >= 15 ? 100 : 0)) << k;
    ASSERT_EQ(run.counts[k][0], k >= 30 ? std::int16_t{-32768} : run.ideal_counts[k][0]) << k;  // saturates, no wrap
  }
}

TEST(SimFalconFaults, DisconnectIsPermanentAndCutsMotorPower) {
  SimFalconConfig config;
  config.faults.disconnect_at_exchange = 40;
  LockstepClock clock;
  SimFalcon sim(config, clock);
  DeviceReading reading;
  const DeviceCommand push{{2000, 2000, 2000}};
  for (int k = 0; k < 200; ++k) {
    clock.advance(kTick_ns);
    ASSERT_EQ(sim.try_exchange(push, reading), k < 40 ? IoStatus::kOk : IoStatus::kDisconnected) << k;
    if (k >= 40) {
      ASSERT_EQ(sim.truth().motor_torque_nm, Eigen::Vector3d::Zero());
    }
  }
  EXPECT_EQ(sim.counters().disconnected_exchanges, 160);
  EXPECT_EQ(sim.truth().motor_force_device_n, Eigen::Vector3d::Zero());
}

TEST(SimFalconFaults, RandomFaultsFollowTheirProbabilityAndTheSeed) {
  SimFalconConfig config;
  config.faults.dropped_reply_probability = 0.1;
  config.faults.torn_packet_probability = 0.05;
  const int n = 10'000;
  const ExchangeLog a = run_exchanges(config, n);
  const ExchangeLog b = run_exchanges(config, n);
  EXPECT_EQ(a.statuses, b.statuses);
  const auto dropped = std::count(a.statuses.begin(), a.statuses.end(), IoStatus::kTimeout);
  const auto torn = std::count(a.statuses.begin(), a.statuses.end(), IoStatus::kTornPacket);
  // Binomial: 1000 ± 30 dropped; torn only when not dropped: 0.9·0.05·n = 450 ± 21. ±4σ.
  EXPECT_NEAR(static_cast<double>(dropped), 1000.0, 120.0);
  EXPECT_NEAR(static_cast<double>(torn), 450.0, 85.0);

  config.faults.seed += 1;
  const ExchangeLog c = run_exchanges(config, n);
  EXPECT_NE(a.statuses, c.statuses);
}

TEST(SimFalconFaults, BadFaultConfigIsRejectedNamingTheField) {
  LockstepClock clock;
  SimFalconConfig config;
  config.faults.stuck_encoders = {StuckEncoderFault{3, ExchangeWindow{0, 1}}};
  EXPECT_THAT([&] { SimFalcon sim(config, clock); },
              ::testing::ThrowsMessage<std::invalid_argument>(::testing::HasSubstr("faults.stuck_encoders[0].arm")));
  config = SimFalconConfig{};
  config.faults.dropped_reply_probability = 1.5;
  EXPECT_THAT([&] { SimFalcon sim(config, clock); },
              ::testing::ThrowsMessage<std::invalid_argument>(::testing::HasSubstr("faults.dropped_reply_probability")));
  config = SimFalconConfig{};
  config.dynamics.effective_mass_kg = 0.0;
  EXPECT_THAT([&] { SimFalcon sim(config, clock); },
              ::testing::ThrowsMessage<std::invalid_argument>(::testing::HasSubstr("dynamics.effective_mass_kg")));
  config = SimFalconConfig{};
  config.initial_position_device_m = Vec3{0.0, 0.0, 0.5};
  EXPECT_THAT([&] { SimFalcon sim(config, clock); },
              ::testing::ThrowsMessage<std::invalid_argument>(::testing::HasSubstr("reachable")));
  config = SimFalconConfig{};
  config.hand = HandScript{};
  config.hand->waypoints = {HandWaypoint{{0.0, 0.0, 0.12}, -1.0, 0.0}};
  EXPECT_THAT([&] { SimFalcon sim(config, clock); },
              ::testing::ThrowsMessage<std::invalid_argument>(::testing::HasSubstr("waypoints[0].speed_m_per_s")));
}

// ---- Determinism and the real-time contract ----------------------------------------------

// A closed loop like rt_core's: a spring toward the centre computed from the *reported*
// encoders, so any divergence between runs would feed back and grow.
std::vector<std::array<std::int16_t, 3>> closed_loop_encoder_sequence(const SimFalconConfig& config, int exchanges) {
  LockstepClock clock;
  SimFalcon sim(config, clock);
  std::vector<std::array<std::int16_t, 3>> sequence;
  DeviceReading reading;
  DeviceCommand command;
  Eigen::Vector3d p_fk = kCentre_device_m;
  for (int k = 0; k < exchanges; ++k) {
    clock.advance(kTick_ns);
    if (sim.try_exchange(command, reading) != IoStatus::kOk) continue;
    sequence.push_back(reading.encoder_counts);
    const Eigen::Vector3d theta_rad = encoders_to_theta(config.encoder, reading.encoder_counts);
    forward_kinematics(config.geometry, theta_rad, p_fk, FkOptions{});
    Eigen::Matrix3d dp_dtheta;
    if (jacobian(config.geometry, p_fk, dp_dtheta)) {
      command.motor_counts =
          force_to_motor_counts(dp_dtheta, 200.0 * (kCentre_device_m - p_fk), kDefaultNewtonMetrePerCount).counts;
    }
  }
  return sequence;
}

TEST(SimFalcon, IsDeterministic) {
  SimFalconConfig config = hand_config();
  config.faults.dropped_reply_probability = 0.02;
  config.faults.stuck_encoders = {StuckEncoderFault{0, ExchangeWindow{100, 20}}};
  const auto first = closed_loop_encoder_sequence(config, 2000);
  const auto second = closed_loop_encoder_sequence(config, 2000);
  ASSERT_GT(first.size(), 1900u);
  EXPECT_EQ(first, second);
  // …and the loop and hand really moved the device.
  EXPECT_NE(first.front(), first[first.size() / 2]);
}

TEST(SimFalcon, TryExchangeNeverAllocates) {
  SimFalconConfig config = hand_config();
  config.faults.dropped_reply_probability = 0.05;
  config.faults.torn_packet_probability = 0.05;
  config.faults.stuck_encoders = {StuckEncoderFault{1, ExchangeWindow{300, 50}}};
  config.faults.encoder_jumps = {EncoderJumpFault{2, 500, 7}};
  config.faults.disconnect_at_exchange = 1900;
  LockstepClock clock;
  SimFalcon sim(config, clock);
  std::array<IoStatus, 2000> statuses{};
  DeviceReading reading;
  const long before = fissure::testing::allocation_count();
  for (std::size_t k = 0; k < statuses.size(); ++k) {
    clock.advance(kTick_ns);
    const auto drive = static_cast<std::int16_t>((static_cast<int>(k) % 400) * 10 - 2000);
    statuses[k] = sim.try_exchange(DeviceCommand{{drive, static_cast<std::int16_t>(-drive), 300}}, reading);
  }
  const long after = fissure::testing::allocation_count();
  EXPECT_EQ(after - before, 0);
  // The loop exercised every path: ok, timeout, torn, disconnected.
  for (const IoStatus status : {IoStatus::kOk, IoStatus::kTimeout, IoStatus::kTornPacket, IoStatus::kDisconnected}) {
    EXPECT_NE(std::find(statuses.begin(), statuses.end(), status), statuses.end()) << to_string(status);
  }
  // The counter really counts (so a zero above means something).
  const long probe_before = fissure::testing::allocation_count();
  auto probe = std::make_unique<int>(1);
  EXPECT_EQ(fissure::testing::allocation_count() - probe_before, 1);
}

}  // namespace
}  // namespace fissure::falcon
