#include "fissure/rt_core/proxy_intake.hpp"

#include <gtest/gtest.h>

#include <limits>

#include "rt_test_support.hpp"

namespace fissure::rt {
namespace {

using testing::plane_proxy;

TEST(ProxyIntake, AcceptsNewValidProxiesAndKeepsThePreviousOneReadable) {
  ProxyExchange exchange;
  ProxyState state;
  EXPECT_EQ(take_latest_proxy(exchange, state, 0), ProxyIntake::kNothingNew);
  exchange.publish(plane_proxy(1, {0, 0, 0}, {0, 1, 0}, 100.0));
  EXPECT_EQ(take_latest_proxy(exchange, state, 1000), ProxyIntake::kAccepted);
  EXPECT_FALSE(state.have_previous);
  exchange.publish(plane_proxy(2, {0, 0.01, 0}, {0, 1, 0}, 200.0));
  EXPECT_EQ(take_latest_proxy(exchange, state, 5000), ProxyIntake::kAccepted);
  ASSERT_TRUE(state.have_previous);
  EXPECT_EQ(active_proxy(state).sequence, 2u);
  EXPECT_EQ(previous_proxy(state).sequence, 1u);
  EXPECT_EQ(proxy_age_ns(state, 7000), 2000);
  EXPECT_EQ(state.accepted_count, 2u);
}

TEST(ProxyIntake, InvalidProxiesAreRejectedCountedAndLatchedUntilAValidOne) {
  ProxyExchange exchange;
  ProxyState state;
  exchange.publish(plane_proxy(1, {0, 0, 0}, {0, 1, 0}, 100.0));
  take_latest_proxy(exchange, state, 0);

  ContactProxy bad = plane_proxy(2, {0, 0, 0}, {0, 1, 0}, 100.0);
  bad.patches[0].stiffness_k = std::numeric_limits<double>::quiet_NaN();
  exchange.publish(bad);
  EXPECT_EQ(take_latest_proxy(exchange, state, 10), ProxyIntake::kRejected);
  EXPECT_TRUE(state.invalid_latched);
  EXPECT_EQ(state.last_error, ProxyError::kNonFinite);
  EXPECT_EQ(active_proxy(state).sequence, 1u);  // the last valid one stays in use (fading)

  ContactProxy not_flagged = plane_proxy(3, {0, 0, 0}, {0, 1, 0}, 100.0);
  not_flagged.flags = 0;  // host says "unusable"
  exchange.publish(not_flagged);
  EXPECT_EQ(take_latest_proxy(exchange, state, 20), ProxyIntake::kRejected);
  EXPECT_EQ(state.rejected_count, 2u);

  exchange.publish(plane_proxy(4, {0, 0, 0}, {0, 1, 0}, 100.0));
  EXPECT_EQ(take_latest_proxy(exchange, state, 30), ProxyIntake::kAccepted);
  EXPECT_FALSE(state.invalid_latched);
  ASSERT_TRUE(state.have_previous);  // the last valid proxy, for the swap blend
  EXPECT_EQ(previous_proxy(state).sequence, 1u);
}

TEST(ProxyIntake, OlderSequencesAreIgnoredWithoutRefreshingTheAge) {
  ProxyExchange exchange;
  ProxyState state;
  exchange.publish(plane_proxy(5, {0, 0, 0}, {0, 1, 0}, 100.0));
  take_latest_proxy(exchange, state, 100);
  exchange.publish(plane_proxy(4, {0, 0, 0}, {0, 1, 0}, 100.0));
  EXPECT_EQ(take_latest_proxy(exchange, state, 900), ProxyIntake::kOutOfOrder);
  EXPECT_EQ(state.out_of_order_count, 1u);
  EXPECT_EQ(proxy_age_ns(state, 1000), 900);
  EXPECT_FALSE(state.invalid_latched);
}

}  // namespace
}  // namespace fissure::rt
