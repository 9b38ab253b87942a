#include "fissure/shared/wire_handshake.hpp"

#include <algorithm>
#include <cstdio>
#include <cstring>

namespace fissure::wire {

namespace {

constexpr std::uint64_t kFnvOffsetBasis = 0xcbf29ce484222325ull;
constexpr std::uint64_t kFnvPrime = 0x100000001b3ull;

void fnv_bytes(std::uint64_t& hash, const void* data, std::size_t bytes) noexcept {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < bytes; ++i) {
    hash ^= p[i];
    hash *= kFnvPrime;
  }
}

void fnv_double(std::uint64_t& hash, double value) noexcept {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  for (int i = 0; i < 8; ++i) {  // byte order fixed: the two ends may differ in endianness
    const auto byte = static_cast<unsigned char>(bits >> (8 * i));
    fnv_bytes(hash, &byte, 1);
  }
}

const char* shown_name(const std::array<char, kHelloSceneNameBytes>& name) noexcept {
  return name[0] == '\0' ? "(none)" : name.data();
}

}  // namespace

std::uint64_t session_fingerprint(std::string_view scene_name, const DeviceMapping& mapping) noexcept {
  std::uint64_t hash = kFnvOffsetBasis;
  fnv_bytes(hash, scene_name.data(), scene_name.size());
  const unsigned char separator = 0;
  fnv_bytes(hash, &separator, 1);
  fnv_double(hash, mapping.scale);
  fnv_double(hash, mapping.force_scale);
  fnv_bytes(hash, mapping.axis_permutation.data(), mapping.axis_permutation.size());
  fnv_bytes(hash, mapping.axis_sign.data(), mapping.axis_sign.size());
  for (const double v : mapping.device_origin_m) fnv_double(hash, v);
  for (const double v : mapping.world_offset_m) fnv_double(hash, v);
  const unsigned char clamp = mapping.clamp_mode ? 1 : 0;
  fnv_bytes(hash, &clamp, 1);
  fnv_bytes(hash, &mapping.closing_axis_world, 1);
  return hash == 0 ? 1 : hash;
}

SessionIdentity session_identity(std::string_view scene_name, const DeviceMapping& mapping) noexcept {
  SessionIdentity identity;
  identity.fingerprint = session_fingerprint(scene_name, mapping);
  const std::size_t length = std::min(scene_name.size(), identity.scene_name.size() - 1);
  std::copy_n(scene_name.data(), length, identity.scene_name.data());
  return identity;
}

Handshake::Handshake(Role own_role, float publish_rate_hz, std::uint32_t session_id, SessionIdentity identity) noexcept
    : own_role_(own_role), publish_rate_hz_(publish_rate_hz), session_id_(session_id), identity_(identity) {}

Hello Handshake::hello(bool closing) const noexcept {
  Hello hello;
  hello.protocol_version = kProtocolVersion;
  hello.role = own_role_;
  hello.flags = static_cast<std::uint8_t>((state_ == HandshakeState::kEstablished ? kHelloPeerSeen : 0) |
                                          (closing ? kHelloClosing : 0));
  hello.session_id = session_id_;
  hello.publish_rate_hz = publish_rate_hz_;
  hello.session_fingerprint = identity_.fingerprint;
  hello.scene_name = identity_.scene_name;
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
  if (identity_.fingerprint != 0 && peer.session_fingerprint != 0 && peer.session_fingerprint != identity_.fingerprint) {
    // Answer the first refusal of a peer session at once: the peer needs our Hello to refuse us
    // too (and name both scenes) before it gives up, and an end that stops after a refusal may
    // be gone before its next periodic Hello. Only once, so two refusing ends do not ping-pong.
    event.reply_needed = error_ != HandshakeError::kSessionMismatch || event.peer_restarted;
    state_ = HandshakeState::kFailed;
    error_ = HandshakeError::kSessionMismatch;
    std::snprintf(error_message_.data(), error_message_.size(),
                  "session mismatch: this %s runs scene '%s' (fingerprint %016llx of scene and device mapping), "
                  "the %s peer runs scene '%s' (fingerprint %016llx); start both ends with the same scene file",
                  to_string(own_role_), shown_name(identity_.scene_name), static_cast<unsigned long long>(identity_.fingerprint),
                  to_string(peer.role), shown_name(peer.scene_name), static_cast<unsigned long long>(peer.session_fingerprint));
    peer_acknowledged_ = false;
    return event;
  }
  if ((peer.flags & kHelloClosing) != 0) {
    // A goodbye: the link stays judged (the peer was compatible), its data ends on purpose.
    peer_closed_ = state_ == HandshakeState::kEstablished && !event.peer_restarted;
    event.established = state_ == HandshakeState::kEstablished;
    return event;
  }
  peer_closed_ = false;
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
