#pragma once
// Finds Falcon packets in a byte stream fed in arbitrary chunks (USB transfers tear packets
// anywhere). Runs in the RT tick: a fixed 16-byte frame buffer, no allocation, noexcept.
//
// The input is payload bytes only: the 2 FTDI modem-status bytes that start every 64-byte
// USB IN packet are stripped by the transport (usb_transport.hpp, strip_ftdi_status_bytes),
// because only the transport knows where USB packet boundaries are.
//
// Resynchronisation rule: '<' always starts a new frame (abandoning any partial one), since
// no valid payload byte can be '<' or '>' (falcon_packet.hpp). Hence a packet that arrives
// intact is always recovered, whatever garbage or torn packet came before it. Every byte
// that does not end up in a packet is counted under exactly one DiscardReason, so
//   bytes_in == 16·packets + Σ discarded_bytes + pending_bytes()   at all times.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "fissure/falcon_hw/falcon_packet.hpp"

namespace fissure::falcon {

enum class DiscardReason : std::uint8_t {
  kOutsidePacket = 0,  ///< byte seen while not inside a frame (garbage between packets)
  kRestarted,          ///< partial frame abandoned because a new '<' arrived (torn packet)
  kEarlyEnd,           ///< '>' before the 16th byte (packet lost bytes in the middle)
  kInvalidPayload,     ///< a payload byte outside its range (corruption)
  kMissingEnd,         ///< 16th byte is not '>' (packet gained bytes / misaligned)
  kReset,              ///< partial frame dropped by reset() (after a purge)
  kCount,
};
const char* to_string(DiscardReason reason) noexcept;

inline constexpr std::size_t kDiscardReasonCount = static_cast<std::size_t>(DiscardReason::kCount);

struct StreamParserStats {
  std::uint64_t bytes_in = 0;
  std::uint64_t packets = 0;
  /// Bytes thrown away, by reason.
  std::array<std::uint64_t, kDiscardReasonCount> discarded_bytes{};
  /// Partial frames thrown away, by reason (kOutsidePacket counts no frames: always 0).
  std::array<std::uint64_t, kDiscardReasonCount> discarded_frames{};

  [[nodiscard]] std::uint64_t total_discarded_bytes() const noexcept;
  [[nodiscard]] std::uint64_t total_discarded_frames() const noexcept;
};

class FalconStreamParser {
 public:
  explicit FalconStreamParser(PacketDirection direction) noexcept : direction_(direction) {}

  /// Consumes one byte. Returns true when it completed a valid packet, which packet() then
  /// holds until the next push().
  bool push(std::uint8_t byte) noexcept;

  /// Consumes all of `bytes`, calling on_packet(const FalconPacket&) for each packet found,
  /// in stream order. Returns the number of packets found.
  template <class OnPacket>
  std::size_t feed(std::span<const std::uint8_t> bytes, OnPacket&& on_packet) noexcept {
    std::size_t found = 0;
    for (const std::uint8_t byte : bytes) {
      if (push(byte)) {
        ++found;
        on_packet(static_cast<const FalconPacket&>(frame_));
      }
    }
    return found;
  }

  /// Drops a partial frame (counted as kReset), e.g. after the transport purged its buffers.
  void reset() noexcept;

  [[nodiscard]] const FalconPacket& packet() const noexcept { return frame_; }
  /// Bytes of the current partial frame (0..15).
  [[nodiscard]] std::size_t pending_bytes() const noexcept { return length_; }
  [[nodiscard]] const StreamParserStats& stats() const noexcept { return stats_; }
  [[nodiscard]] PacketDirection direction() const noexcept { return direction_; }

 private:
  void discard_frame(DiscardReason reason, std::size_t bytes) noexcept;

  PacketDirection direction_;
  FalconPacket frame_{};
  std::size_t length_ = 0;  // bytes of frame_ filled; 0 = waiting for '<'
  StreamParserStats stats_{};
};

}  // namespace fissure::falcon
