#include "fissure/rt_core/proxy_intake.hpp"

#include <gtest/gtest.h>

#include <cmath>
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

// A one-patch proxy whose plane (normal +y) sits at height y_m, built at host time t_ns.
ContactProxy surface_at(std::uint64_t sequence, double y_m, TimeNs t_ns, ToolPart part = ToolPart::kTool) {
  ContactProxy proxy = plane_proxy(sequence, {0.0, y_m, 0.0}, {0.0, 1.0, 0.0}, 1000.0);
  proxy.patches[0].reference_time_ns = t_ns;
  proxy.patches[0].tool_part = part;
  proxy.host_time_ns = t_ns;
  return proxy;
}

double plane_height(const ContactProxy& proxy) { return proxy.patches[0].plane_point_world_m[1]; }

constexpr TimeNs kHostPeriodNs = 10'000'000;  // a 100 Hz host

ProxyExtrapolation extrapolating() {
  ProxyExtrapolation on;
  on.enabled = true;
  return on;
}

TEST(ProxyIntake, ASteadilyMovingSurfaceIsExtrapolatedForAtMostOneHostPeriod) {
  ProxyExchange exchange;
  ProxyState state;
  const double speed = 0.02;  // the surface advances onto the tool at 2 cm/s
  for (int i = 0; i < 3; ++i) {
    exchange.publish(surface_at(static_cast<std::uint64_t>(i + 1), speed * 0.01 * i, i * kHostPeriodNs));
    ASSERT_EQ(take_latest_proxy(exchange, state, i * kHostPeriodNs, extrapolating()), ProxyIntake::kAccepted);
  }
  EXPECT_NEAR(plane_height(active_proxy(state)), 2 * speed * 0.01, 1e-15);  // age 0: as received
  take_latest_proxy(exchange, state, 2 * kHostPeriodNs + kHostPeriodNs / 2, extrapolating());
  EXPECT_NEAR(plane_height(active_proxy(state)), 2.5 * speed * 0.01, 1e-12);
  EXPECT_NEAR(plane_height(received_proxy(state)), 2 * speed * 0.01, 1e-15);  // the received copy is untouched
  // Host late: never further than one host period ahead of the last proxy.
  take_latest_proxy(exchange, state, 2 * kHostPeriodNs + 7 * kHostPeriodNs, extrapolating());
  EXPECT_NEAR(plane_height(active_proxy(state)), 3 * speed * 0.01, 1e-12);
}

TEST(ProxyIntake, AOneOffJumpIsNotExtrapolated) {
  ProxyExchange exchange;
  ProxyState state;
  // Still, still, then a 5 mm jump (contact lost/gained on the host): no trend behind it.
  const double heights[] = {0.0, 0.0, 0.005};
  for (int i = 0; i < 3; ++i) {
    exchange.publish(surface_at(static_cast<std::uint64_t>(i + 1), heights[i], i * kHostPeriodNs));
    take_latest_proxy(exchange, state, i * kHostPeriodNs, extrapolating());
  }
  take_latest_proxy(exchange, state, 2 * kHostPeriodNs + kHostPeriodNs / 2, extrapolating());
  EXPECT_EQ(plane_height(active_proxy(state)), 0.005);
  // A reversal (up, then down) is not a trend either.
  exchange.publish(surface_at(4, 0.004, 3 * kHostPeriodNs));
  take_latest_proxy(exchange, state, 3 * kHostPeriodNs, extrapolating());
  take_latest_proxy(exchange, state, 3 * kHostPeriodNs + kHostPeriodNs / 2, extrapolating());
  EXPECT_EQ(plane_height(active_proxy(state)), 0.004);
}

TEST(ProxyIntake, PatchesOfAnotherPartOrFacingElsewhereGiveNoSpeed) {
  ProxyExchange exchange;
  ProxyState state;
  exchange.publish(surface_at(1, 0.000, 0, ToolPart::kJawA));
  take_latest_proxy(exchange, state, 0, extrapolating());
  exchange.publish(surface_at(2, 0.001, kHostPeriodNs, ToolPart::kJawA));
  take_latest_proxy(exchange, state, kHostPeriodNs, extrapolating());
  exchange.publish(surface_at(3, 0.002, 2 * kHostPeriodNs, ToolPart::kJawB));  // the other jaw
  take_latest_proxy(exchange, state, 2 * kHostPeriodNs, extrapolating());
  take_latest_proxy(exchange, state, 2 * kHostPeriodNs + kHostPeriodNs / 2, extrapolating());
  EXPECT_EQ(plane_height(active_proxy(state)), 0.002);
  ContactProxy tilted = surface_at(4, 0.003, 3 * kHostPeriodNs, ToolPart::kJawB);
  tilted.patches[0].normal_world = {0.0, std::cos(0.3), std::sin(0.3)};  // 17° away from the last one
  exchange.publish(tilted);
  take_latest_proxy(exchange, state, 3 * kHostPeriodNs, extrapolating());
  take_latest_proxy(exchange, state, 3 * kHostPeriodNs + kHostPeriodNs / 2, extrapolating());
  EXPECT_EQ(plane_height(active_proxy(state)), 0.003);
}

TEST(ProxyIntake, ExtrapolationIsOffByDefaultAndThePreviousProxyIsExtrapolatedToTheSwapTick) {
  ProxyExchange exchange;
  ProxyState frozen_state;
  ProxyState state;
  const ProxyExtrapolation off;  // the default
  const ProxyExtrapolation on = extrapolating();
  for (int i = 0; i < 3; ++i) {
    exchange.publish(surface_at(static_cast<std::uint64_t>(i + 1), 0.001 * i, i * kHostPeriodNs));
    take_latest_proxy(exchange, state, i * kHostPeriodNs, on);
    exchange.publish(surface_at(static_cast<std::uint64_t>(i + 1), 0.001 * i, i * kHostPeriodNs));
    take_latest_proxy(exchange, frozen_state, i * kHostPeriodNs, off);
  }
  take_latest_proxy(exchange, frozen_state, 2 * kHostPeriodNs + kHostPeriodNs / 2, off);
  EXPECT_EQ(plane_height(active_proxy(frozen_state)), 0.002);
  // The swap blend compares the old proxy as it was being rendered at the swap tick.
  exchange.publish(surface_at(4, 0.0028, 3 * kHostPeriodNs));
  ASSERT_EQ(take_latest_proxy(exchange, state, 3 * kHostPeriodNs, on), ProxyIntake::kAccepted);
  ASSERT_TRUE(state.have_previous);
  EXPECT_NEAR(plane_height(previous_proxy(state)), 0.003, 1e-12);
  EXPECT_EQ(plane_height(active_proxy(state)), 0.0028);
}

}  // namespace
}  // namespace fissure::rt
