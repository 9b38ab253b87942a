#pragma once
// The link handshake: each end announces its protocol version, role, publish rate and what it
// runs (the session fingerprint of its scene and device mapping) in a Hello and judges the
// peer's. A peer speaking another version, or running another scene or mapping, is refused
// with an error naming both values; a new session id means the peer restarted (its sequence
// numbers start over); a Hello with kHelloClosing means the peer stopped cleanly (its data
// ends on purpose, not by a crash or a cut link). Pure state machine, noexcept, no allocation.
#include <array>
#include <cstdint>
#include <string_view>

#include "fissure/shared/session_config.hpp"
#include "fissure/shared/wire_codec.hpp"

namespace fissure::wire {

enum class HandshakeState : std::uint8_t { kAwaitingPeer, kEstablished, kFailed };
enum class HandshakeError : std::uint8_t { kNone, kVersionMismatch, kRoleConflict, kSessionMismatch };

/// What an end runs, as its Hello announces it. fingerprint 0: not checked (an end started
/// without a scene, or a tool that links without one).
struct SessionIdentity {
  std::uint64_t fingerprint = 0;
  std::array<char, kHelloSceneNameBytes> scene_name{};
};

/// FNV-1a 64 over the scene name and every field of the device mapping (doubles by their bit
/// patterns): the two ends of a split session must run the same scene with the same mapping,
/// or the host renders contacts for a tool the rt end places elsewhere. Never 0.
[[nodiscard]] std::uint64_t session_fingerprint(std::string_view scene_name, const DeviceMapping& mapping) noexcept;
[[nodiscard]] SessionIdentity session_identity(std::string_view scene_name, const DeviceMapping& mapping) noexcept;

/// What one received Hello changed.
struct HandshakeEvent {
  bool established = false;     ///< the link is (still) usable after this Hello
  bool peer_restarted = false;  ///< first Hello of this peer session: forget its old sequence numbers
  bool reply_needed = false;    ///< send a Hello now: the peer has not seen ours, or we just established
};

class Handshake {
 public:
  Handshake(Role own_role, float publish_rate_hz, std::uint32_t session_id, SessionIdentity identity = {}) noexcept;

  /// The Hello to send now (kHelloPeerSeen set once a compatible peer Hello arrived);
  /// `closing`: the goodbye of an end stopping cleanly.
  [[nodiscard]] Hello hello(bool closing = false) const noexcept;
  HandshakeEvent on_hello(const Hello& peer) noexcept;

  [[nodiscard]] HandshakeState state() const noexcept { return state_; }
  [[nodiscard]] HandshakeError error() const noexcept { return error_; }
  /// One line, e.g. "wire protocol version mismatch: this rt speaks version 1, the host peer
  /// speaks version 2 (run the same Fissure release on both ends)"; "" when no error.
  [[nodiscard]] const char* error_message() const noexcept { return error_message_.data(); }
  /// True once the peer's Hello says it has seen ours (no more Hellos needed).
  [[nodiscard]] bool peer_acknowledged() const noexcept { return peer_acknowledged_; }
  [[nodiscard]] const Hello& peer() const noexcept { return peer_; }
  /// True once the established peer said goodbye (kHelloClosing), until it starts again.
  [[nodiscard]] bool peer_closed() const noexcept { return peer_closed_; }

 private:
  Role own_role_;
  float publish_rate_hz_;
  std::uint32_t session_id_;
  SessionIdentity identity_;
  bool peer_closed_ = false;
  HandshakeState state_ = HandshakeState::kAwaitingPeer;
  HandshakeError error_ = HandshakeError::kNone;
  bool has_peer_ = false;
  bool peer_acknowledged_ = false;
  Hello peer_{};
  std::array<char, 320> error_message_{};
};

}  // namespace fissure::wire
