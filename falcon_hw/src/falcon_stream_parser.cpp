#include "fissure/falcon_hw/falcon_stream_parser.hpp"

namespace fissure::falcon {

const char* to_string(DiscardReason reason) noexcept {
  switch (reason) {
    case DiscardReason::kOutsidePacket: return "outside packet";
    case DiscardReason::kRestarted: return "restarted by '<' (torn packet)";
    case DiscardReason::kEarlyEnd: return "early '>' (short packet)";
    case DiscardReason::kInvalidPayload: return "invalid payload byte";
    case DiscardReason::kMissingEnd: return "16th byte not '>'";
    case DiscardReason::kReset: return "reset";
    case DiscardReason::kCount: break;
  }
  return "unknown";
}

std::uint64_t StreamParserStats::total_discarded_bytes() const noexcept {
  std::uint64_t total = 0;
  for (const std::uint64_t n : discarded_bytes) total += n;
  return total;
}

std::uint64_t StreamParserStats::total_discarded_frames() const noexcept {
  std::uint64_t total = 0;
  for (const std::uint64_t n : discarded_frames) total += n;
  return total;
}

void FalconStreamParser::discard_frame(DiscardReason reason, std::size_t bytes) noexcept {
  const auto index = static_cast<std::size_t>(reason);
  stats_.discarded_bytes[index] += bytes;
  stats_.discarded_frames[index] += 1;
  length_ = 0;
}

bool FalconStreamParser::push(std::uint8_t byte) noexcept {
  ++stats_.bytes_in;
  if (byte == kPacketStartByte) {
    // A new packet starts here, whatever we were doing: a partial frame was torn.
    if (length_ > 0) discard_frame(DiscardReason::kRestarted, length_);
    frame_[0] = byte;
    length_ = 1;
    return false;
  }
  if (length_ == 0) {
    stats_.discarded_bytes[static_cast<std::size_t>(DiscardReason::kOutsidePacket)] += 1;
    return false;
  }
  if (length_ == kPacketSizeBytes - 1) {
    if (byte != kPacketEndByte) {
      discard_frame(DiscardReason::kMissingEnd, kPacketSizeBytes);
      return false;
    }
    frame_[length_] = byte;
    length_ = 0;
    ++stats_.packets;
    return true;
  }
  if (byte == kPacketEndByte) {
    discard_frame(DiscardReason::kEarlyEnd, length_ + 1);
    return false;
  }
  if (!is_valid_payload_byte(direction_, length_, byte)) {
    discard_frame(DiscardReason::kInvalidPayload, length_ + 1);
    return false;
  }
  frame_[length_++] = byte;
  return false;
}

void FalconStreamParser::reset() noexcept {
  if (length_ > 0) discard_frame(DiscardReason::kReset, length_);
}

}  // namespace fissure::falcon
