#include "fissure/falcon_hw/falcon_stream_parser.hpp"

#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace fissure::falcon {
namespace {

using Bytes = std::vector<std::uint8_t>;

struct Found {
  std::uint64_t end_offset;  // stream offset one past the packet's '>'
  FalconPacket packet;
};

std::vector<Found> parse_all(FalconStreamParser& parser, const Bytes& stream, std::size_t chunk = 1) {
  std::vector<Found> found;
  for (std::size_t at = 0; at < stream.size(); at += chunk) {
    const std::size_t n = std::min(chunk, stream.size() - at);
    parser.feed(std::span<const std::uint8_t>(stream.data() + at, n),
                [&](const FalconPacket& p) { found.push_back({parser.stats().bytes_in, p}); });
  }
  return found;
}

void expect_counters_consistent(const FalconStreamParser& parser) {
  const StreamParserStats& s = parser.stats();
  EXPECT_EQ(s.bytes_in, kPacketSizeBytes * s.packets + s.total_discarded_bytes() + parser.pending_bytes());
  EXPECT_EQ(s.discarded_frames[static_cast<std::size_t>(DiscardReason::kOutsidePacket)], 0U);
}

FalconPacket reading_packet(std::int16_t a, std::int16_t b, std::int16_t c, std::uint8_t buttons = 0,
                            std::uint8_t homed = 0) {
  DeviceReading r;
  r.encoder_counts = {a, b, c};
  r.buttons = buttons;
  r.homed_mask = homed;
  return encode_reading(r);
}

void append(Bytes& stream, std::span<const std::uint8_t> bytes) { stream.insert(stream.end(), bytes.begin(), bytes.end()); }

std::uint64_t discarded(const FalconStreamParser& p, DiscardReason r) {
  return p.stats().discarded_bytes[static_cast<std::size_t>(r)];
}

TEST(FalconStreamParser, FindsPacketsInAnyChunking) {
  Bytes stream;
  const FalconPacket a = reading_packet(1, -2, 3, 0x5, 0x7);
  const FalconPacket b = reading_packet(-32768, 32767, 0);
  append(stream, a);
  append(stream, b);
  for (std::size_t chunk = 1; chunk <= stream.size(); ++chunk) {
    FalconStreamParser parser(PacketDirection::kDeviceToHost);
    const auto found = parse_all(parser, stream, chunk);
    ASSERT_EQ(found.size(), 2U) << "chunk " << chunk;
    EXPECT_EQ(found[0].packet, a);
    EXPECT_EQ(found[1].packet, b);
    EXPECT_EQ(parser.stats().total_discarded_bytes(), 0U);
    expect_counters_consistent(parser);
  }
}

TEST(FalconStreamParser, ResyncsAfterTornPacket) {
  const FalconPacket torn = reading_packet(11, 22, 33);
  const FalconPacket good = reading_packet(44, 55, 66);
  Bytes stream(torn.begin(), torn.begin() + 9);  // the tail of the first packet was lost
  append(stream, good);
  FalconStreamParser parser(PacketDirection::kDeviceToHost);
  const auto found = parse_all(parser, stream, 5);
  ASSERT_EQ(found.size(), 1U);
  EXPECT_EQ(found[0].packet, good);
  EXPECT_EQ(discarded(parser, DiscardReason::kRestarted), 9U);
  EXPECT_EQ(parser.stats().discarded_frames[static_cast<std::size_t>(DiscardReason::kRestarted)], 1U);
  expect_counters_consistent(parser);
}

TEST(FalconStreamParser, ResyncsAfterMisalignedStart) {
  const FalconPacket first = reading_packet(1, 2, 3);
  const FalconPacket second = reading_packet(4, 5, 6);
  Bytes stream(first.begin() + 6, first.end());  // we started listening mid-packet
  append(stream, second);
  FalconStreamParser parser(PacketDirection::kDeviceToHost);
  const auto found = parse_all(parser, stream);
  ASSERT_EQ(found.size(), 1U);
  EXPECT_EQ(found[0].packet, second);
  EXPECT_EQ(discarded(parser, DiscardReason::kOutsidePacket), 10U);
  expect_counters_consistent(parser);
}

TEST(FalconStreamParser, ShortPacketIsDiscardedAtItsEarlyEnd) {
  const FalconPacket p = reading_packet(7, 8, 9);
  Bytes stream(p.begin(), p.begin() + 5);  // bytes lost in the middle
  stream.insert(stream.end(), p.begin() + 12, p.end());
  append(stream, p);
  FalconStreamParser parser(PacketDirection::kDeviceToHost);
  const auto found = parse_all(parser, stream);
  ASSERT_EQ(found.size(), 1U);
  EXPECT_EQ(found[0].packet, p);
  EXPECT_EQ(discarded(parser, DiscardReason::kEarlyEnd), 9U);
  expect_counters_consistent(parser);
}

TEST(FalconStreamParser, InvalidNibbleDiscardsTheFrame) {
  FalconPacket bad = reading_packet(7, 8, 9);
  bad[4] = 0x51;  // 'Q': one past the largest nibble
  const FalconPacket good = reading_packet(1, 1, 1);
  Bytes stream(bad.begin(), bad.end());
  append(stream, good);
  FalconStreamParser parser(PacketDirection::kDeviceToHost);
  const auto found = parse_all(parser, stream);
  ASSERT_EQ(found.size(), 1U);
  EXPECT_EQ(found[0].packet, good);
  EXPECT_EQ(discarded(parser, DiscardReason::kInvalidPayload), 5U);       // '<' + 3 nibbles + 'Q'
  EXPECT_EQ(discarded(parser, DiscardReason::kOutsidePacket), 11U);       // the rest of the bad packet
  expect_counters_consistent(parser);
}

TEST(FalconStreamParser, SixteenthByteMustBeTheEndMarker) {
  FalconPacket long_packet = reading_packet(3, 3, 3);
  long_packet[15] = 'B';  // a 15th payload byte where '>' should be
  Bytes stream(long_packet.begin(), long_packet.end());
  stream.push_back(kPacketEndByte);
  const FalconPacket good = reading_packet(2, 2, 2);
  append(stream, good);
  FalconStreamParser parser(PacketDirection::kDeviceToHost);
  const auto found = parse_all(parser, stream);
  ASSERT_EQ(found.size(), 1U);
  EXPECT_EQ(found[0].packet, good);
  EXPECT_EQ(discarded(parser, DiscardReason::kMissingEnd), 16U);
  EXPECT_EQ(discarded(parser, DiscardReason::kOutsidePacket), 1U);
  expect_counters_consistent(parser);
}

TEST(FalconStreamParser, DirectionDecidesWhetherAWideFlagsByteIsValid) {
  const FalconPacket homed = reading_packet(0, 0, 0, 0x3, 0x7);  // byte 13 = 0x41 + 0x73 > 'P'
  Bytes stream(homed.begin(), homed.end());
  FalconStreamParser from_device(PacketDirection::kDeviceToHost);
  EXPECT_EQ(parse_all(from_device, stream).size(), 1U);
  FalconStreamParser from_host(PacketDirection::kHostToDevice);
  EXPECT_EQ(parse_all(from_host, stream).size(), 0U);
  EXPECT_EQ(discarded(from_host, DiscardReason::kInvalidPayload), 14U);
  expect_counters_consistent(from_host);
}

TEST(FalconStreamParser, ResetDropsThePartialFrame) {
  const FalconPacket p = reading_packet(5, 5, 5);
  FalconStreamParser parser(PacketDirection::kDeviceToHost);
  for (std::size_t i = 0; i < 10; ++i) EXPECT_FALSE(parser.push(p[i]));
  EXPECT_EQ(parser.pending_bytes(), 10U);
  parser.reset();
  EXPECT_EQ(parser.pending_bytes(), 0U);
  EXPECT_EQ(discarded(parser, DiscardReason::kReset), 10U);
  // The rest of that packet is now garbage; the next packet parses.
  Bytes stream(p.begin() + 10, p.end());
  append(stream, p);
  EXPECT_EQ(parse_all(parser, stream).size(), 1U);
  expect_counters_consistent(parser);
}

// ---------------------------------------------------------------- fuzz

// Garbage biased towards what confuses a parser: markers, valid nibbles, wide flag bytes.
std::uint8_t garbage_byte(std::mt19937_64& rng) {
  const std::uint64_t r = rng();
  switch (r % 6) {
    case 0: return kPacketStartByte;
    case 1: return kPacketEndByte;
    case 2:
    case 3: return static_cast<std::uint8_t>(kNibbleOffset + (r >> 8) % 16);
    case 4: return static_cast<std::uint8_t>(kNibbleOffset + (r >> 8) % 128);
    default: return static_cast<std::uint8_t>(r >> 8);
  }
}

FalconPacket random_valid_packet(std::mt19937_64& rng, PacketDirection direction) {
  FalconPacket packet{};
  packet.front() = kPacketStartByte;
  packet.back() = kPacketEndByte;
  for (std::size_t i = 1; i <= kReservedByteIndex; ++i) {
    const bool wide = direction == PacketDirection::kDeviceToHost && i == kFlagsByteIndex;
    packet[i] = static_cast<std::uint8_t>(kNibbleOffset + rng() % (wide ? 128 : 16));
  }
  return packet;
}

TEST(FalconStreamParser, FuzzMillionStreamsRecoversEveryIntactPacket) {
  constexpr int kStreams = 1'000'000;
  std::mt19937_64 rng(0xFA1C0DE);
  std::uint64_t hidden_total = 0;
  std::uint64_t found_total = 0;
  Bytes stream;
  std::vector<std::size_t> hidden_starts;
  std::vector<FalconPacket> hidden_packets;
  std::vector<Found> found;
  for (int s = 0; s < kStreams; ++s) {
    const auto direction = (s & 1) != 0 ? PacketDirection::kDeviceToHost : PacketDirection::kHostToDevice;
    stream.clear();
    hidden_starts.clear();
    hidden_packets.clear();
    if (rng() % 4 == 0) {  // start listening in the middle of a packet
      const FalconPacket p = random_valid_packet(rng, direction);
      stream.insert(stream.end(), p.begin() + static_cast<std::ptrdiff_t>(1 + rng() % 15), p.end());
    }
    const int segments = 1 + static_cast<int>(rng() % 6);
    for (int seg = 0; seg < segments; ++seg) {
      switch (rng() % 4) {
        case 0: {  // garbage
          const std::size_t n = rng() % 25;
          for (std::size_t i = 0; i < n; ++i) stream.push_back(garbage_byte(rng));
          break;
        }
        case 1: {  // a damaged packet: truncated, byte replaced, byte inserted or byte deleted
          FalconPacket p = random_valid_packet(rng, direction);
          Bytes damaged(p.begin(), p.end());
          const std::size_t at = 1 + rng() % 14;
          switch (rng() % 4) {
            case 0: damaged.resize(1 + rng() % 15); break;
            case 1: damaged[at] = garbage_byte(rng); break;
            case 2: damaged.insert(damaged.begin() + static_cast<std::ptrdiff_t>(at), garbage_byte(rng)); break;
            default: damaged.erase(damaged.begin() + static_cast<std::ptrdiff_t>(at)); break;
          }
          append(stream, damaged);
          break;
        }
        default: {  // an intact packet: must be recovered exactly
          const FalconPacket p = random_valid_packet(rng, direction);
          hidden_starts.push_back(stream.size());
          hidden_packets.push_back(p);
          append(stream, p);
          break;
        }
      }
    }

    FalconStreamParser parser(direction);
    found.clear();
    std::size_t at = 0;
    while (at < stream.size()) {  // arbitrary chunking, like USB transfers
      const std::size_t n = std::min<std::size_t>(1 + rng() % 40, stream.size() - at);
      parser.feed(std::span<const std::uint8_t>(stream.data() + at, n),
                  [&](const FalconPacket& p) { found.push_back({parser.stats().bytes_in, p}); });
      at += n;
    }

    // Every intact packet is found, at its own position, with its own bytes.
    std::size_t f = 0;
    for (std::size_t h = 0; h < hidden_starts.size(); ++h) {
      const std::uint64_t end = hidden_starts[h] + kPacketSizeBytes;
      while (f < found.size() && found[f].end_offset < end) ++f;
      ASSERT_LT(f, found.size()) << "stream " << s << ": intact packet at " << hidden_starts[h] << " lost";
      ASSERT_EQ(found[f].end_offset, end) << "stream " << s;
      ASSERT_EQ(found[f].packet, hidden_packets[h]) << "stream " << s;
    }
    // Everything reported is a valid packet that really is in the stream at that place.
    for (const Found& x : found) {
      ASSERT_TRUE(check_packet(direction, x.packet).ok()) << "stream " << s;
      ASSERT_GE(x.end_offset, kPacketSizeBytes);
      ASSERT_TRUE(std::equal(x.packet.begin(), x.packet.end(), stream.begin() + static_cast<std::ptrdiff_t>(x.end_offset - kPacketSizeBytes)))
          << "stream " << s;
    }
    // Stronger still: markers cannot be payload, so valid windows never overlap, and the
    // packets found must be exactly the valid 16-byte windows of the stream.
    std::size_t windows = 0;
    for (std::size_t i = 0; i + kPacketSizeBytes <= stream.size(); ++i) {
      if (stream[i] != kPacketStartByte || stream[i + kPacketSizeBytes - 1] != kPacketEndByte) continue;
      FalconPacket window{};
      std::copy_n(stream.begin() + static_cast<std::ptrdiff_t>(i), kPacketSizeBytes, window.begin());
      if (!check_packet(direction, window).ok()) continue;
      ASSERT_LT(windows, found.size()) << "stream " << s;
      ASSERT_EQ(found[windows].end_offset, i + kPacketSizeBytes) << "stream " << s;
      ++windows;
    }
    ASSERT_EQ(windows, found.size()) << "stream " << s;
    // Counters account for every byte.
    const StreamParserStats& st = parser.stats();
    ASSERT_EQ(st.bytes_in, stream.size());
    ASSERT_EQ(st.packets, found.size());
    ASSERT_EQ(st.bytes_in, kPacketSizeBytes * st.packets + st.total_discarded_bytes() + parser.pending_bytes())
        << "stream " << s;
    hidden_total += hidden_starts.size();
    found_total += found.size();
  }
  EXPECT_GT(hidden_total, 1'000'000U);  // the fuzz really exercised recovery
  EXPECT_GE(found_total, hidden_total);
}

}  // namespace
}  // namespace fissure::falcon
