#include "fissure/shared/wire_handshake.hpp"

#include <gtest/gtest.h>

#include <string>

#include "fissure/shared/loopback_carrier.hpp"
#include "fissure/shared/wire_link.hpp"

namespace fissure::wire {
namespace {

Hello hello_from(Role role, std::uint16_t version, std::uint32_t session, std::uint8_t flags = 0) {
  Hello hello;
  hello.protocol_version = version;
  hello.role = role;
  hello.session_id = session;
  hello.flags = flags;
  hello.publish_rate_hz = 100.0f;
  return hello;
}

TEST(Handshake, CompatiblePeerEstablishesAndIsAskedForAnAcknowledgement) {
  Handshake rt(Role::kRt, 1000.0f, 11);
  EXPECT_EQ(rt.state(), HandshakeState::kAwaitingPeer);
  EXPECT_EQ(rt.hello().flags & kHelloPeerSeen, 0);
  HandshakeEvent event = rt.on_hello(hello_from(Role::kHost, kProtocolVersion, 22));
  EXPECT_TRUE(event.established);
  EXPECT_TRUE(event.peer_restarted) << "first Hello of a session";
  EXPECT_TRUE(event.reply_needed) << "the host has not seen us yet";
  EXPECT_EQ(rt.state(), HandshakeState::kEstablished);
  EXPECT_EQ(rt.hello().flags & kHelloPeerSeen, kHelloPeerSeen);
  EXPECT_FALSE(rt.peer_acknowledged());
  event = rt.on_hello(hello_from(Role::kHost, kProtocolVersion, 22, kHelloPeerSeen));
  EXPECT_FALSE(event.peer_restarted);
  EXPECT_FALSE(event.reply_needed);
  EXPECT_TRUE(rt.peer_acknowledged());
  EXPECT_STREQ(rt.error_message(), "");
  EXPECT_EQ(rt.peer().publish_rate_hz, 100.0f);
}

TEST(Handshake, VersionMismatchIsRefusedNamingBothVersions) {
  Handshake rt(Role::kRt, 1000.0f, 11);
  const std::uint16_t peer_version = kProtocolVersion + 1;
  const HandshakeEvent event = rt.on_hello(hello_from(Role::kHost, peer_version, 22));
  EXPECT_FALSE(event.established);
  EXPECT_EQ(rt.state(), HandshakeState::kFailed);
  EXPECT_EQ(rt.error(), HandshakeError::kVersionMismatch);
  const std::string message = rt.error_message();
  EXPECT_NE(message.find("this rt speaks version " + std::to_string(kProtocolVersion)), std::string::npos) << message;
  EXPECT_NE(message.find("host peer speaks version " + std::to_string(peer_version)), std::string::npos) << message;
  // The same peer coming back with the right version is accepted again.
  EXPECT_TRUE(rt.on_hello(hello_from(Role::kHost, kProtocolVersion, 23)).established);
  EXPECT_STREQ(rt.error_message(), "");
}

TEST(Handshake, TwoEndsClaimingTheSameRoleAreRefused) {
  Handshake host(Role::kHost, 100.0f, 1);
  EXPECT_FALSE(host.on_hello(hello_from(Role::kHost, kProtocolVersion, 2)).established);
  EXPECT_EQ(host.error(), HandshakeError::kRoleConflict);
  EXPECT_NE(std::string(host.error_message()).find("'host'"), std::string::npos);
}

TEST(Handshake, NewSessionIdMeansThePeerRestarted) {
  Handshake rt(Role::kRt, 1000.0f, 11);
  rt.on_hello(hello_from(Role::kHost, kProtocolVersion, 22));
  EXPECT_FALSE(rt.on_hello(hello_from(Role::kHost, kProtocolVersion, 22)).peer_restarted);
  EXPECT_TRUE(rt.on_hello(hello_from(Role::kHost, kProtocolVersion, 23)).peer_restarted);
}

TEST(Handshake, MismatchTravelsOverTheWireAndDataIsRefused) {
  // A host of a newer protocol on the other end of a real link: its Hello still decodes
  // (frozen layout), the rt end reports both versions, and its data frames are discarded.
  LockstepClock clock;
  transport::LoopbackLink link(clock);
  transport::LinkEndpoint rt(link.a(), clock, transport::LinkConfig{.role = Role::kRt, .session_id = 5});
  const std::uint16_t future_version = kProtocolVersion + 1;
  FrameBatch batch;
  ASSERT_EQ(encode(hello_from(Role::kHost, future_version, 9), 0, batch), EncodeStatus::kOk);
  ASSERT_EQ(link.b().try_send(batch.frames[0]), transport::CarrierStatus::kOk);
  ASSERT_EQ(encode(ContactProxy{}, 0, batch), EncodeStatus::kOk);
  batch.frames[0].data[0] = static_cast<std::uint8_t>(future_version);  // what that host's frames carry
  ASSERT_EQ(link.b().try_send(batch.frames[0]), transport::CarrierStatus::kOk);
  rt.tick();
  EXPECT_FALSE(rt.established());
  EXPECT_EQ(rt.handshake().error(), HandshakeError::kVersionMismatch);
  const std::string message = rt.handshake().error_message();
  EXPECT_NE(message.find("version " + std::to_string(kProtocolVersion)), std::string::npos) << message;
  EXPECT_NE(message.find("version " + std::to_string(future_version)), std::string::npos) << message;
  EXPECT_EQ(rt.receiver().wire_stats().frames_wrong_version, 1u);
  EXPECT_FALSE(rt.receiver().has_proxy());
}

}  // namespace
}  // namespace fissure::wire
