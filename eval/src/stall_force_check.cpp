#include "fissure/eval/stall_force_check.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "fissure/eval/eval_error.hpp"
#include "fissure/shared/time.hpp"
#include "fissure/shared/messages.hpp"

namespace fissure::eval {
Eigen::Vector3d rendered_environment_device_n(const rt::SafetyConfig& safety, const rt::TelemetrySample& sample) noexcept {
  std::uint32_t flags = 0;  // the tick's own flags carry kFlagSoftWall; not needed here
  return as_eigen(sample.contact_force_device_n) +
         rt::workspace_soft_wall_n(safety, as_eigen(sample.position_device_m), flags);
}

StallForceCheck::StallForceCheck(std::vector<TimeWindow> stalls, double period_s, const rt::SafetyConfig& safety)
    : stalls_(std::move(stalls)), safety_(safety) {
  if (!(period_s > 0.0)) throw EvalError("stall force check: rt period " + std::to_string(period_s) + " s is not > 0");
  window_ticks_ = static_cast<std::size_t>(std::lround(kStressStallMeanWindow_s / period_s));
  if (window_ticks_ < 1 || window_ticks_ > kMeanRingSize) {
    throw EvalError("stall force check: an rt period of " + std::to_string(period_s) + " s gives " +
                    std::to_string(window_ticks_) + " ticks per mean window (1–" + std::to_string(kMeanRingSize) + ")");
  }
}

StallCheckTick StallForceCheck::tick(const rt::TelemetrySample& sample) {
  const double t_s = to_seconds(sample.time_ns);
  while (next_stall_ < stalls_.size() &&
         t_s >= stalls_[next_stall_].end_s + kStressStallRecovery_s + kStressStallCheck_s) {
    ++next_stall_;
    this_stall_failed_ = false;
  }
  if (next_stall_ >= stalls_.size()) return {};
  const double window_start_s = stalls_[next_stall_].end_s + kStressStallRecovery_s;
  if (t_s < window_start_s - kStressStallMeanWindow_s) {
    mean_samples_ = 0;
    return {};
  }
  const std::size_t slot = mean_samples_++ % kMeanRingSize;
  commanded_ring_[slot] = as_eigen(sample.force_device_n);
  contact_ring_[slot] = as_eigen(sample.contact_force_device_n);
  // What the device can command of it: safety's clamp (direction kept), as the tick applies it.
  reference_ring_[slot] = rt::clamp_force_magnitude(rendered_environment_device_n(safety_, sample), safety_.max_force_n);
  if (t_s < window_start_s || mean_samples_ < window_ticks_) return {};
  Eigen::Vector3d commanded = Eigen::Vector3d::Zero(), reference = Eigen::Vector3d::Zero(),
                  contact = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < window_ticks_; ++k) {
    const std::size_t i = (mean_samples_ - 1 - k) % kMeanRingSize;
    commanded += commanded_ring_[i];
    reference += reference_ring_[i];
    contact += contact_ring_[i];
  }
  const auto n = static_cast<double>(window_ticks_);
  commanded /= n;
  reference /= n;
  contact /= n;
  // The check is about a contact after a stall: no contact, nothing checked. The tolerance is
  // relative to the reference, so that must be above the same floor too (a soft wall cancelling
  // the contact would leave 5 % of next to nothing).
  const double reference_n = reference.norm();
  if (!(contact.norm() >= kStressStallMinForce_n) || !(reference_n >= kStressStallMinForce_n)) {
    return {StallCheckOutcome::kBelowMinForce, 0.0};
  }
  const double error = (commanded - reference).norm() / reference_n;
  ++checked_ticks_;
  error_max_ = std::max(error_max_, error);
  if (!(error <= kStressStallForceTolerance)) {
    if (!this_stall_failed_) ++stalls_failed_;
    this_stall_failed_ = true;
    return {StallCheckOutcome::kOverTolerance, error};
  }
  return {StallCheckOutcome::kWithin, error};
}

}  // namespace fissure::eval
