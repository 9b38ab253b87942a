#include "fissure/shared/spsc_ring.hpp"

#include <gtest/gtest.h>

#include <thread>

#include "checksummed_payload.hpp"

namespace fissure {
namespace {

using test::ChecksummedPayload;

TEST(SpscRing, FifoOrderAndEmpty) {
  SpscRing<int, 4> ring;
  int out = 0;
  EXPECT_FALSE(ring.try_pop(out));
  for (int i = 0; i < 4; ++i) ASSERT_TRUE(ring.try_push(i));
  EXPECT_EQ(ring.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(ring.try_pop(out));
    EXPECT_EQ(out, i);
  }
  EXPECT_FALSE(ring.try_pop(out));
}

TEST(SpscRing, FullRingRejectsWithoutOverwriting) {
  SpscRing<int, 2> ring;
  ASSERT_TRUE(ring.try_push(1));
  ASSERT_TRUE(ring.try_push(2));
  EXPECT_FALSE(ring.try_push(3));
  int out = 0;
  ASSERT_TRUE(ring.try_pop(out));
  EXPECT_EQ(out, 1);
  ASSERT_TRUE(ring.try_push(3));
  ASSERT_TRUE(ring.try_pop(out));
  EXPECT_EQ(out, 2);
  ASSERT_TRUE(ring.try_pop(out));
  EXPECT_EQ(out, 3);
}

TEST(SpscRing, WrapsAroundManyTimes) {
  SpscRing<std::uint64_t, 8> ring;
  std::uint64_t out = 0;
  for (std::uint64_t i = 0; i < 10'000; ++i) {
    ASSERT_TRUE(ring.try_push(i));
    ASSERT_TRUE(ring.try_pop(out));
    ASSERT_EQ(out, i);
  }
}

// Two threads, 10⁶ items: every pushed item arrives once, in order, intact.
TEST(SpscRing, TwoThreadsMillionItemsInOrderIntact) {
  constexpr std::uint64_t kCount = 1'000'000;
  static SpscRing<ChecksummedPayload, 1024> ring;  // ≈ 1 MiB: keep it off the stack
  std::uint64_t received = 0;
  std::uint64_t torn = 0;
  std::uint64_t out_of_order = 0;
  std::thread consumer([&] {
    ChecksummedPayload out;
    while (received < kCount) {
      if (!ring.try_pop(out)) {
        std::this_thread::yield();  // on a loaded 2-core box, let the producer run
        continue;
      }
      if (!out.verify()) ++torn;
      if (out.sequence != received + 1) ++out_of_order;
      ++received;
    }
  });
  for (std::uint64_t i = 1; i <= kCount; ++i) {
    const auto payload = ChecksummedPayload::make(i);
    while (!ring.try_push(payload)) std::this_thread::yield();
  }
  consumer.join();
  EXPECT_EQ(received, kCount);
  EXPECT_EQ(torn, 0u);
  EXPECT_EQ(out_of_order, 0u);
}

}  // namespace
}  // namespace fissure
