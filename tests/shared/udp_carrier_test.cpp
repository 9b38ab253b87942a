// The UDP carrier on 127.0.0.1 (ephemeral ports, non-blocking). No sleeps: receivers poll in
// a bounded loop; loopback UDP delivers within a few syscalls, the bound only stops a hang.
#include "fissure/shared/udp_carrier.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <string>

#include "fissure/shared/wire_link.hpp"
#include "wire_test_messages.hpp"

namespace fissure::transport {
namespace {

constexpr int kMaxPolls = 1'000'000;

UdpCarrierConfig bound_to(const std::string& address, std::uint16_t port) {
  UdpCarrierConfig config;
  config.local_address = address;
  config.local_port = port;
  return config;
}

UdpCarrierConfig local_only() { return bound_to("127.0.0.1", 0); }

UdpCarrierConfig towards(std::uint16_t port) {
  UdpCarrierConfig config = local_only();
  config.remote_address = "127.0.0.1";
  config.remote_port = port;
  return config;
}

TEST(UdpFrameLayout, PacksLikeCanfdFrameAndRejectsBadDatagrams) {
  CanFdFrame frame;
  frame.can_id = 0x103;
  frame.length = 48;
  frame.flags = wire::kCanFdBitRateSwitch;
  for (std::size_t i = 0; i < 48; ++i) frame.data[i] = static_cast<std::uint8_t>(i + 1);
  std::uint8_t datagram[80] = {};
  ASSERT_EQ(pack_udp_frame(frame, datagram), 8u + 48u);
  EXPECT_EQ(datagram[0], 0x03);
  EXPECT_EQ(datagram[1], 0x01);
  EXPECT_EQ(datagram[4], 48);
  EXPECT_EQ(datagram[5], wire::kCanFdBitRateSwitch);
  CanFdFrame back;
  ASSERT_TRUE(unpack_udp_frame(datagram, 56, back));
  EXPECT_EQ(back.can_id, frame.can_id);
  EXPECT_EQ(back.length, 48);
  EXPECT_EQ(back.data, frame.data);
  EXPECT_FALSE(unpack_udp_frame(datagram, 55, back)) << "size disagrees with the length byte";
  EXPECT_FALSE(unpack_udp_frame(datagram, 7, back)) << "shorter than the header";
  datagram[4] = 65;
  EXPECT_FALSE(unpack_udp_frame(datagram, 8 + 65, back)) << "longer than CAN FD allows";
}

TEST(UdpCarrier, ProxyAndDeviceStateRoundTripOverLoopbackUdp) {
  MonotonicClock clock;
  UdpCarrier listener(local_only(), clock);  // the rt end: learns its peer from the first frame
  ASSERT_NE(listener.local_port(), 0);
  UdpCarrier talker(towards(listener.local_port()), clock);
  EXPECT_FALSE(listener.has_remote());

  LinkSender host_sender(talker);
  LinkReceiver rt_receiver(listener, clock);
  // A clamp's full proxy with both jaws' friction: the largest message the shipped tools send.
  const ContactProxy sent = test::make_proxy(77, kMaxContactPatches, 0b110);
  ASSERT_EQ(host_sender.publish(sent), wire::EncodeStatus::kOk);
  EXPECT_EQ(host_sender.service(), 11u);
  ContactProxy got;
  for (int poll = 0; poll < kMaxPolls && !rt_receiver.try_take_proxy(got); ++poll) rt_receiver.poll();
  test::expect_wire_equal(sent, got);
  EXPECT_TRUE(listener.has_remote());

  // And back, to the learned address.
  LinkSender rt_sender(listener);
  LinkReceiver host_receiver(talker, clock);
  const DeviceState state = test::make_device_state(5);
  rt_sender.publish(state);
  EXPECT_EQ(rt_sender.service(), 1u);
  DeviceState got_state;
  for (int poll = 0; poll < kMaxPolls && !host_receiver.try_take_device_state(got_state); ++poll) host_receiver.poll();
  test::expect_wire_equal(state, got_state);
  EXPECT_EQ(talker.health().frames_received, 1u);
  EXPECT_EQ(listener.health().frames_received, 11u);
  test::expect_counts_add_up(rt_receiver.reassembler());
}

TEST(UdpCarrier, NothingWaitingIsEmptyNotABlock) {
  MonotonicClock clock;
  UdpCarrier carrier(local_only(), clock);
  ReceivedFrame frame;
  EXPECT_EQ(carrier.try_receive(frame), CarrierStatus::kEmpty);
}

TEST(UdpCarrier, ListenerWithoutPeerCannotSendYet) {
  MonotonicClock clock;
  UdpCarrier listener(local_only(), clock);
  EXPECT_EQ(listener.try_send(CanFdFrame{}), CarrierStatus::kError);
  EXPECT_EQ(listener.health().last_errno, ENOTCONN);
}

TEST(UdpCarrier, MalformedDatagramsAreCountedAndSkipped) {
  MonotonicClock clock;
  UdpCarrier listener(local_only(), clock);
  const int raw = socket(AF_INET, SOCK_DGRAM, 0);
  ASSERT_GE(raw, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(listener.local_port());
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const char junk[5] = {1, 2, 3, 4, 5};
  ASSERT_EQ(sendto(raw, junk, sizeof junk, 0, reinterpret_cast<const sockaddr*>(&to), sizeof to), 5);
  CanFdFrame good;
  good.can_id = 0x102;
  good.length = 8;
  std::uint8_t datagram[80];
  const std::size_t size = pack_udp_frame(good, datagram);
  ASSERT_EQ(sendto(raw, datagram, size, 0, reinterpret_cast<const sockaddr*>(&to), sizeof to), static_cast<ssize_t>(size));
  close(raw);
  ReceivedFrame frame;
  CarrierStatus status = CarrierStatus::kEmpty;
  for (int poll = 0; poll < kMaxPolls && status != CarrierStatus::kOk; ++poll) status = listener.try_receive(frame);
  ASSERT_EQ(status, CarrierStatus::kOk);
  EXPECT_EQ(frame.frame.can_id, 0x102u);
  EXPECT_EQ(listener.health().malformed_received, 1u);
}

TEST(UdpCarrier, BadAddressesFailWithTheAddressInTheMessage) {
  MonotonicClock clock;
  try {
    UdpCarrier carrier(bound_to("no-such-host.invalid", 0), clock);
    FAIL() << "expected TransportError";
  } catch (const TransportError& e) {
    EXPECT_NE(std::string(e.what()).find("no-such-host.invalid"), std::string::npos) << e.what();
  }
  UdpCarrier first(local_only(), clock);
  try {
    UdpCarrier second(bound_to("127.0.0.1", first.local_port()), clock);
    FAIL() << "expected TransportError (port in use)";
  } catch (const TransportError& e) {
    EXPECT_NE(std::string(e.what()).find("127.0.0.1:" + std::to_string(first.local_port())), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace fissure::transport
