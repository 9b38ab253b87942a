#include "fissure/shared/wire_handshake.hpp"

#include <gtest/gtest.h>

#include <string>

#include "fissure/shared/loopback_carrier.hpp"
#include "fissure/shared/udp_carrier.hpp"
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

DeviceMapping clamp_mapping() {
  DeviceMapping mapping;
  mapping.scale = 2.0;
  mapping.clamp_mode = true;
  mapping.world_offset_m = {0.0, 0.1, 0.0};
  return mapping;
}

TEST(SessionFingerprint, CoversTheSceneNameAndEveryMappingField) {
  const DeviceMapping base = clamp_mapping();
  const std::uint64_t reference = session_fingerprint("clamp-vessel", base);
  EXPECT_EQ(session_fingerprint("clamp-vessel", base), reference) << "deterministic";
  EXPECT_NE(session_fingerprint("spatula-sphere", base), reference);
  DeviceMapping changed = base;
  changed.scale = 2.0000001;
  EXPECT_NE(session_fingerprint("clamp-vessel", changed), reference);
  changed = base;
  changed.axis_sign[1] = -1;
  EXPECT_NE(session_fingerprint("clamp-vessel", changed), reference);
  changed = base;
  changed.world_offset_m[2] = 1e-9;
  EXPECT_NE(session_fingerprint("clamp-vessel", changed), reference);
  changed = base;
  changed.closing_axis_world = 1;
  EXPECT_NE(session_fingerprint("clamp-vessel", changed), reference);
  EXPECT_NE(reference, 0u) << "0 means 'not checked'";
  const SessionIdentity identity = session_identity("clamp-vessel", base);
  EXPECT_EQ(identity.fingerprint, reference);
  EXPECT_STREQ(identity.scene_name.data(), "clamp-vessel");
  const SessionIdentity long_name = session_identity(std::string(100, 'x'), base);
  EXPECT_EQ(std::string(long_name.scene_name.data()).size(), kHelloSceneNameBytes - 1) << "cut, and terminated";
}

/// Runs two endpoints until both are established or both refused the other; bounded, no sleeps.
template <typename Pump>
void link_up(transport::LinkEndpoint& a, transport::LinkEndpoint& b, Pump&& between) {
  for (int i = 0; i < 100'000; ++i) {
    a.tick();
    b.tick();
    between();
    const bool both_refused = a.handshake().state() == HandshakeState::kFailed && b.handshake().state() == HandshakeState::kFailed;
    if (both_refused || (a.established() && b.established() && a.handshake().peer_acknowledged() && b.handshake().peer_acknowledged())) return;
  }
}

void expect_session_mismatch(const transport::LinkEndpoint& end, const char* own, const char* peer_role, const char* peer_scene) {
  EXPECT_FALSE(end.established());
  EXPECT_EQ(end.handshake().error(), HandshakeError::kSessionMismatch);
  const std::string message = end.handshake().error_message();
  EXPECT_NE(message.find(std::string("this ") + own), std::string::npos) << message;
  EXPECT_NE(message.find(std::string("the ") + peer_role + " peer runs scene '" + peer_scene + "'"), std::string::npos) << message;
  char fingerprint[24];
  std::snprintf(fingerprint, sizeof fingerprint, "%016llx", static_cast<unsigned long long>(end.handshake().peer().session_fingerprint));
  EXPECT_NE(message.find(fingerprint), std::string::npos) << "the peer's fingerprint in: " << message;
}

transport::LinkConfig end_config(Role role, std::uint32_t session, const char* scene, const DeviceMapping& mapping) {
  transport::LinkConfig config{.role = role, .session_id = session};
  config.identity = session_identity(scene, mapping);
  return config;
}

TEST(Handshake, SameSceneAndMappingLinkUpInProcess) {
  LockstepClock clock;
  transport::LoopbackLink link(clock);
  transport::LinkEndpoint rt(link.a(), clock, end_config(Role::kRt, 1, "clamp-vessel", clamp_mapping()));
  transport::LinkEndpoint host(link.b(), clock, end_config(Role::kHost, 2, "clamp-vessel", clamp_mapping()));
  link_up(rt, host, [&] { clock.advance(1'000'000); });
  EXPECT_TRUE(rt.established());
  EXPECT_TRUE(host.established());
  EXPECT_STREQ(rt.handshake().peer().scene_name.data(), "clamp-vessel");
}

TEST(Handshake, AnotherSceneIsRefusedAtBothEndsNamingBothInProcess) {
  // The case: rt on clamp-vessel, host on spatula-sphere.
  LockstepClock clock;
  transport::LoopbackLink link(clock);
  transport::LinkEndpoint rt(link.a(), clock, end_config(Role::kRt, 1, "clamp-vessel", clamp_mapping()));
  transport::LinkEndpoint host(link.b(), clock, end_config(Role::kHost, 2, "spatula-sphere", DeviceMapping{}));
  link_up(rt, host, [&] { clock.advance(1'000'000); });
  expect_session_mismatch(rt, "rt runs scene 'clamp-vessel'", "host", "spatula-sphere");
  expect_session_mismatch(host, "host runs scene 'spatula-sphere'", "rt", "clamp-vessel");
  // Data from a refused peer is never accepted.
  EXPECT_EQ(host.publish(ContactProxy{}), EncodeStatus::kOk);
  host.tick();
  rt.tick();
  EXPECT_FALSE(rt.receiver().has_proxy());
}

