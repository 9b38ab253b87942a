#pragma once
// Reassembly of wire frames into whole messages (the receiving half of wire_codec.hpp).
// Fixed-size buffers, no allocation, noexcept: the rt side runs it inside its tick.
//
// A message is handed out whole or not at all. Every received frame is accounted for by
// exactly one frame counter, and every message whose frames were accepted ends in exactly
// one message counter (or is still pending), so the counts add up:
//   frames_received  = frames_accepted + frames_too_short + frames_wrong_version
//                    + frames_unknown_type + frames_bad_segment + frames_duplicate_segment
//                    + frames_stale
//   messages_started = hellos_received + device_states_applied + proxies_applied
//                    + messages_crc_error + messages_malformed + messages_invalid
//                    + messages_duplicate + messages_out_of_order + messages_incomplete
//                    + messages_superseded + pending_assemblies()
#include <array>
#include <cstddef>
#include <cstdint>

#include "fissure/shared/message_validation.hpp"
#include "fissure/shared/messages.hpp"
#include "fissure/shared/time.hpp"
#include "fissure/shared/wire_codec.hpp"

namespace fissure::wire {

struct WireStats {
  // Frame level.
  std::uint64_t frames_received = 0;
  std::uint64_t frames_accepted = 0;           ///< stored into (or completing) a message
  std::uint64_t frames_too_short = 0;          ///< shorter than the 4-byte header
  std::uint64_t frames_wrong_version = 0;      ///< data frame of another protocol version
  std::uint64_t frames_unknown_type = 0;       ///< message type byte not known
  std::uint64_t frames_bad_segment = 0;        ///< index > last, too many segments, short chunk, count disagrees
  std::uint64_t frames_duplicate_segment = 0;  ///< segment already held for that message
  std::uint64_t frames_stale = 0;              ///< segment of a message already finished or superseded
  // Message level.
  std::uint64_t messages_started = 0;
  std::uint64_t hellos_received = 0;
  std::uint64_t device_states_applied = 0;
  std::uint64_t proxies_applied = 0;
  std::uint64_t messages_crc_error = 0;        ///< reassembled bytes fail the CRC-32C
  std::uint64_t messages_malformed = 0;        ///< length implied by the content disagrees with the segments
  std::uint64_t messages_invalid = 0;          ///< decoded but NaN/inf or out of range (message_validation)
  std::uint64_t messages_duplicate = 0;        ///< sequence equal to the last applied one of its type
  std::uint64_t messages_out_of_order = 0;     ///< sequence older than the last applied one (reordered)
  std::uint64_t messages_incomplete = 0;       ///< a segment never came (timeout or slot needed)
  std::uint64_t messages_superseded = 0;       ///< still incomplete when a newer message of its type applied

  [[nodiscard]] std::uint64_t frames_discarded() const noexcept {
    return frames_too_short + frames_wrong_version + frames_unknown_type + frames_bad_segment +
           frames_duplicate_segment + frames_stale;
  }
  [[nodiscard]] std::uint64_t messages_discarded() const noexcept {
    return messages_crc_error + messages_malformed + messages_invalid + messages_duplicate +
           messages_out_of_order + messages_incomplete + messages_superseded;
  }
};

struct ReassemblerConfig {
  /// An assembly not completed within this is dropped as incomplete. 50 ms: a full 10-frame
  /// proxy needs ≈ 1.7 ms on a 1/5 Mbit/s bus, so 50 ms only expires truly lost segments,
  /// while staying well under any useful proxy lifetime (the rt side fades a proxy older than
  /// its stale bound anyway).
  TimeNs assembly_timeout_ns = 50'000'000;
};

class Reassembler {
 public:
  /// Messages that can be in reassembly at once. Only proxies use slots (the others are one
  /// frame); 4 tolerates a proxy reordered across three newer ones.
  static constexpr std::size_t kSlots = 4;
  /// Transfer ids at most this far behind the last finished one are "old" (late segments);
  /// farther ones are new (the 8-bit id wrapped). 64 ≫ any reordering depth a bus produces.
  static constexpr int kStaleWindowTransfers = 64;

  explicit Reassembler(ReassemblerConfig config = {}) noexcept : config_(config) {}

  /// Feeds one received frame. Returns the type of the message it completed and that passed
  /// every check (read it with device_state()/contact_proxy()/hello() before the next push),
  /// or kNone. A Hello is returned whatever its protocol version (the handshake judges it).
  MessageType push(const CanFdFrame& frame, TimeNs now_ns) noexcept;

  [[nodiscard]] const DeviceState& device_state() const noexcept { return device_state_; }
  [[nodiscard]] const ContactProxy& contact_proxy() const noexcept { return contact_proxy_; }
  [[nodiscard]] const Hello& hello() const noexcept { return hello_; }

  /// Drops assemblies older than the timeout (push() does this too).
  void expire(TimeNs now_ns) noexcept;
  /// Forgets the last applied sequence numbers and transfer ids: the peer restarted and
  /// counts from the beginning again. Pending assemblies are discarded as incomplete.
  void reset_sequences() noexcept;

  [[nodiscard]] std::size_t pending_assemblies() const noexcept;
  [[nodiscard]] const WireStats& stats() const noexcept { return stats_; }
  /// Why the last message counted in messages_invalid was rejected.
  [[nodiscard]] ProxyError last_invalid_reason() const noexcept { return last_invalid_reason_; }

 private:
  struct Slot {
    bool in_use = false;
    MessageType type = MessageType::kNone;
    std::uint8_t version = 0;
    std::uint8_t transfer_id = 0;
    std::uint8_t segment_count = 0;
    std::uint16_t received_mask = 0;
    std::size_t last_segment_bytes = 0;
    TimeNs started_ns = 0;
    std::uint64_t start_order = 0;
    std::array<std::uint8_t, kMaxSegments * kSegmentBytes> bytes{};
  };
  struct TypeTrack {
    bool has_finished = false;     ///< a transfer of this type completed (applied or discarded)
    std::uint8_t last_transfer_id = 0;
    bool has_applied = false;
    std::uint64_t last_sequence = 0;
  };

  MessageType complete(MessageType type, std::uint8_t version, std::uint8_t transfer_id, std::uint8_t segment_count,
                       const std::uint8_t* message, std::size_t available) noexcept;
  bool is_stale(MessageType type, std::uint8_t transfer_id) const noexcept;
  void mark_finished(MessageType type, std::uint8_t transfer_id) noexcept;
  void supersede_older(MessageType type, std::uint8_t transfer_id) noexcept;
  Slot* find_or_claim_slot(MessageType type, std::uint8_t transfer_id, TimeNs now_ns) noexcept;
  TypeTrack& track(MessageType type) noexcept { return tracks_[static_cast<std::size_t>(type)]; }
  const TypeTrack& track(MessageType type) const noexcept { return tracks_[static_cast<std::size_t>(type)]; }

  ReassemblerConfig config_;
  std::array<Slot, kSlots> slots_{};
  std::array<TypeTrack, 4> tracks_{};
  std::uint64_t next_start_order_ = 0;
  WireStats stats_{};
  ProxyError last_invalid_reason_ = ProxyError::kNone;
  DeviceState device_state_{};
  ContactProxy contact_proxy_{};
  ContactProxy scratch_proxy_{};  ///< decoded here first; kept off the stack (1.2 KB)
  Hello hello_{};
};

}  // namespace fissure::wire
