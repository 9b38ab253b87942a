// The carrier contract on the in-memory loopback (the UDP and SocketCAN carriers have their
// own suites): order, both directions, receive timestamps from the injected clock, back-pressure.
#include "fissure/shared/loopback_carrier.hpp"

#include <gtest/gtest.h>

#include <thread>

namespace fissure::transport {
namespace {

CanFdFrame frame_with(std::uint8_t tag) {
  CanFdFrame frame;
  frame.can_id = 0x102;
  frame.length = 12;
  frame.data[0] = tag;
  return frame;
}

TEST(LoopbackCarrier, DeliversInOrderInBothDirectionsWithClockTimestamps) {
  LockstepClock clock(5'000);
  LoopbackLink link(clock);
  for (std::uint8_t tag = 0; tag < 10; ++tag) ASSERT_EQ(link.a().try_send(frame_with(tag)), CarrierStatus::kOk);
  ASSERT_EQ(link.b().try_send(frame_with(99)), CarrierStatus::kOk);
  ReceivedFrame received;
  EXPECT_EQ(link.a().try_receive(received), CarrierStatus::kOk);
  EXPECT_EQ(received.frame.data[0], 99);
  EXPECT_EQ(link.a().try_receive(received), CarrierStatus::kEmpty) << "a does not hear itself";
  for (std::uint8_t tag = 0; tag < 10; ++tag) {
    clock.advance(100);
    ASSERT_EQ(link.b().try_receive(received), CarrierStatus::kOk);
    EXPECT_EQ(received.frame.data[0], tag);
    EXPECT_EQ(received.frame.length, 12);
    EXPECT_EQ(received.receive_time_ns, 5'000 + 100 * (tag + 1));
  }
  EXPECT_EQ(link.b().try_receive(received), CarrierStatus::kEmpty);
  EXPECT_EQ(link.a().health().frames_sent, 10u);
  EXPECT_EQ(link.b().health().frames_received, 10u);
}

TEST(LoopbackCarrier, FullQueueReportsBusyInsteadOfBlocking) {
  LockstepClock clock;
  LoopbackLink link(clock);
  for (std::size_t i = 0; i < LoopbackLink::kCapacityFrames; ++i) ASSERT_EQ(link.a().try_send(frame_with(1)), CarrierStatus::kOk);
  EXPECT_EQ(link.a().try_send(frame_with(2)), CarrierStatus::kBusy);
  EXPECT_EQ(link.a().health().send_busy, 1u);
  ReceivedFrame received;
  ASSERT_EQ(link.b().try_receive(received), CarrierStatus::kOk);
  EXPECT_EQ(link.a().try_send(frame_with(2)), CarrierStatus::kOk) << "room again after one was taken";
}

TEST(LoopbackCarrier, EndsMayLiveOnTwoThreads) {
  LockstepClock clock;
  LoopbackLink link(clock);
  constexpr int kFrames = 20'000;
  std::thread producer([&] {
    for (int i = 0; i < kFrames;) {
      CanFdFrame frame = frame_with(static_cast<std::uint8_t>(i));
      frame.data[1] = static_cast<std::uint8_t>(i >> 8);
      if (link.a().try_send(frame) == CarrierStatus::kOk) ++i;
    }
  });
  int expected = 0;
  ReceivedFrame received;
  while (expected < kFrames) {
    if (link.b().try_receive(received) != CarrierStatus::kOk) continue;
    ASSERT_EQ(received.frame.data[0] | (received.frame.data[1] << 8), expected & 0xFFFF);
    ++expected;
  }
  producer.join();
}

}  // namespace
}  // namespace fissure::transport
