#pragma once
// Pipeline stage: encoder counts → motor-arm angles θ1, with the encoder-jump check.
// An encoder that moved further since the last accepted sample than the arm can physically
// turn in that time (a lost/gained count burst, a glitching cable, a re-home behind our
// back) is a fault: the sample is not used. The jumped angle becomes the reference for the
// next check, so a persistent offset is judged once, not forever (recovery: docs/rt_core.md).
#include <array>
#include <cstdint>

#include <Eigen/Core>

#include "fissure/falcon_hw/encoder_mapping.hpp"

namespace fissure::rt {

/// Fastest plausible motor-arm rotation [rad/s]. A fast flick of the hand is ~3 m/s; with
/// |∂p/∂θ| ≈ 0.08 m/rad at the workspace centre (falcon_hw kinematics) that is ≈ 40 rad/s,
/// so 100 rad/s (0.1 rad = 157 counts per 1 ms tick) leaves a 2.5× margin and still catches
/// any jump of a few hundred counts.
inline constexpr double kDefaultMaxJointRate_rad_per_s = 100.0;
/// Clean ticks after a device fault before the force ramps back in: 20 ticks (20 ms at
/// 1 kHz) re-primes the velocity filter (its lag is ~3 ms) and shows the fault is gone.
inline constexpr int kDefaultRecoveryTicks = 20;

struct FaultConfig {
  double max_joint_rate_rad_per_s = kDefaultMaxJointRate_rad_per_s;
  int recovery_ticks = kDefaultRecoveryTicks;
};

struct JointState {
  Eigen::Vector3d theta_rad = Eigen::Vector3d::Zero();
  bool have_reference = false;  ///< theta_rad holds the previous sample
};

enum class JointCheck : std::uint8_t { kOk, kJump, kNonFinite };

/// Converts counts to θ1 and checks the change against max_joint_rate·elapsed (+ one count
/// of quantisation). `elapsed_s` is the time since the previous sample judged.
JointCheck encoders_to_joint_angles(const falcon::EncoderMapping& mapping, const FaultConfig& faults,
                                    JointState& state, const std::array<std::int16_t, 3>& counts,
                                    double elapsed_s) noexcept;

}  // namespace fissure::rt
