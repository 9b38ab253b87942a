#include "fissure/rt_core/velocity_filter.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace fissure::rt {
namespace {

constexpr double kRate_hz = 1000.0;
constexpr double kPeriod_s = 1.0 / kRate_hz;

TEST(VelocityFilter, ConstantVelocityIsReproducedExactlyAfterSettling) {
  const VelocityFilterCoefficients c = design_velocity_filter(100.0, kRate_hz);
  VelocityFilterState state;
  const Eigen::Vector3d v(0.1, -0.2, 0.05);
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  for (int k = 0; k < 200; ++k) out = update_velocity(c, state, v * (k * kPeriod_s), kPeriod_s);
  EXPECT_NEAR((out - v).norm(), 0.0, 1e-9);  // DC gain is exactly 1
}

TEST(VelocityFilter, FirstSampleStartsFromRest) {
  const VelocityFilterCoefficients c = design_velocity_filter(100.0, kRate_hz);
  VelocityFilterState state;
  // A first sample far from the origin must not read as a huge velocity.
  EXPECT_EQ(update_velocity(c, state, Eigen::Vector3d(0.0, 0.0, 0.125), kPeriod_s), Eigen::Vector3d::Zero());
}

TEST(VelocityFilter, DocumentedLagMatchesARampInVelocity) {
  // p = a·t²/2 ⇒ v = a·t; in steady state the estimate must read a·(t − lag).
  const double cutoff_hz = 100.0;
  const VelocityFilterCoefficients c = design_velocity_filter(cutoff_hz, kRate_hz);
  const double lag_s = velocity_lag_s(cutoff_hz, kRate_hz);
  // The analogue figure the docs quote: √2/(2π f_c) + T/2 ≈ 2.75 ms at 100 Hz, 1 kHz.
  EXPECT_NEAR(lag_s, std::numbers::sqrt2 / (2.0 * std::numbers::pi * cutoff_hz) + 0.5 * kPeriod_s, 1e-4);
  VelocityFilterState state;
  const double a = 2.0;  // m/s²
  double t = 0.0;
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  for (int k = 0; k < 400; ++k) {
    t = k * kPeriod_s;
    out = update_velocity(c, state, Eigen::Vector3d(0.5 * a * t * t, 0.0, 0.0), kPeriod_s);
  }
  EXPECT_NEAR(out.x(), a * (t - lag_s), 1e-9);
}

TEST(VelocityFilter, QuantisationNoiseAtNyquistIsRemoved) {
  // One encoder count back and forth every tick (≈ 50 µm): the raw difference reads ±50 mm/s.
  const VelocityFilterCoefficients c = design_velocity_filter(100.0, kRate_hz);
  VelocityFilterState state;
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  for (int k = 0; k < 400; ++k) out = update_velocity(c, state, Eigen::Vector3d((k % 2) * 50e-6, 0.0, 0.0), kPeriod_s);
  EXPECT_LT(std::fabs(out.x()), 1e-6);  // bilinear transform puts both zeros at z = −1
}

TEST(VelocityFilter, ResetForgetsHistory) {
  const VelocityFilterCoefficients c = design_velocity_filter(100.0, kRate_hz);
  VelocityFilterState state;
  for (int k = 0; k < 50; ++k) update_velocity(c, state, Eigen::Vector3d(k * 1e-3, 0.0, 0.0), kPeriod_s);
  reset(state);
  EXPECT_FALSE(state.primed);
  EXPECT_EQ(update_velocity(c, state, Eigen::Vector3d(1.0, 1.0, 1.0), kPeriod_s), Eigen::Vector3d::Zero());
}

}  // namespace
}  // namespace fissure::rt
