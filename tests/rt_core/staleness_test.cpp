#include "fissure/rt_core/staleness.hpp"

#include <gtest/gtest.h>

namespace fissure::rt {
namespace {

TEST(Staleness, UsableOnlyWithAFreshValidProxy) {
  const ProxyConfig config;  // stale after 100 ms
  EXPECT_FALSE(proxy_usable(config, false, false, 0));
  EXPECT_TRUE(proxy_usable(config, true, false, from_seconds(0.1)));
  EXPECT_FALSE(proxy_usable(config, true, false, from_seconds(0.1) + 1));
  EXPECT_FALSE(proxy_usable(config, true, true, 0));
}

TEST(Staleness, GainFadesOutWithinFadeTimeAndBackIn) {
  ProxyConfig config;
  config.fade_s = 0.05;
  FadeState state;
  state.gain = 1.0;
  const double period_s = 0.001;
  int ticks_to_zero = 0;
  double previous = 1.0;
  while (update_fade(config, state, false, period_s) > 0.0) {
    EXPECT_LT(state.gain, previous);
    previous = state.gain;
    ++ticks_to_zero;
  }
  EXPECT_LE(ticks_to_zero + 1, 51);  // zero within fade_s (+ rounding of one tick)
  int ticks_to_one = 0;
  while (update_fade(config, state, true, period_s) < 1.0) ++ticks_to_one;
  EXPECT_LE(ticks_to_one + 1, 51);
  EXPECT_GE(ticks_to_one + 1, 49);  // not a step
}

}  // namespace
}  // namespace fissure::rt
