// SampleReservoir (session/session_record.hpp): the per-tick and per-step samples behind the
// quantiles of `fissure run` and `fissure sim`. Every value is kept up to kCapacity (the
// quantiles are exact for every test and benchmark run); beyond it the memory stays at
// kCapacity values, a uniform sample of the whole run drawn from a fixed seed.
#include "fissure/session/session_record.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace fissure::session {
namespace {

constexpr std::size_t kCapacity = SampleReservoir::kCapacity;

/// A sequence with no order to it (so a reservoir that kept only the first or the last values,
/// or sorted them, would show), every value distinct: value i is i scrambled by a bijection.
double value_of(std::uint64_t i) { return static_cast<double>((i * 2654435761u) % 4294967291u); }

TEST(SampleReservoirTest, KeepsEveryValueInOrderUpToItsCapacity) {
  SampleReservoir r;
  EXPECT_EQ(r.count(), 0u);
  EXPECT_TRUE(r.exact());
  EXPECT_TRUE(r.values().empty());
  std::vector<double> all;
  for (std::uint64_t i = 0; i < kCapacity; ++i) {
    r.add(value_of(i));
    all.push_back(value_of(i));
  }
  EXPECT_EQ(r.count(), kCapacity);
  EXPECT_TRUE(r.exact());
  EXPECT_EQ(r.values(), all);
  EXPECT_EQ(r.max(), *std::max_element(all.begin(), all.end()));
}

TEST(SampleReservoirTest, ItsQuantilesBelowCapacityAreTheExactOnes) {
  SampleReservoir r;
  std::vector<double> all;
  for (std::uint64_t i = 0; i < 10001; ++i) {
    r.add(value_of(i) * 1e-3);
    all.push_back(value_of(i) * 1e-3);
  }
  const Quantiles sampled = quantiles(r);
  const Quantiles exact = quantiles(all);
  EXPECT_EQ(sampled.median, exact.median);
  EXPECT_EQ(sampled.p99, exact.p99);
  EXPECT_EQ(sampled.max, exact.max);
}

TEST(SampleReservoirTest, NegativeValuesHaveTheirOwnMaximum) {
  // The max starts from the first value, not from 0.
  SampleReservoir r;
  r.add(-3.0);
  r.add(-1.5);
  r.add(-2.0);
  EXPECT_EQ(r.max(), -1.5);
  EXPECT_EQ(quantiles(r).max, -1.5);
}

TEST(SampleReservoirTest, BeyondItsCapacityItKeepsCapacityValuesSampledFromTheWholeRun) {
  constexpr std::uint64_t kCount = 3 * kCapacity;
  SampleReservoir r;
  double max = 0.0;
  for (std::uint64_t i = 0; i < kCount; ++i) {
    r.add(static_cast<double>(i));  // value = its index, so a kept value says where it came from
    max = std::max(max, static_cast<double>(i));
  }
  EXPECT_EQ(r.count(), kCount);
  EXPECT_FALSE(r.exact());
  EXPECT_EQ(r.values().size(), kCapacity);  // bounded: 8 MiB whatever the run's length
  EXPECT_EQ(r.max(), max);                  // the max stays exact
  // Uniform over the whole run: each third of it holds about a third of the kept values (the
  // seed is fixed, so these fractions are the same on every run and machine).
  std::array<std::size_t, 3> per_third{};
  std::vector<double> kept = r.values();
  for (double v : kept) {
    ASSERT_GE(v, 0.0);
    ASSERT_LT(v, static_cast<double>(kCount));
    ++per_third[static_cast<std::size_t>(v) / kCapacity];
  }
  for (std::size_t third = 0; third < 3; ++third) {
    const double fraction = static_cast<double>(per_third[third]) / static_cast<double>(kCapacity);
    EXPECT_NEAR(fraction, 1.0 / 3.0, 0.01) << "third " << third;
  }
  // No value is kept twice.
  std::sort(kept.begin(), kept.end());
  EXPECT_EQ(std::adjacent_find(kept.begin(), kept.end()), kept.end());
  // The sampled median of 0 .. 3N−1 is close to the exact one, 1.5 N.
  const Quantiles q = quantiles(r);
  EXPECT_NEAR(q.median / static_cast<double>(kCount), 0.5, 0.005);
  EXPECT_NEAR(q.p99 / static_cast<double>(kCount), 0.99, 0.005);
}

TEST(SampleReservoirTest, TheSameValuesGiveTheSameSample) {
  // A lockstep run is reproducible: its sampled quantiles do not change between runs.
  SampleReservoir a, b;
  for (std::uint64_t i = 0; i < kCapacity + kCapacity / 2; ++i) {
    a.add(value_of(i));
    b.add(value_of(i));
  }
  EXPECT_FALSE(a.exact());
  EXPECT_EQ(a.values(), b.values());
}

}  // namespace
}  // namespace fissure::session
