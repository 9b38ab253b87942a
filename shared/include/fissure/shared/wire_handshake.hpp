#pragma once
// The link handshake: each end announces its protocol version, role and publish rate in a
// Hello and judges the peer's. A peer speaking another version is refused with an error
// naming both versions; a new session id means the peer restarted (its sequence numbers
// start over). Pure state machine, noexcept, no allocation.
#include <array>
#include <cstdint>

#include "fissure/shared/wire_codec.hpp"

namespace fissure::wire {

enum class HandshakeState : std::uint8_t { kAwaitingPeer, kEstablished, kFailed };
enum class HandshakeError : std::uint8_t { kNone, kVersionMismatch, kRoleConflict };

/// What one received Hello changed.
struct HandshakeEvent {
  bool established = false;     ///< the link is (still) usable after this Hello
  bool peer_restarted = false;  ///< first Hello of this peer session: forget its old sequence numbers
  bool reply_needed = false;    ///< send a Hello now: the peer has not seen ours, or we just established
};

class Handshake {
 public:
  Handshake(Role own_role, float publish_rate_hz, std::uint32_t session_id) noexcept;

  /// The Hello to send now (kHelloPeerSeen set once a compatible peer Hello arrived).
  [[nodiscard]] Hello hello() const noexcept;
  HandshakeEvent on_hello(const Hello& peer) noexcept;

  [[nodiscard]] HandshakeState state() const noexcept { return state_; }
  [[nodiscard]] HandshakeError error() const noexcept { return error_; }
  /// One line, e.g. "wire protocol version mismatch: this rt speaks version 1, the host peer
  /// speaks version 2 (run the same Fissure release on both ends)"; "" when no error.
  [[nodiscard]] const char* error_message() const noexcept { return error_message_.data(); }
  /// True once the peer's Hello says it has seen ours (no more Hellos needed).
  [[nodiscard]] bool peer_acknowledged() const noexcept { return peer_acknowledged_; }
  [[nodiscard]] const Hello& peer() const noexcept { return peer_; }

 private:
  Role own_role_;
  float publish_rate_hz_;
  std::uint32_t session_id_;
  HandshakeState state_ = HandshakeState::kAwaitingPeer;
  HandshakeError error_ = HandshakeError::kNone;
  bool has_peer_ = false;
  bool peer_acknowledged_ = false;
  Hello peer_{};
  std::array<char, 192> error_message_{};
};

}  // namespace fissure::wire
