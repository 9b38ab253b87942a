#include "fissure/shared/wire_handshake.hpp"

#include <cstdio>

namespace fissure::wire {

Handshake::Handshake(Role own_role, float publish_rate_hz, std::uint32_t session_id) noexcept
    : own_role_(own_role), publish_rate_hz_(publish_rate_hz), session_id_(session_id) {}

Hello Handshake::hello() const noexcept {
  Hello hello;
  hello.protocol_version = kProtocolVersion;
  hello.role = own_role_;
  hello.flags = state_ == HandshakeState::kEstablished ? kHelloPeerSeen : 0;
  hello.session_id = session_id_;
  hello.publish_rate_hz = publish_rate_hz_;
  return hello;
}

HandshakeEvent Handshake::on_hello(const Hello& peer) noexcept {
  HandshakeEvent event;
  event.peer_restarted = !has_peer_ || peer.session_id != peer_.session_id;
  has_peer_ = true;
  peer_ = peer;
  if (peer.protocol_version != kProtocolVersion) {
    state_ = HandshakeState::kFailed;
    error_ = HandshakeError::kVersionMismatch;
    const Role peer_role = peer.role == Role::kRt || peer.role == Role::kHost ? peer.role
                                                                              : (own_role_ == Role::kRt ? Role::kHost : Role::kRt);
    std::snprintf(error_message_.data(), error_message_.size(),
                  "wire protocol version mismatch: this %s speaks version %u, the %s peer speaks version %u "
                  "(run the same Fissure release on both ends)",
                  to_string(own_role_), static_cast<unsigned>(kProtocolVersion), to_string(peer_role),
                  static_cast<unsigned>(peer.protocol_version));
    peer_acknowledged_ = false;
    return event;
  }
  if (peer.role == own_role_ || (peer.role != Role::kRt && peer.role != Role::kHost)) {
    state_ = HandshakeState::kFailed;
    error_ = HandshakeError::kRoleConflict;
    std::snprintf(error_message_.data(), error_message_.size(),
                  "wire handshake: both ends claim to be '%s' (one must be rt, the other host)",
                  to_string(own_role_));
    peer_acknowledged_ = false;
    return event;
  }
  const bool newly_established = state_ != HandshakeState::kEstablished || event.peer_restarted;
  state_ = HandshakeState::kEstablished;
  error_ = HandshakeError::kNone;
  error_message_[0] = '\0';
  peer_acknowledged_ = (peer.flags & kHelloPeerSeen) != 0;
  event.established = true;
  // Reply when the peer has not seen us, and once on establishing: our earlier Hellos (if
  // any) went out without kHelloPeerSeen, and the peer keeps repeating until it gets one with it.
  event.reply_needed = !peer_acknowledged_ || newly_established;
  return event;
}

}  // namespace fissure::wire
