#include "fissure/falcon_hw/sim_falcon.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/LU>

#include "fissure/falcon_hw/motor_command.hpp"

namespace fissure::falcon {
namespace {

[[noreturn]] void reject(const std::string& field, const std::string& requirement, double value) {
  throw std::invalid_argument("sim-falcon config: " + field + " must be " + requirement + " (got " +
                              std::to_string(value) + ")");
}

void require_positive(double value, const std::string& field) {
  if (!std::isfinite(value) || value <= 0.0) reject(field, "finite and > 0", value);
}

void require_non_negative(double value, const std::string& field) {
  if (!std::isfinite(value) || value < 0.0) reject(field, "finite and >= 0", value);
}

void require_probability(double value, const std::string& field) {
  if (!(value >= 0.0 && value <= 1.0)) reject(field, "in [0, 1]", value);
}

void require_finite(const Vec3& v, const std::string& field) {
  for (std::size_t axis = 0; axis < 3; ++axis) {
    if (!std::isfinite(v[axis])) reject(field + "[" + std::to_string(axis) + "]", "finite", v[axis]);
  }
}

void require_arm(int arm, const std::string& field) {
  if (arm < 0 || arm > 2) reject(field, "0, 1 or 2", arm);
}

void require_window(const ExchangeWindow& window, const std::string& field) {
  if (window.first < 0) reject(field + ".first", ">= 0", static_cast<double>(window.first));
  if (window.count < 0) reject(field + ".count", ">= 0", static_cast<double>(window.count));
}

void validate(const SimFalconConfig& config) {
  const SimDynamicsConfig& dynamics = config.dynamics;
  require_positive(dynamics.effective_mass_kg, "dynamics.effective_mass_kg");
  require_non_negative(dynamics.viscous_damping_n_s_per_m, "dynamics.viscous_damping_n_s_per_m");
  require_positive(dynamics.physics_rate_hz, "dynamics.physics_rate_hz");
  if (dynamics.physics_rate_hz > 1e8) reject("dynamics.physics_rate_hz", "<= 1e8 (10 ns sub-steps)", dynamics.physics_rate_hz);
  require_positive(dynamics.max_catch_up_s, "dynamics.max_catch_up_s");
  if (dynamics.max_catch_up_s > 10.0) reject("dynamics.max_catch_up_s", "<= 10 s (one call must stay bounded)", dynamics.max_catch_up_s);
  require_finite(dynamics.end_stop_centre_device_m, "dynamics.end_stop_centre_device_m");
  require_positive(dynamics.end_stop_radius_m, "dynamics.end_stop_radius_m");
  require_non_negative(dynamics.end_stop_stiffness_n_per_m, "dynamics.end_stop_stiffness_n_per_m");
  require_non_negative(dynamics.end_stop_damping_n_s_per_m, "dynamics.end_stop_damping_n_s_per_m");
  require_non_negative(config.motors.newton_metre_per_count, "motors.newton_metre_per_count");
  require_non_negative(config.motors.max_motor_torque_nm, "motors.max_motor_torque_nm");

  const SimFaultConfig& faults = config.faults;
  require_probability(faults.dropped_reply_probability, "faults.dropped_reply_probability");
  require_probability(faults.torn_packet_probability, "faults.torn_packet_probability");
  for (std::size_t i = 0; i < faults.dropped_replies.size(); ++i) {
    require_window(faults.dropped_replies[i], "faults.dropped_replies[" + std::to_string(i) + "]");
  }
  for (std::size_t i = 0; i < faults.torn_packets.size(); ++i) {
    require_window(faults.torn_packets[i], "faults.torn_packets[" + std::to_string(i) + "]");
  }
  for (std::size_t i = 0; i < faults.stuck_encoders.size(); ++i) {
    const std::string field = "faults.stuck_encoders[" + std::to_string(i) + "]";
    require_arm(faults.stuck_encoders[i].arm, field + ".arm");
    require_window(faults.stuck_encoders[i].window, field + ".window");
  }
  for (std::size_t i = 0; i < faults.encoder_jumps.size(); ++i) {
    const std::string field = "faults.encoder_jumps[" + std::to_string(i) + "]";
    require_arm(faults.encoder_jumps[i].arm, field + ".arm");
    if (faults.encoder_jumps[i].at_exchange < 0) {
      reject(field + ".at_exchange", ">= 0", static_cast<double>(faults.encoder_jumps[i].at_exchange));
    }
  }
  if (faults.disconnect_at_exchange < -1) {
    reject("faults.disconnect_at_exchange", ">= 0, or -1 for never", static_cast<double>(faults.disconnect_at_exchange));
  }
  if (config.initial_position_device_m) require_finite(*config.initial_position_device_m, "initial_position_device_m");
  require_finite(config.initial_velocity_device_m_per_s, "initial_velocity_device_m_per_s");
}

bool in_any(const std::vector<ExchangeWindow>& windows, std::int64_t exchange) noexcept {
  return std::any_of(windows.begin(), windows.end(),
                     [exchange](const ExchangeWindow& window) { return window.contains(exchange); });
}

std::int16_t saturate_to_int16(std::int64_t value) noexcept {
  return static_cast<std::int16_t>(std::clamp<std::int64_t>(value, std::numeric_limits<std::int16_t>::min(),
                                                            std::numeric_limits<std::int16_t>::max()));
}

}  // namespace

SimFalcon::SimFalcon(SimFalconConfig config, const Clock& clock)
    : config_(std::move(config)),
      clock_(clock),
      session_start_ns_(clock.now()),
      sub_step_ns_(1),
      decay_per_full_step_(1.0),
      newton_metre_per_count_(kDefaultNewtonMetrePerCount),
      max_motor_torque_nm_(0.0),
      rng_state_(config_.faults.seed) {
  validate(config_);
  if (config_.hand) hand_.emplace(*config_.hand);  // validates the script, may throw

  sub_step_ns_ = std::max<TimeNs>(1, period_from_rate_hz(config_.dynamics.physics_rate_hz));
  const double b_over_m = config_.dynamics.viscous_damping_n_s_per_m / config_.dynamics.effective_mass_kg;
  decay_per_full_step_ = std::exp(-b_over_m * to_seconds(sub_step_ns_));
  if (config_.motors.newton_metre_per_count > 0.0) newton_metre_per_count_ = config_.motors.newton_metre_per_count;
  max_motor_torque_nm_ = config_.motors.max_motor_torque_nm > 0.0
                             ? config_.motors.max_motor_torque_nm
                             : static_cast<double>(kMaxMotorCount) * newton_metre_per_count_;

  Vec3 start = config_.dynamics.end_stop_centre_device_m;
  if (config_.initial_position_device_m) {
    start = *config_.initial_position_device_m;
  } else if (config_.hand) {
    start = config_.hand->start_position_device_m;
  }
  truth_.time_ns = session_start_ns_;
  truth_.position_device_m = as_eigen(start);
  truth_.velocity_device_m_per_s = as_eigen(config_.initial_velocity_device_m_per_s);
  if (!ideal_encoder_counts(last_reported_counts_)) {
    throw std::invalid_argument("sim-falcon config: initial position (" + std::to_string(start[0]) + ", " +
                                std::to_string(start[1]) + ", " + std::to_string(start[2]) +
                                ") m is outside the Falcon's reachable region (inverse kinematics fails)");
  }
}

bool SimFalcon::ideal_encoder_counts(std::array<std::int16_t, 3>& counts) const noexcept {
  Eigen::Vector3d theta_rad;
  if (!inverse_kinematics(config_.geometry, truth_.position_device_m, theta_rad)) return false;
  counts = theta_to_encoders(config_.encoder, theta_rad);
  return true;
}

double SimFalcon::next_uniform() noexcept {
  // splitmix64 (Steele, Lea & Flood 2014): tiny, fully specified, identical on every platform
  // (std::uniform_real_distribution is not specified bit-exactly across standard libraries).
  std::uint64_t z = (rng_state_ += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * 0x1.0p-53;  // uniform in [0, 1)
}

void SimFalcon::apply_command(const DeviceCommand& command) noexcept {
  std::array<std::int16_t, 3> clamped{};
  for (std::size_t arm = 0; arm < 3; ++arm) {
    // The firmware's 12-bit range: we assume it saturates per motor (it cannot keep the
    // direction the way force_to_motor_counts does; that is the host's job).
    clamped[arm] = std::clamp<std::int16_t>(command.motor_counts[arm], -kMaxMotorCount, kMaxMotorCount);
  }
  const Eigen::Vector3d torque_nm = motor_counts_to_torque(clamped, newton_metre_per_count_);
  truth_.motor_torque_nm = torque_nm.cwiseMax(-max_motor_torque_nm_).cwiseMin(max_motor_torque_nm_);
}

Eigen::Vector3d SimFalcon::end_stop_force(const Eigen::Vector3d& p, const Eigen::Vector3d& v) const noexcept {
  const SimDynamicsConfig& dynamics = config_.dynamics;
  const Eigen::Vector3d from_centre = p - as_eigen(dynamics.end_stop_centre_device_m);
  const double distance_m = from_centre.norm();
  const double penetration_m = distance_m - dynamics.end_stop_radius_m;
  if (penetration_m <= 0.0) return Eigen::Vector3d::Zero();
  const Eigen::Vector3d outward = from_centre / distance_m;
  // Spring + damper along the wall normal, push-only: a wall never pulls the grip back in.
  const double push_n = dynamics.end_stop_stiffness_n_per_m * penetration_m +
                        dynamics.end_stop_damping_n_s_per_m * v.dot(outward);
  return push_n > 0.0 ? Eigen::Vector3d(-push_n * outward) : Eigen::Vector3d::Zero();
}

void SimFalcon::sub_step(TimeNs h_ns) noexcept {
  const SimDynamicsConfig& dynamics = config_.dynamics;
  const double h_s = to_seconds(h_ns);
  const Eigen::Vector3d p = truth_.position_device_m;
  const Eigen::Vector3d v = truth_.velocity_device_m_per_s;

  // Motor force: τ = Jᵀ·F ⇒ F = J⁻ᵀ·τ, with J = ∂p/∂θ at the current position.
  Eigen::Vector3d motor_force_n = Eigen::Vector3d::Zero();
  if (!truth_.motor_torque_nm.isZero(0.0)) {
    Eigen::Matrix3d dp_dtheta;
    if (jacobian(config_.geometry, p, dp_dtheta)) {
      motor_force_n = dp_dtheta.transpose().partialPivLu().solve(truth_.motor_torque_nm);
    } else {
      ++counters_.kinematics_failures;  // outside the reachable set: no motor force this sub-step
    }
  }
  const Eigen::Vector3d hand_force_n =
      hand_ ? hand_->force_on_grip_device_n(to_seconds(truth_.time_ns - session_start_ns_), p, v)
            : Eigen::Vector3d::Zero();
  const Eigen::Vector3d end_stop_force_n = end_stop_force(p, v);
  const double mass_kg = dynamics.effective_mass_kg;
  const Eigen::Vector3d applied_n = motor_force_n + hand_force_n + end_stop_force_n;

  // Exact solution of m·v' = F − b·v over the step with F held constant; p semi-implicit.
  const double b = dynamics.viscous_damping_n_s_per_m;
  Eigen::Vector3d v_next;
  if (b > 0.0) {
    const double decay = h_ns == sub_step_ns_ ? decay_per_full_step_ : std::exp(-b / mass_kg * h_s);
    v_next = v * decay + applied_n / b * (1.0 - decay);
  } else {
    v_next = v + applied_n / mass_kg * h_s;
  }
  truth_.velocity_device_m_per_s = v_next;
  truth_.position_device_m = p + v_next * h_s;
  truth_.motor_force_device_n = motor_force_n;
  truth_.hand_force_device_n = hand_force_n;
  truth_.end_stop_force_device_n = end_stop_force_n;
  truth_.time_ns += h_ns;
  ++counters_.sub_steps;
}

void SimFalcon::advance_physics_to(TimeNs t_ns) noexcept {
  TimeNs gap_ns = t_ns - truth_.time_ns;
  if (gap_ns <= 0) return;
  const TimeNs max_gap_ns = from_seconds(config_.dynamics.max_catch_up_s);
  if (gap_ns > max_gap_ns) {
    counters_.skipped_time_ns += gap_ns - max_gap_ns;
    truth_.time_ns = t_ns - max_gap_ns;
    gap_ns = max_gap_ns;
  }
  while (t_ns - truth_.time_ns >= sub_step_ns_) sub_step(sub_step_ns_);
  if (t_ns > truth_.time_ns) sub_step(t_ns - truth_.time_ns);  // land exactly on the exchange time
}

IoStatus SimFalcon::try_exchange(const DeviceCommand& command, DeviceReading& reading) noexcept {
  const TimeNs now_ns = clock_.now();
  advance_physics_to(now_ns);  // under the previous command: one tick of latency

  const std::int64_t exchange = counters_.exchanges++;
  const SimFaultConfig& faults = config_.faults;
  // Always two draws per exchange, so the random faults depend only on seed and index.
  const double drop_draw = next_uniform();
  const double torn_draw = next_uniform();

  if (faults.disconnect_at_exchange >= 0 && exchange >= faults.disconnect_at_exchange) disconnected_ = true;
  if (disconnected_) {
    truth_.motor_torque_nm.setZero();  // unplugged: the motors lose power
    ++counters_.disconnected_exchanges;
    return IoStatus::kDisconnected;
  }

  apply_command(command);  // the device got this command; it acts from now on

  if (drop_draw < faults.dropped_reply_probability || in_any(faults.dropped_replies, exchange)) {
    ++counters_.dropped_replies;
    return IoStatus::kTimeout;
  }
  if (torn_draw < faults.torn_packet_probability || in_any(faults.torn_packets, exchange)) {
    ++counters_.torn_packets;
    return IoStatus::kTornPacket;
  }

  std::array<std::int16_t, 3> counts = last_reported_counts_;
  if (!ideal_encoder_counts(counts)) ++counters_.kinematics_failures;  // keeps the last counts

  bool jumped = false;
  for (const EncoderJumpFault& jump : faults.encoder_jumps) {
    if (exchange >= jump.at_exchange) {
      const auto arm = static_cast<std::size_t>(jump.arm);
      counts[arm] = saturate_to_int16(std::int64_t{counts[arm]} + jump.jump_counts);
      jumped = true;
    }
  }
  bool stuck = false;
  for (const StuckEncoderFault& fault : faults.stuck_encoders) {
    if (fault.window.contains(exchange)) {
      const auto arm = static_cast<std::size_t>(fault.arm);
      counts[arm] = last_reported_counts_[arm];
      stuck = true;
    }
  }
  counters_.jumped_encoder_readings += jumped ? 1 : 0;
  counters_.stuck_encoder_readings += stuck ? 1 : 0;

  reading.encoder_counts = counts;
  reading.buttons = hand_ ? static_cast<std::uint8_t>(
                                hand_->buttons_at(to_seconds(now_ns - session_start_ns_)) & 0xFu)
                          : std::uint8_t{0};
  reading.homed_mask = config_.homed_mask;
  reading.receive_time_ns = now_ns;
  last_reported_counts_ = counts;
  return IoStatus::kOk;
}

}  // namespace fissure::falcon