TEST(Handshake, SameSceneWithAnotherMappingIsRefused) {
  LockstepClock clock;
  transport::LoopbackLink link(clock);
  DeviceMapping other = clamp_mapping();
  other.force_scale = 0.5;
  transport::LinkEndpoint rt(link.a(), clock, end_config(Role::kRt, 1, "clamp-vessel", clamp_mapping()));
  transport::LinkEndpoint host(link.b(), clock, end_config(Role::kHost, 2, "clamp-vessel", other));
  link_up(rt, host, [&] { clock.advance(1'000'000); });
  expect_session_mismatch(rt, "rt runs scene 'clamp-vessel'", "host", "clamp-vessel");
}

TEST(Handshake, ARefusalIsAnsweredOnceSoThePeerCanRefuseToo) {
  Handshake rt(Role::kRt, 1000.0f, 1, session_identity("clamp-vessel", clamp_mapping()));
  Hello peer = hello_from(Role::kHost, kProtocolVersion, 2);
  peer.session_fingerprint = session_fingerprint("spatula-sphere", DeviceMapping{});
  EXPECT_TRUE(rt.on_hello(peer).reply_needed) << "the host must get our Hello to refuse us";
  EXPECT_FALSE(rt.on_hello(peer).reply_needed) << "not again for the same host session";
  peer.session_id = 3;
  EXPECT_TRUE(rt.on_hello(peer).reply_needed) << "a restarted host is answered again";
  EXPECT_EQ(rt.state(), HandshakeState::kFailed);
}

TEST(Handshake, AnEndWithoutAFingerprintIsNotChecked) {
  Handshake rt(Role::kRt, 1000.0f, 1, session_identity("clamp-vessel", clamp_mapping()));
  Hello peer = hello_from(Role::kHost, kProtocolVersion, 2);
  peer.session_fingerprint = 0;
  EXPECT_TRUE(rt.on_hello(peer).established);
}

TEST(Handshake, OverUdpTheMatchLinksAndTheMismatchIsRefused) {
  // Two real sockets on 127.0.0.1: the host end knows the rt end's port, the rt end learns
  // the host's address from its first datagram (as in a split deployment). Polls are bounded;
  // loopback UDP delivers within a few syscalls.
  for (const bool same_scene : {true, false}) {
    LockstepClock clock;
    transport::UdpCarrierConfig rt_udp;
    rt_udp.local_address = "127.0.0.1";
    transport::UdpCarrier rt_carrier(rt_udp, clock);
    transport::UdpCarrierConfig host_udp;
    host_udp.local_address = "127.0.0.1";
    host_udp.remote_address = "127.0.0.1";
    host_udp.remote_port = rt_carrier.local_port();
    transport::UdpCarrier host_carrier(host_udp, clock);
    transport::LinkEndpoint rt(rt_carrier, clock, end_config(Role::kRt, 1, "clamp-vessel", clamp_mapping()));
    transport::LinkEndpoint host(host_carrier, clock,
                                 end_config(Role::kHost, 2, same_scene ? "clamp-vessel" : "spatula-sphere",
                                            same_scene ? clamp_mapping() : DeviceMapping{}));
    link_up(rt, host, [&] { clock.advance(1'000'000); });
    if (same_scene) {
      EXPECT_TRUE(rt.established());
      EXPECT_TRUE(host.established());
    } else {
      expect_session_mismatch(rt, "rt runs scene 'clamp-vessel'", "host", "spatula-sphere");
      expect_session_mismatch(host, "host runs scene 'spatula-sphere'", "rt", "clamp-vessel");
    }
  }
}

TEST(Handshake, AGoodbyeMarksThePeerClosedUntilItStartsAgain) {
  LockstepClock clock;
  transport::LoopbackLink link(clock);
  transport::LinkEndpoint rt(link.a(), clock, end_config(Role::kRt, 1, "s", DeviceMapping{}));
  transport::LinkEndpoint host(link.b(), clock, end_config(Role::kHost, 2, "s", DeviceMapping{}));
  link_up(rt, host, [&] { clock.advance(1'000'000); });
  ASSERT_TRUE(rt.established());
  EXPECT_FALSE(rt.handshake().peer_closed());
  host.close();
  rt.tick();
  EXPECT_TRUE(rt.handshake().peer_closed());
  EXPECT_TRUE(rt.established()) << "a goodbye is not a refusal";
  // The host starting again (new session id) is a live peer once more.
  transport::LinkEndpoint host_again(link.b(), clock, end_config(Role::kHost, 3, "s", DeviceMapping{}));
  link_up(rt, host_again, [&] { clock.advance(1'000'000); });
  EXPECT_FALSE(rt.handshake().peer_closed());
}

}  // namespace
}  // namespace fissure::wire
