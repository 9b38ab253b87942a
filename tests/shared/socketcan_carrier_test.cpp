// SocketCAN: the error-frame decoding runs everywhere; the real-socket tests run where the
// kernel has AF_CAN and a vcan0 with the FD MTU, and skip with the setup command otherwise.
#include "fissure/shared/socketcan_carrier.hpp"

#include <linux/can.h>
#include <linux/can/error.h>

#include <gtest/gtest.h>

#include <string>

#include "fissure/shared/wire_link.hpp"
#include "wire_test_messages.hpp"

namespace fissure::transport {
namespace {

constexpr const char* kInterface = "vcan0";
constexpr const char* kSetupHint =
    "run `ip link add dev vcan0 type vcan; ip link set vcan0 mtu 72 up` on a kernel with vcan";
constexpr int kMaxPolls = 1'000'000;

TEST(CanErrorFrames, BusOffTxTimeoutAndRestartAreRecognised) {
  std::uint8_t data[CAN_ERR_DLC] = {};
  CanErrorReport report = classify_can_error_frame(CAN_ERR_FLAG | CAN_ERR_BUSOFF, data, CAN_ERR_DLC);
  EXPECT_TRUE(report.bus_off);
  EXPECT_FALSE(report.tx_timeout);
  report = classify_can_error_frame(CAN_ERR_FLAG | CAN_ERR_TX_TIMEOUT | CAN_ERR_ACK, data, CAN_ERR_DLC);
  EXPECT_TRUE(report.tx_timeout);
  EXPECT_TRUE(report.no_ack);
  EXPECT_FALSE(report.bus_off);
  data[1] = CAN_ERR_CRTL_TX_PASSIVE;
  EXPECT_TRUE(classify_can_error_frame(CAN_ERR_FLAG | CAN_ERR_CRTL, data, CAN_ERR_DLC).controller_problem);
  data[1] = CAN_ERR_CRTL_ACTIVE;
  EXPECT_FALSE(classify_can_error_frame(CAN_ERR_FLAG | CAN_ERR_CRTL, data, CAN_ERR_DLC).controller_problem)
      << "back to error-active is not a problem";
  EXPECT_TRUE(classify_can_error_frame(CAN_ERR_FLAG | CAN_ERR_RESTARTED, data, CAN_ERR_DLC).restarted);
  EXPECT_FALSE(classify_can_error_frame(CAN_ERR_BUSOFF, data, CAN_ERR_DLC).bus_off) << "not an error frame without the flag";
}

TEST(SocketCanCarrier, MissingKernelSupportIsAClearTransportError) {
  std::string reason;
  if (socketcan_supported(&reason)) GTEST_SKIP() << "this kernel has AF_CAN; the unsupported path cannot be shown here";
  EXPECT_NE(reason.find("AF_CAN unsupported by this kernel"), std::string::npos) << reason;
  MonotonicClock clock;
  try {
    SocketCanCarrier carrier(kInterface, clock);
    FAIL() << "expected TransportError";
  } catch (const TransportError& e) {
    EXPECT_EQ(e.kind(), TransportError::Kind::kUnsupported);
    EXPECT_NE(std::string(e.what()).find("AF_CAN"), std::string::npos) << e.what();
  }
}

/// Skips the calling test unless AF_CAN and vcan0 (MTU 72) are usable.
#define REQUIRE_VCAN0()                                                                                      \
  do {                                                                                                       \
    std::string reason;                                                                                      \
    if (!socketcan_supported(&reason)) GTEST_SKIP() << reason << "; " << kSetupHint;                         \
    try {                                                                                                    \
      MonotonicClock probe_clock;                                                                            \
      SocketCanCarrier probe(kInterface, probe_clock);                                                       \
    } catch (const TransportError& e) {                                                                      \
      if (e.kind() == TransportError::Kind::kNoSuchInterface || e.kind() == TransportError::Kind::kConfiguration) \
        GTEST_SKIP() << e.what() << "; " << kSetupHint;                                                      \
      throw;                                                                                                 \
    }                                                                                                        \
  } while (false)

TEST(SocketCanCarrier, ProxyRoundTripsOverVcan) {
  REQUIRE_VCAN0();
  MonotonicClock clock;
  SocketCanCarrier host_side(kInterface, clock);
  SocketCanCarrier rt_side(kInterface, clock);
  LinkSender sender(host_side);
  LinkReceiver receiver(rt_side, clock);
  const ContactProxy sent = test::make_proxy(31, kMaxContactPatches);
  const TimeNs before_ns = clock.now();
  ASSERT_EQ(sender.publish(sent), wire::EncodeStatus::kOk);
  for (int poll = 0; poll < kMaxPolls && !sender.idle(); ++poll) sender.service();  // vcan's queue may push back
  ContactProxy got;
  for (int poll = 0; poll < kMaxPolls && !receiver.try_take_proxy(got); ++poll) receiver.poll();
  test::expect_wire_equal(sent, got);
  EXPECT_EQ(rt_side.health().frames_received, 10u);
  // The proxy was received after it was published and is no older than the whole exchange.
  EXPECT_GE(receiver.proxy_age_ns(), 0);
  EXPECT_LE(receiver.proxy_age_ns(), clock.now() - before_ns);
}

TEST(SocketCanCarrier, ReceiveTimestampsAreOnTheMonotonicTimeline) {
  REQUIRE_VCAN0();
  MonotonicClock clock;
  SocketCanCarrier a(kInterface, clock);
  SocketCanCarrier b(kInterface, clock);
  CanFdFrame frame;
  frame.can_id = wire::can_id_for(wire::MessageType::kDeviceState);
  frame.length = 64;
  const TimeNs before_ns = clock.now();
  CarrierStatus sent = CarrierStatus::kBusy;
  for (int poll = 0; poll < kMaxPolls && sent == CarrierStatus::kBusy; ++poll) sent = a.try_send(frame);
  ASSERT_EQ(sent, CarrierStatus::kOk);
  ReceivedFrame received;
  CarrierStatus status = CarrierStatus::kEmpty;
  for (int poll = 0; poll < kMaxPolls && status == CarrierStatus::kEmpty; ++poll) status = b.try_receive(received);
  ASSERT_EQ(status, CarrierStatus::kOk);
  EXPECT_EQ(received.frame.length, 64);
  // 5 ms of slack for the realtime→monotonic mapping (both clocks read at different instants).
  EXPECT_GE(received.receive_time_ns, before_ns - 5'000'000);
  EXPECT_LE(received.receive_time_ns, clock.now() + 5'000'000);
}

TEST(SocketCanCarrier, ClassicMtuInterfaceIsRefusedWithTheFix) {
  std::string reason;
  if (!socketcan_supported(&reason)) GTEST_SKIP() << reason << "; " << kSetupHint;
  // Only meaningful where a classic-MTU interface exists; vcan0 set up per the hint has MTU 72.
  MonotonicClock clock;
  try {
    SocketCanCarrier carrier("vcan_classic", clock);
    GTEST_SKIP() << "vcan_classic has MTU 72: nothing to refuse";
  } catch (const TransportError& e) {
    if (e.kind() == TransportError::Kind::kNoSuchInterface) {
      GTEST_SKIP() << "no classic-MTU test interface: ip link add dev vcan_classic type vcan; ip link set vcan_classic up";
    }
    EXPECT_EQ(e.kind(), TransportError::Kind::kConfiguration);
    EXPECT_NE(std::string(e.what()).find("mtu 72"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace fissure::transport
