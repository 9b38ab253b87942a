#include "fissure/shared/clock.hpp"

#include <gtest/gtest.h>

#include <thread>

namespace fissure {
namespace {

TEST(LockstepClock, OnlyMovesWhenTold) {
  LockstepClock clock(1000);
  EXPECT_EQ(clock.now(), 1000);
  EXPECT_EQ(clock.now(), 1000);
  EXPECT_EQ(clock.advance(500), 1500);
  EXPECT_EQ(clock.now(), 1500);
}

TEST(LockstepClock, SleepUntilJumpsForwardNeverBack) {
  LockstepClock clock(0);
  EXPECT_EQ(clock.sleep_until(1'000'000), 1'000'000);
  EXPECT_EQ(clock.sleep_until(10), 1'000'000);
  EXPECT_EQ(clock.advance(-5), 1'000'000) << "negative advance is ignored";
}

TEST(LockstepClock, ReadersOnOtherThreadsSeeMonotonicTime) {
  LockstepClock clock(0);
  std::thread reader([&] {
    TimeNs last = 0;
    while (last < 100'000) {
      const TimeNs t = clock.now();
      ASSERT_GE(t, last);
      last = t;
    }
  });
  for (int i = 0; i < 100'000; ++i) clock.advance(1);
  reader.join();
  EXPECT_EQ(clock.now(), 100'000);
}

TEST(MonotonicClock, SleepUntilReturnsAtOrAfterDeadline) {
  MonotonicClock clock;
  const TimeNs start = clock.now();
  const TimeNs deadline = start + 200'000;  // 0.2 ms: the clock under test, not a wait for a thread
  EXPECT_GE(clock.sleep_until(deadline), deadline);
  EXPECT_GE(clock.sleep_until(start), deadline) << "a past deadline returns at once";
}

TEST(Time, PeriodFromRate) {
  EXPECT_EQ(period_from_rate_hz(1000.0), 1'000'000);
  EXPECT_EQ(period_from_rate_hz(3000.0), 333'333);
  EXPECT_DOUBLE_EQ(to_seconds(1'500'000'000), 1.5);
}

}  // namespace
}  // namespace fissure
