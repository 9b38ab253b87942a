#include "fissure/shared/wire_link.hpp"

#include <gtest/gtest.h>

#include "fissure/shared/loopback_carrier.hpp"
#include "wire_test_messages.hpp"

namespace fissure::transport {
namespace {

using test::expect_wire_equal;
using test::make_device_state;
using test::make_proxy;

constexpr TimeNs kTick_ns = 1'000'000;  // 1 kHz rt tick in these tests

/// Both ends of a link on one lockstep clock.
struct LinkPair {
  LockstepClock clock{0};
  LoopbackLink link{clock};
  LinkEndpoint rt{link.a(), clock, LinkConfig{.role = wire::Role::kRt, .publish_rate_hz = 1000.0f, .session_id = 100}};
  LinkEndpoint host{link.b(), clock, LinkConfig{.role = wire::Role::kHost, .publish_rate_hz = 100.0f, .session_id = 200}};

  void step() {
    clock.advance(kTick_ns);
    rt.tick();
    host.tick();
  }
};

TEST(LinkEndpoint, HandshakeCompletesAndStopsSendingHellos) {
  LinkPair pair;
  pair.step();
  pair.step();
  pair.step();
  EXPECT_TRUE(pair.rt.established());
  EXPECT_TRUE(pair.host.established());
  EXPECT_TRUE(pair.rt.handshake().peer_acknowledged());
  EXPECT_TRUE(pair.host.handshake().peer_acknowledged());
  EXPECT_EQ(pair.host.handshake().peer().publish_rate_hz, 1000.0f);
  const std::uint64_t hellos = pair.rt.receiver().wire_stats().hellos_received + pair.host.receiver().wire_stats().hellos_received;
  for (int i = 0; i < 1000; ++i) pair.step();  // a full second: past many Hello periods
  EXPECT_EQ(pair.rt.receiver().wire_stats().hellos_received + pair.host.receiver().wire_stats().hellos_received, hellos)
      << "no Hellos once both sides acknowledged";
}

TEST(LinkEndpoint, DataFlowsBothWaysAndAgesTrackTheLastGoodMessage) {
  LinkPair pair;
  for (int i = 0; i < 3; ++i) pair.step();
  ASSERT_TRUE(pair.rt.established() && pair.host.established());

  for (std::uint64_t n = 1; n <= 100; ++n) {
    const DeviceState state = make_device_state(n);
    pair.rt.publish(state);
    if (n % 10 == 0) pair.host.publish(make_proxy(n / 10, 2));  // 100 Hz host
    pair.step();
    DeviceState got_state;
    ASSERT_TRUE(pair.host.receiver().try_take_device_state(got_state)) << n;
    expect_wire_equal(state, got_state);
    EXPECT_FALSE(pair.host.receiver().try_take_device_state(got_state)) << "taken once";
  }
  // step() ticks rt before host, so the host's last proxy reaches rt on rt's next tick.
  pair.clock.advance(kTick_ns);
  pair.rt.tick();
  ContactProxy proxy;
  ASSERT_TRUE(pair.rt.receiver().try_take_proxy(proxy));
  expect_wire_equal(make_proxy(10, 2), proxy);
  EXPECT_EQ(pair.rt.receiver().proxy_age_ns(), 0) << "received in the last rt tick";

  // The host dies: the rt side sees the proxy age grow and can fade it (BRIEF §5).
  constexpr TimeNs kStaleBound_ns = 50'000'000;
  for (int i = 0; i < 60; ++i) {
    pair.clock.advance(kTick_ns);
    pair.rt.publish(make_device_state(200 + static_cast<std::uint64_t>(i)));
    pair.rt.tick();
  }
  EXPECT_EQ(pair.rt.receiver().proxy_age_ns(), 60 * kTick_ns);
  EXPECT_FALSE(pair.rt.receiver().proxy_fresh(kStaleBound_ns));

  // The rt dies: the host notices the DeviceState age. (Its first tick here still receives
  // the samples rt sent meanwhile, so the age counts from that tick: 59 ticks.)
  for (int i = 0; i < 60; ++i) {
    pair.clock.advance(kTick_ns);
    pair.host.tick();
  }
  EXPECT_EQ(pair.host.receiver().device_state_age_ns(), 59 * kTick_ns);
  EXPECT_FALSE(pair.host.receiver().device_state_fresh(kStaleBound_ns));
}

TEST(LinkEndpoint, NothingIsAgedBeforeTheFirstMessage) {
  LinkPair pair;
  EXPECT_EQ(pair.rt.receiver().proxy_age_ns(), kNeverReceived);
  EXPECT_FALSE(pair.rt.receiver().proxy_fresh(1'000'000'000));
  EXPECT_FALSE(pair.rt.receiver().has_proxy());
}

TEST(LinkEndpoint, DataBeforeTheHandshakeIsIgnoredAndCounted) {
  LockstepClock clock;
  LoopbackLink link(clock);
  LinkEndpoint rt(link.a(), clock, LinkConfig{.role = wire::Role::kRt, .session_id = 1});
  LinkSender rogue(link.b());  // a host that never says Hello
  rogue.publish(make_proxy(1, 1));
  rogue.service();
  rt.tick();
  EXPECT_FALSE(rt.receiver().has_proxy());
  EXPECT_EQ(rt.receiver().stats().data_before_handshake, 1u);
}

TEST(LinkEndpoint, RestartedHostIsAcceptedAgainFromSequenceOne) {
  LockstepClock clock;
  LoopbackLink link(clock);
  LinkEndpoint rt(link.a(), clock, LinkConfig{.role = wire::Role::kRt, .session_id = 1});
  ContactProxy got;
  {
    LinkEndpoint host(link.b(), clock, LinkConfig{.role = wire::Role::kHost, .session_id = 2});
    for (int i = 0; i < 3; ++i) {
      clock.advance(kTick_ns);
      rt.tick();
      host.tick();
    }
    host.publish(make_proxy(500, 1));
    host.tick();
    rt.tick();
    ASSERT_TRUE(rt.receiver().try_take_proxy(got));
    EXPECT_EQ(got.sequence, 500u);
  }
  // A new host process: new session id, sequence numbers from 1 again.
  LinkEndpoint host(link.b(), clock, LinkConfig{.role = wire::Role::kHost, .session_id = 3});
  for (int i = 0; i < 3; ++i) {
    clock.advance(kTick_ns);
    host.tick();
    rt.tick();
  }
  host.publish(make_proxy(1, 1));
  host.tick();
  rt.tick();
  ASSERT_TRUE(rt.receiver().try_take_proxy(got)) << "not mistaken for an old, out-of-order proxy";
  expect_wire_equal(make_proxy(1, 1), got);
}

/// A carrier that accepts a fixed number of frames per "bus slot", like a saturated CAN bus.
class ThrottledCarrier final : public FrameCarrier {
 public:
  explicit ThrottledCarrier(FrameCarrier& inner) : inner_(inner) {}
  void allow(int frames) { budget_ = frames; }
  CarrierStatus try_send(const CanFdFrame& frame) noexcept override {
    if (budget_ == 0) return CarrierStatus::kBusy;
    --budget_;
    return inner_.try_send(frame);
  }
  CarrierStatus try_receive(ReceivedFrame& out) noexcept override { return inner_.try_receive(out); }
  const CarrierHealth& health() const noexcept override { return inner_.health(); }

 private:
  FrameCarrier& inner_;
  int budget_ = 0;
};

TEST(LinkSender, FinishesTheMessageInFlightThenSendsOnlyTheNewest) {
  LockstepClock clock;
  LoopbackLink link(clock);
  ThrottledCarrier throttled(link.a());
  LinkSender sender(throttled);
  LinkReceiver receiver(link.b(), clock, nullptr, LinkReceiverConfig{.max_frames_per_poll = 1});

  ASSERT_EQ(sender.publish(make_proxy(1, 8)), wire::EncodeStatus::kOk);  // 10 frames
  throttled.allow(3);
  EXPECT_EQ(sender.service(), 3u);
  sender.publish(make_proxy(2, 8));
  sender.publish(make_proxy(3, 8));  // replaces 2 before any of it went out
  throttled.allow(1000);
  sender.service();
  EXPECT_TRUE(sender.idle());
  EXPECT_EQ(sender.stats().messages_skipped, 1u);
  EXPECT_EQ(sender.stats().messages_sent, 2u);
  EXPECT_EQ(sender.stats().carrier_busy, 1u);

  std::vector<std::uint64_t> received_sequences;
  ContactProxy got;
  while (receiver.poll().frames > 0) {
    if (receiver.try_take_proxy(got)) received_sequences.push_back(got.sequence);
  }
  EXPECT_EQ(received_sequences, (std::vector<std::uint64_t>{1, 3}));
  EXPECT_EQ(receiver.wire_stats().messages_started, 2u) << "nothing of proxy 2 reached the wire";
}

TEST(LinkSender, QueuedButUnstartedMessageIsReplacedInPlace) {
  LockstepClock clock;
  LoopbackLink link(clock);
  ThrottledCarrier throttled(link.a());
  LinkSender sender(throttled);
  LinkReceiver receiver(link.b(), clock);
  sender.publish(make_device_state(1));
  sender.publish(make_device_state(2));
  throttled.allow(10);
  sender.service();
  receiver.poll();
  DeviceState got;
  ASSERT_TRUE(receiver.try_take_device_state(got));
  EXPECT_EQ(got.sequence, 2u);
  EXPECT_EQ(receiver.wire_stats().messages_started, 1u);
}

TEST(LinkSender, CarrierErrorDropsTheRestOfTheMessage) {
  class FailingCarrier final : public FrameCarrier {
   public:
    CarrierStatus try_send(const CanFdFrame&) noexcept override { return CarrierStatus::kError; }
    CarrierStatus try_receive(ReceivedFrame&) noexcept override { return CarrierStatus::kEmpty; }
    const CarrierHealth& health() const noexcept override { return health_; }
    CarrierHealth health_{};
  } failing;
  LinkSender sender(failing);
  sender.publish(make_proxy(1, 4));
  EXPECT_EQ(sender.service(), 0u);
  EXPECT_TRUE(sender.idle());
  EXPECT_EQ(sender.stats().messages_send_failed, 1u) << "the first failed frame ends the message";
  EXPECT_EQ(sender.stats().frames_sent, 0u);
}

}  // namespace
}  // namespace fissure::transport
