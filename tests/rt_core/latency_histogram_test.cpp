#include "fissure/rt_core/latency_histogram.hpp"

#include <gtest/gtest.h>

#include <memory>

namespace fissure::rt {
namespace {

TEST(LatencyHistogram, QuantilesInWholeMicrosecondsAndExactMax) {
  auto histogram = std::make_unique<LatencyHistogram>();
  for (int i = 0; i < 98; ++i) histogram->add(3'400);  // 3.4 µs → bin 3
  histogram->add(12'700);
  histogram->add(45'000'000);  // 45 ms: beyond the bins
  EXPECT_EQ(histogram->count, 100u);
  EXPECT_EQ(histogram->overflow, 1u);
  EXPECT_DOUBLE_EQ(histogram->quantile_us(0.5), 3.0);
  EXPECT_DOUBLE_EQ(histogram->quantile_us(0.99), 12.0);
  EXPECT_DOUBLE_EQ(histogram->quantile_us(1.0), 45'000.0);
  EXPECT_EQ(histogram->min_ns, 3'400);
}

}  // namespace
}  // namespace fissure::rt
