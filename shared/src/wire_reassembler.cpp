#include "fissure/shared/wire_reassembler.hpp"

#include <algorithm>
#include <cstring>

namespace fissure::wire {
namespace {

/// Signed distance a → b of 8-bit wrapping counters, in [−128, 127].
int transfer_distance(std::uint8_t from, std::uint8_t to) noexcept {
  return static_cast<std::int8_t>(static_cast<std::uint8_t>(to - from));
}

}  // namespace

MessageType Reassembler::push(const CanFdFrame& frame, TimeNs now_ns) noexcept {
  ++stats_.frames_received;
  expire(now_ns);
  const std::size_t length = std::min<std::size_t>(frame.length, kCanFdMaxDataBytes);
  if (length < kFrameHeaderBytes) {
    ++stats_.frames_too_short;
    return MessageType::kNone;
  }
  const FrameHeader header = parse_header(frame);
  const auto type = static_cast<MessageType>(header.type);
  const std::size_t max_segments = max_segments_for(type);
  if (max_segments == 0) {
    ++stats_.frames_unknown_type;
    return MessageType::kNone;
  }
  // A Hello is read whatever its version: that is how a mismatch gets reported by number.
  if (type != MessageType::kHello && header.version != kProtocolVersion) {
    ++stats_.frames_wrong_version;
    return MessageType::kNone;
  }
  const std::size_t chunk_bytes = length - kFrameHeaderBytes;
  const bool is_last_segment = header.segment_index + 1 == header.segment_count;
  if (header.segment_index >= header.segment_count || header.segment_count > max_segments ||
      (!is_last_segment && chunk_bytes < kSegmentBytes)) {
    ++stats_.frames_bad_segment;
    return MessageType::kNone;
  }
  // Only proxies are tracked by transfer id: the one-frame messages are judged by their
  // sequence number alone (a late duplicate then counts as messages_duplicate).
  if (type == MessageType::kContactProxy && is_stale(type, header.transfer_id)) {
    ++stats_.frames_stale;
    return MessageType::kNone;
  }
  if (header.segment_count == 1) {
    ++stats_.frames_accepted;
    ++stats_.messages_started;
    return complete(type, header.version, header.transfer_id, 1, frame.data.data() + kFrameHeaderBytes, chunk_bytes);
  }

  Slot* slot = nullptr;
  for (Slot& candidate : slots_) {
    if (candidate.in_use && candidate.type == type && candidate.transfer_id == header.transfer_id) slot = &candidate;
  }
  const std::uint16_t segment_bit = static_cast<std::uint16_t>(1u << header.segment_index);
  if (slot != nullptr) {
    if (slot->segment_count != header.segment_count || slot->version != header.version) {
      ++stats_.frames_bad_segment;
      return MessageType::kNone;
    }
    if ((slot->received_mask & segment_bit) != 0) {
      ++stats_.frames_duplicate_segment;
      return MessageType::kNone;
    }
  } else {
    slot = find_or_claim_slot(type, header.transfer_id, now_ns);
    slot->version = header.version;
    slot->segment_count = header.segment_count;
    ++stats_.messages_started;
  }
  const std::size_t stored_bytes = std::min(chunk_bytes, kSegmentBytes);
  std::memcpy(slot->bytes.data() + header.segment_index * kSegmentBytes, frame.data.data() + kFrameHeaderBytes,
              stored_bytes);
  slot->received_mask = static_cast<std::uint16_t>(slot->received_mask | segment_bit);
  if (is_last_segment) slot->last_segment_bytes = stored_bytes;
  ++stats_.frames_accepted;

  const std::uint16_t all_segments = static_cast<std::uint16_t>((1u << slot->segment_count) - 1u);
  if (slot->received_mask != all_segments) return MessageType::kNone;
  slot->in_use = false;
  const std::size_t available = (slot->segment_count - 1u) * kSegmentBytes + slot->last_segment_bytes;
  return complete(type, slot->version, slot->transfer_id, slot->segment_count, slot->bytes.data(), available);
}

MessageType Reassembler::complete(MessageType type, std::uint8_t version, std::uint8_t transfer_id,
                                  std::uint8_t segment_count, const std::uint8_t* message,
                                  std::size_t available) noexcept {
  const std::size_t message_bytes = message_bytes_for(type, message, available);
  if (message_bytes == 0 || message_bytes > available || segments_for(message_bytes) != segment_count) {
    ++stats_.messages_malformed;
    return MessageType::kNone;
  }
  if (!crc_matches(version, type, transfer_id, segment_count, message, message_bytes)) {
    // The transfer id itself may be the corrupted byte: do not let it mark anything finished.
    ++stats_.messages_crc_error;
    return MessageType::kNone;
  }
  switch (type) {
    case MessageType::kHello:
      decode_hello(message, hello_);
      ++stats_.hellos_received;
      return MessageType::kHello;

    case MessageType::kDeviceState: {
      DeviceState decoded;
      decode_device_state(message, decoded);
      TypeTrack& tr = track(type);
      if (!is_finite(decoded)) {
        ++stats_.messages_invalid;
        last_invalid_reason_ = ProxyError::kNonFinite;
        return MessageType::kNone;
      }
      if (tr.has_applied && decoded.sequence <= tr.last_sequence) {
        ++(decoded.sequence == tr.last_sequence ? stats_.messages_duplicate : stats_.messages_out_of_order);
        return MessageType::kNone;
      }
      tr.has_applied = true;
      tr.last_sequence = decoded.sequence;
      device_state_ = decoded;
      ++stats_.device_states_applied;
      return MessageType::kDeviceState;
    }

    case MessageType::kContactProxy: {
      // Decode into the output only once every check passed: contact_proxy() keeps the last
      // good proxy, never a half-checked one.
      ContactProxy& decoded = scratch_proxy_;
      decode_contact_proxy(message, decoded);
      TypeTrack& tr = track(type);
      mark_finished(type, transfer_id);
      const ProxyError error = validate(decoded);
      if (error != ProxyError::kNone) {
        ++stats_.messages_invalid;
        last_invalid_reason_ = error;
        return MessageType::kNone;
      }
      if (tr.has_applied && decoded.sequence <= tr.last_sequence) {
        ++(decoded.sequence == tr.last_sequence ? stats_.messages_duplicate : stats_.messages_out_of_order);
        return MessageType::kNone;
      }
      tr.has_applied = true;
      tr.last_sequence = decoded.sequence;
      supersede_older(type, transfer_id);
      contact_proxy_ = decoded;
      ++stats_.proxies_applied;
      return MessageType::kContactProxy;
    }

    case MessageType::kNone: break;
  }
  return MessageType::kNone;
}

bool Reassembler::is_stale(MessageType type, std::uint8_t transfer_id) const noexcept {
  const TypeTrack& tr = track(type);
  if (!tr.has_finished) return false;
  const int distance = transfer_distance(tr.last_transfer_id, transfer_id);
  return distance <= 0 && distance >= -kStaleWindowTransfers;
}

void Reassembler::mark_finished(MessageType type, std::uint8_t transfer_id) noexcept {
  TypeTrack& tr = track(type);
  if (!tr.has_finished || transfer_distance(tr.last_transfer_id, transfer_id) > 0) {
    tr.last_transfer_id = transfer_id;
    tr.has_finished = true;
  }
}

void Reassembler::supersede_older(MessageType type, std::uint8_t transfer_id) noexcept {
  for (Slot& slot : slots_) {
    if (!slot.in_use || slot.type != type) continue;
    const int distance = transfer_distance(transfer_id, slot.transfer_id);
    if (distance < 0 && distance >= -kStaleWindowTransfers) {
      slot.in_use = false;
      ++stats_.messages_superseded;
    }
  }
}

Reassembler::Slot* Reassembler::find_or_claim_slot(MessageType type, std::uint8_t transfer_id, TimeNs now_ns) noexcept {
  Slot* chosen = nullptr;
  for (Slot& slot : slots_) {
    if (!slot.in_use) {
      chosen = &slot;
      break;
    }
  }
  if (chosen == nullptr) {
    // All busy: the oldest assembly is the one most likely missing a segment for good.
    chosen = &slots_[0];
    for (Slot& slot : slots_) {
      if (slot.start_order < chosen->start_order) chosen = &slot;
    }
    ++stats_.messages_incomplete;
  }
  chosen->in_use = true;
  chosen->type = type;
  chosen->transfer_id = transfer_id;
  chosen->received_mask = 0;
  chosen->last_segment_bytes = 0;
  chosen->started_ns = now_ns;
  chosen->start_order = next_start_order_++;
  return chosen;
}

void Reassembler::expire(TimeNs now_ns) noexcept {
  for (Slot& slot : slots_) {
    if (slot.in_use && now_ns - slot.started_ns > config_.assembly_timeout_ns) {
      slot.in_use = false;
      ++stats_.messages_incomplete;
    }
  }
}

void Reassembler::reset_sequences() noexcept {
  for (Slot& slot : slots_) {
    if (slot.in_use) {
      slot.in_use = false;
      ++stats_.messages_incomplete;
    }
  }
  tracks_ = {};
}

std::size_t Reassembler::pending_assemblies() const noexcept {
  return static_cast<std::size_t>(std::count_if(slots_.begin(), slots_.end(), [](const Slot& s) { return s.in_use; }));
}

}  // namespace fissure::wire
