#include "fissure/shared/transport_spec.hpp"

#include <gtest/gtest.h>

#include <string>

#include "fissure/shared/udp_carrier.hpp"
#include "fissure/shared/wire_link.hpp"
#include "wire_test_messages.hpp"

namespace fissure::transport {
namespace {

TEST(TransportSpec, ParsesTheThreeForms) {
  EXPECT_EQ(parse_transport_spec("inproc").kind, TransportSpec::Kind::kInProcess);
  const TransportSpec can = parse_transport_spec("can:can0");
  EXPECT_EQ(can.kind, TransportSpec::Kind::kCan);
  EXPECT_EQ(can.can_interface, "can0");
  const TransportSpec udp = parse_transport_spec("udp:192.168.1.20:7400");
  EXPECT_EQ(udp.kind, TransportSpec::Kind::kUdp);
  EXPECT_EQ(udp.udp_host, "192.168.1.20");
  EXPECT_EQ(udp.udp_port, 7400);
}

TEST(TransportSpec, BadTextIsRefusedQuotingIt) {
  for (const char* text : {"tcp:x:1", "can:", "udp:host", "udp::5", "udp:h:0", "udp:h:70000", "udp:h:12x"}) {
    try {
      parse_transport_spec(text);
      FAIL() << text << " was accepted";
    } catch (const TransportError& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("'") + text + "'"), std::string::npos) << e.what();
    }
  }
}

TEST(TransportSpec, UdpRtListensAndHostSendsToIt) {
  MonotonicClock clock;
  // Find a free port by letting the kernel pick one, then hand it to the rt end.
  std::uint16_t port = 0;
  {
    UdpCarrierConfig probe;
    probe.local_address = "127.0.0.1";
    port = UdpCarrier(probe, clock).local_port();
  }
  const TransportSpec spec = parse_transport_spec("udp:127.0.0.1:" + std::to_string(port));
  std::unique_ptr<FrameCarrier> rt = open_carrier(spec, wire::Role::kRt, clock);
  std::unique_ptr<FrameCarrier> host = open_carrier(spec, wire::Role::kHost, clock);
  LinkSender sender(*host);
  LinkReceiver receiver(*rt, clock);
  const ContactProxy sent = test::make_proxy(8, 2);
  sender.publish(sent);
  sender.service();
  ContactProxy got;
  for (int poll = 0; poll < 1'000'000 && !receiver.try_take_proxy(got); ++poll) receiver.poll();
  test::expect_wire_equal(sent, got);
  EXPECT_THROW(open_carrier(parse_transport_spec("inproc"), wire::Role::kRt, clock), TransportError);
}

}  // namespace
}  // namespace fissure::transport
