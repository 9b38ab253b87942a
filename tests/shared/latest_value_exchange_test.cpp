#include "fissure/shared/latest_value_exchange.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "checksummed_payload.hpp"
#include "fissure/shared/messages.hpp"

namespace fissure {
namespace {

using test::ChecksummedPayload;

TEST(LatestValueExchange, EmptyUntilFirstPublish) {
  LatestValueExchange<int> exchange;
  int out = -1;
  EXPECT_FALSE(exchange.try_fetch(out));
  EXPECT_EQ(out, -1);
}

TEST(LatestValueExchange, FetchReturnsNewestAndOnlyOnce) {
  LatestValueExchange<int> exchange;
  exchange.publish(1);
  exchange.publish(2);
  exchange.publish(3);
  int out = 0;
  ASSERT_TRUE(exchange.try_fetch(out));
  EXPECT_EQ(out, 3);
  EXPECT_FALSE(exchange.try_fetch(out));  // nothing newer
  EXPECT_EQ(out, 3);
  exchange.publish(4);
  ASSERT_TRUE(exchange.try_fetch(out));
  EXPECT_EQ(out, 4);
}

TEST(LatestValueExchange, AlternatingPublishFetchNeverLosesTheLatest) {
  LatestValueExchange<ContactProxy> exchange;
  ContactProxy proxy;
  ContactProxy out;
  for (std::uint64_t i = 1; i <= 1000; ++i) {
    proxy.sequence = i;
    exchange.publish(proxy);
    if (i % 3 == 0) {
      ASSERT_TRUE(exchange.try_fetch(out));
      EXPECT_EQ(out.sequence, i);
    }
  }
}

// Two threads, 10⁶ publications; every value the consumer sees must be intact (checksum)
// and sequences must never go backwards. Run again under ThreadSanitizer in CI.
TEST(LatestValueExchange, TwoThreadsMillionExchangesNoTornReads) {
  constexpr std::uint64_t kCount = 1'000'000;
  LatestValueExchange<ChecksummedPayload> exchange;
  std::atomic<bool> done{false};
  std::uint64_t fetched = 0;
  std::uint64_t torn = 0;
  std::uint64_t backwards = 0;
  std::uint64_t last_sequence = 0;

  std::thread consumer([&] {
    ChecksummedPayload out;
    auto drain = [&] {
      if (!exchange.try_fetch(out)) {
        std::this_thread::yield();  // nothing new: let the producer run (2-core CI)
        return;
      }
      ++fetched;
      if (!out.verify()) ++torn;
      if (out.sequence <= last_sequence) ++backwards;
      last_sequence = out.sequence;
    };
    while (!done.load(std::memory_order_acquire)) drain();
    drain();  // the final value published before `done`
  });
  for (std::uint64_t i = 1; i <= kCount; ++i) exchange.publish(ChecksummedPayload::make(i));
  done.store(true, std::memory_order_release);
  consumer.join();

  EXPECT_EQ(torn, 0u);
  EXPECT_EQ(backwards, 0u);
  EXPECT_GT(fetched, 0u);
  EXPECT_EQ(last_sequence, kCount) << "the newest value must always be fetchable";
}

}  // namespace
}  // namespace fissure
