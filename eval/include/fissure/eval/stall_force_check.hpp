#pragma once
// The stress harness's check after an injected rt stall (issue 26): from kStressStallRecovery_s
// after each stall, for kStressStallCheck_s, the commanded force must be within
// kStressStallForceTolerance of the force rt_core renders as the environment, both as means over
// the last kStressStallMeanWindow_s (stress_cases.hpp says why means).
//
// The reference is the environment the tick hands to the passivity controller: the contact
// (proxy) force after blend and fade PLUS safety's workspace soft wall (tick.cpp adds the two
// before the controller; safety.hpp says why). A hand resting beyond the workspace radius gets
// both, and a command that renders both is the un-held-back wall this check is about; compared
// with the contact force alone it reads the soft wall as an error (0.12–1.82 N on contacts of
// ~1.4 N in the full profile). The telemetry records the contact force and the position the
// tick used; the soft wall is rt_core's own workspace_soft_wall_n of that position with the
// loop's SafetyConfig — the same function, input and config the tick evaluates. The reference is
// that environment clamped to safety's max_force_n per tick (direction kept, clamp_force_magnitude):
// safety clamps every command to it, so a contact above it (10.1 and 15.3 N in the full profile)
// can only be commanded at max_force_n, and compared unclamped no controller could pass it.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "fissure/eval/stress_cases.hpp"
#include "fissure/rt_core/safety.hpp"
#include "fissure/rt_core/telemetry.hpp"

namespace fissure::eval {

/// The environment force rt_core renders at the sample's tick [N, device frame]: its contact force
/// plus the workspace soft wall at its position (safety.hpp).
Eigen::Vector3d rendered_environment_device_n(const rt::SafetyConfig& safety, const rt::TelemetrySample& sample) noexcept;

/// What one sample did to the check.
enum class StallCheckOutcome : std::uint8_t {
  kOutsideWindow,   ///< not in a check window (or its mean window is still filling)
  kBelowMinForce,   ///< in a window, but the contact or the reference mean is below kStressStallMinForce_n
  kWithin,          ///< checked: error ≤ kStressStallForceTolerance
  kOverTolerance,   ///< checked: error above the tolerance
};

struct StallCheckTick {
  StallCheckOutcome outcome = StallCheckOutcome::kOutsideWindow;
  double error = 0.0;  ///< |mean F_cmd − mean F_env| / |mean F_env| when checked
};

class StallForceCheck {
 public:
  /// stalls: in time order (StressSetup::rt_stalls); period_s: the rt period (the means' tick count).
  StallForceCheck(std::vector<TimeWindow> stalls, double period_s, const rt::SafetyConfig& safety);

  /// Feeds one telemetry sample (every tick, in order).
  StallCheckTick tick(const rt::TelemetrySample& sample);

  [[nodiscard]] double error_max() const noexcept { return error_max_; }
  [[nodiscard]] std::uint64_t checked_ticks() const noexcept { return checked_ticks_; }
  /// Stalls with at least one checked tick over the tolerance.
  [[nodiscard]] std::size_t stalls_failed() const noexcept { return stalls_failed_; }

 private:
  /// Ring of the last commanded and reference forces (≥ the means' ticks at the fastest rate,
  /// 10 kHz × kStressStallMeanWindow_s).
  static constexpr std::size_t kMeanRingSize = 256;
  std::array<Eigen::Vector3d, kMeanRingSize> commanded_ring_{};
  std::array<Eigen::Vector3d, kMeanRingSize> reference_ring_{};
  std::array<Eigen::Vector3d, kMeanRingSize> contact_ring_{};
  std::size_t mean_samples_ = 0;
  std::size_t window_ticks_ = 0;

  std::vector<TimeWindow> stalls_;
  rt::SafetyConfig safety_;
  std::size_t next_stall_ = 0;
  bool this_stall_failed_ = false;
  std::size_t stalls_failed_ = 0;
  double error_max_ = 0.0;
  std::uint64_t checked_ticks_ = 0;
};

}  // namespace fissure::eval
