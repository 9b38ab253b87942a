#include "fissure/rt_core/sub_count_position.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "fissure/rt_core/velocity_filter.hpp"

namespace fissure::rt {
namespace {

constexpr double kRate_hz = 1000.0;
constexpr double kPeriod_s = 1.0 / kRate_hz;
constexpr double kCount_m = kPassivityEncoderCount_m;

/// A position as the encoders report it: rounded to whole counts per axis.
Eigen::Vector3d quantised(const Eigen::Vector3d& p_m) {
  return (p_m / kCount_m).array().round().matrix() * kCount_m;
}

// A hand resting on a count boundary: the reading toggles by one count every tick. The
// reading itself steps by 50 µm each tick (0.05 N at 1000 N/m); the estimate by half that,
// about the boundary.
TEST(SubCountPosition, AReadingTogglingAcrossABoundaryMovesTheEstimateByHalfACount) {
  SubCountPositionState state;
  const Eigen::Vector3d a(0.0, 0.0, 0.1), b = a + Eigen::Vector3d(0.0, kCount_m, 0.0);
  double largest_step_m = 0.0, mean_y_m = 0.0;
  Eigen::Vector3d last = update_sub_count_position(state, a, Eigen::Vector3d::Zero(), kPeriod_s);
  for (int k = 1; k <= 100; ++k) {
    const Eigen::Vector3d p = update_sub_count_position(state, (k % 2) != 0 ? b : a, Eigen::Vector3d::Zero(), kPeriod_s);
    if (k > 1) largest_step_m = std::max(largest_step_m, (p - last).norm());
    mean_y_m += p.y() / 100.0;
    last = p;
  }
  EXPECT_NEAR(largest_step_m, kCount_m - 2.0 * kSubCountHalfWidth_m, 1e-12);  // half a count
  EXPECT_NEAR(mean_y_m, a.y() + 0.5 * kCount_m, 1e-9);  // about the boundary between the two counts
}

// A hand moving slowly (2 mm/s: one count every 25 ticks) through quantised readings, with the
// velocity filter in the loop: the estimate moves at most the true motion per tick plus what
// the filter's ripple leaves (v_f of quantised readings ripples by a few mm/s) and what a count
// change pushes it by, at most half a count; it stays within h of the reading.
TEST(SubCountPosition, SlowMotionMovesTheEstimateSmoothlyWithinHalfACount) {
  const VelocityFilterCoefficients filter = design_velocity_filter(100.0, kRate_hz);
  VelocityFilterState velocity;
  SubCountPositionState state;
  const Eigen::Vector3d start(0.001, -0.02, 0.1), v(0.0, -0.002, 0.0);
  Eigen::Vector3d last = Eigen::Vector3d::Zero();
  double largest_step_m = 0.0, reading_step_max_m = 0.0, farthest_from_reading_m = 0.0, farthest_from_truth_m = 0.0;
  Eigen::Vector3d last_reading = quantised(start);
  for (int k = 0; k < 2000; ++k) {
    const Eigen::Vector3d truth = start + v * (k * kPeriod_s);
    const Eigen::Vector3d reading = quantised(truth);
    const Eigen::Vector3d v_f = update_velocity(filter, velocity, reading, kPeriod_s);
    const Eigen::Vector3d p = update_sub_count_position(state, reading, v_f, kPeriod_s);
    if (k > 100) {  // after the filter's start-up
      largest_step_m = std::max(largest_step_m, (p - last).norm());
      reading_step_max_m = std::max(reading_step_max_m, (reading - last_reading).norm());
      farthest_from_truth_m = std::max(farthest_from_truth_m, (p - truth).cwiseAbs().maxCoeff());
    }
    farthest_from_reading_m = std::max(farthest_from_reading_m, (p - reading).cwiseAbs().maxCoeff());
    last = p;
    last_reading = reading;
  }
  EXPECT_NEAR(reading_step_max_m, kCount_m, 1e-12);      // the readings step by a whole count
  EXPECT_LE(largest_step_m, 0.5 * kCount_m);             // the estimate by at most half of one
  EXPECT_LE(farthest_from_reading_m, kSubCountHalfWidth_m + 1e-12);
  EXPECT_LE(farthest_from_truth_m, 0.5 * kCount_m + kSubCountHalfWidth_m + 1e-12);  // the reading: ≤ ½ count off
}

// A velocity estimate that is wrong (a stale v_f after the hand stopped) cannot carry the
// estimate away: it is held within half a count of the reading.
TEST(SubCountPosition, AWrongVelocityCannotCarryTheEstimateAway) {
  SubCountPositionState state;
  const Eigen::Vector3d reading(0.0, 0.0, 0.1), v_wrong(0.5, -0.5, 0.5);
  Eigen::Vector3d p = update_sub_count_position(state, reading, Eigen::Vector3d::Zero(), kPeriod_s);
  for (int k = 0; k < 50; ++k) p = update_sub_count_position(state, reading, v_wrong, kPeriod_s);
  EXPECT_NEAR((p - reading).cwiseAbs().maxCoeff(), kSubCountHalfWidth_m, 1e-12);
}

TEST(SubCountPosition, ResetStartsAtTheReading) {
  SubCountPositionState state;
  (void)update_sub_count_position(state, Eigen::Vector3d(0.0, 0.0, 0.1), Eigen::Vector3d::Zero(), kPeriod_s);
  reset(state);
  const Eigen::Vector3d far(0.02, 0.0, 0.1);
  EXPECT_EQ(update_sub_count_position(state, far, Eigen::Vector3d(1.0, 0.0, 0.0), kPeriod_s), far);
}

}  // namespace
}  // namespace fissure::rt
