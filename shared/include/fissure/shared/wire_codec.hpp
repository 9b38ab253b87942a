#pragma once
// The wire codec: DeviceState, ContactProxy and the handshake Hello in CAN FD frames
// (BRIEF §2, §8; the byte layout is documented in docs/wire_protocol.md).
//
// Every frame starts with a 4-byte header:
//   byte 0  protocol version (kProtocolVersion, one byte)
//   byte 1  message type (MessageType)
//   byte 2  transfer id: the sender's per-type message counter, mod 256 (matches segments)
//   byte 3  bits 0–3 segment index, bits 4–7 index of the last segment (count − 1)
// followed by up to 60 bytes of the message. A message is its body followed by a CRC-32C
// over (version, type, transfer id, segment count, body); the body is compact: float32 for geometry,
// the orientation as "smallest three" float32 components, and only patch_count patches.
// Encoding and decoding are noexcept and allocation-free (fixed-size FrameBatch).
#include <array>
#include <cstddef>
#include <cstdint>

#include "fissure/shared/can_fd_frame.hpp"
#include "fissure/shared/messages.hpp"

namespace fissure::wire {

static_assert(kProtocolVersion <= 0xFF, "the frame header carries the protocol version in one byte");

inline constexpr std::size_t kFrameHeaderBytes = 4;
/// Message bytes per frame: a 64-byte FD frame minus the header.
inline constexpr std::size_t kSegmentBytes = kCanFdMaxDataBytes - kFrameHeaderBytes;
/// The segment index and count share one header byte (4 bits each).
inline constexpr std::size_t kMaxSegments = 16;
inline constexpr std::size_t kCrcBytes = 4;

enum class MessageType : std::uint8_t {
  kNone = 0,
  kHello = 1,         ///< handshake; its layout is frozen across protocol versions
  kDeviceState = 2,   ///< rt → host
  kContactProxy = 3,  ///< host → rt
};

/// 11-bit CAN identifiers: lower wins arbitration, so the rt heartbeat (DeviceState) goes
/// before the bulkier proxy segments. 0x100 keeps clear of typical vehicle/ECU ranges on a lab bus.
inline constexpr std::uint32_t kCanIdBase = 0x100;
constexpr std::uint32_t can_id_for(MessageType type) noexcept { return kCanIdBase + static_cast<std::uint32_t>(type); }

/// Which end of the link a peer is.
enum class Role : std::uint8_t { kRt = 1, kHost = 2 };
const char* to_string(Role role) noexcept;

enum HelloFlags : std::uint8_t {
  kHelloPeerSeen = 1u << 0,  ///< the sender has received a compatible Hello from us
  kHelloClosing = 1u << 1,   ///< the sender is stopping cleanly: no more data will follow
};

/// Bytes of the scene name a Hello carries (zero-padded; a longer name is cut).
inline constexpr std::size_t kHelloSceneNameBytes = 32;
/// The first protocol version whose Hello carries the fingerprint and scene name.
inline constexpr std::uint16_t kHelloFingerprintVersion = 3;

/// Handshake message. Its first 12 bytes (version, role, flags, session id, rate) never change
/// with kProtocolVersion, so a peer of any version can read them and report a mismatch with both
/// version numbers; the length follows from the version (12 body bytes before version 3, 52 from it).
struct Hello {
  std::uint16_t protocol_version = kProtocolVersion;
  Role role = Role::kRt;
  std::uint8_t flags = 0;        ///< HelloFlags
  std::uint32_t session_id = 0;  ///< random per process start: a new id means the peer restarted
  float publish_rate_hz = 0.0f;  ///< rate at which the sender publishes its data messages
  /// What the sender runs: session_fingerprint(scene name, device mapping); 0 = not checked.
  std::uint64_t session_fingerprint = 0;
  std::array<char, kHelloSceneNameBytes> scene_name{};  ///< for the mismatch message
};

// Body sizes (before the CRC). Counted in docs/wire_protocol.md field by field.
/// The frozen prefix: a Hello of versions 1 and 2 is only this.
inline constexpr std::size_t kHelloPrefixBodyBytes = 12;
inline constexpr std::size_t kHelloBodyBytes = kHelloPrefixBodyBytes + 8 + kHelloSceneNameBytes;
inline constexpr std::size_t kDeviceStateBodyBytes = 52;
inline constexpr std::size_t kProxyFixedBodyBytes = 18;
inline constexpr std::size_t kPatchBodyBytes = 69;
/// Per tool part whose friction bit is set (messages.hpp, PartFriction): 9 × f32 and μ_s, μ_k
/// as u16 in steps of 1/kFrictionRatioStepsPerUnit — 40 B, so a clamp's full proxy (8 patches, both jaws'
/// friction: 654 B = 5232 bits) stays within CRC-32C's Hamming distance 6 (≤ 5243 bits).
inline constexpr std::size_t kPartFrictionBodyBytes = 40;
/// μ on the wire: round(μ · 10⁴) as u16 — 10⁻⁴ is far finer than any measured coefficient
/// (0.11–0.83 ± a few hundredths, docs/scenes.md), and 2 (the largest valid μ) is 20000.
inline constexpr double kFrictionRatioStepsPerUnit = 1.0e4;
/// Rounding is monotonic, so μ_k ≤ μ_s survives the trip; an out-of-range μ is clamped to
/// [0, 6.5535] and a NaN is sent as 0xFFFF (6.5535), which validation rejects (> 2).
constexpr std::uint16_t friction_ratio_to_wire(double ratio) noexcept {
  if (!(ratio >= 0.0)) return ratio < 0.0 ? std::uint16_t{0} : std::uint16_t{0xFFFF};
  const double steps = ratio * kFrictionRatioStepsPerUnit + 0.5;
  return steps >= 65535.0 ? std::uint16_t{0xFFFF} : static_cast<std::uint16_t>(steps);
}
constexpr double friction_ratio_from_wire(std::uint16_t steps) noexcept { return steps / kFrictionRatioStepsPerUnit; }

/// How many parts' friction a proxy with these flags carries.
constexpr std::size_t friction_parts_in(std::uint32_t flags) noexcept {
  std::size_t count = 0;
  for (unsigned part = 0; part < 3; ++part) count += (flags >> (kProxyFrictionShift + part)) & 1u;
  return count;
}

constexpr std::size_t proxy_message_bytes(std::size_t patch_count, std::size_t friction_parts = 0) noexcept {
  return kProxyFixedBodyBytes + kPatchBodyBytes * patch_count + kPartFrictionBodyBytes * friction_parts + kCrcBytes;
}
inline constexpr std::size_t kHelloMessageBytes = kHelloBodyBytes + kCrcBytes;
inline constexpr std::size_t kDeviceStateMessageBytes = kDeviceStateBodyBytes + kCrcBytes;
inline constexpr std::size_t kMaxMessageBytes = proxy_message_bytes(kMaxContactPatches, 3);

constexpr std::size_t segments_for(std::size_t message_bytes) noexcept {
  return (message_bytes + kSegmentBytes - 1) / kSegmentBytes;
}
static_assert(segments_for(kMaxMessageBytes) <= kMaxSegments);
static_assert(segments_for(kDeviceStateMessageBytes) == 1, "a DeviceState must fit one frame");
static_assert(segments_for(kHelloMessageBytes) == 1);

/// Frames of one encoded message, in send order.
struct FrameBatch {
  std::array<CanFdFrame, kMaxSegments> frames{};
  std::size_t count = 0;
};

enum class EncodeStatus : std::uint8_t {
  kOk = 0,
  kTooManyPatches,     ///< patch_count > kMaxContactPatches
  kFlagsNotEncodable,  ///< ContactProxy::flags uses bits above 7 (the wire has one byte)
  kBadToolPart,        ///< tool_part does not fit 4 bits
};
const char* to_string(EncodeStatus status) noexcept;

/// Encodes one message into `out` (replacing its contents). `transfer_id` is the sender's
/// per-type counter of messages put on the wire (+1 each, wrapping): the receiver matches
/// segments by it and recognises late segments of messages it already finished. Sequence
/// numbers are not used for this because a newest-wins sender skips them.
EncodeStatus encode(const DeviceState& state, std::uint8_t transfer_id, FrameBatch& out) noexcept;
EncodeStatus encode(const ContactProxy& proxy, std::uint8_t transfer_id, FrameBatch& out) noexcept;
EncodeStatus encode(const Hello& hello, std::uint8_t transfer_id, FrameBatch& out) noexcept;

// ---- message level, used by the reassembler ----------------------------------------------

/// Fields of a frame header (no validation).
struct FrameHeader {
  std::uint8_t version = 0;
  std::uint8_t type = 0;
  std::uint8_t transfer_id = 0;
  std::uint8_t segment_index = 0;
  std::uint8_t segment_count = 0;
};
FrameHeader parse_header(const CanFdFrame& frame) noexcept;

/// Largest number of segments a message of `type` can have (0 for an unknown type).
std::size_t max_segments_for(MessageType type) noexcept;

/// Total message bytes (body + CRC) implied by a reassembled message's first bytes; 0 when
/// they are inconsistent (e.g. a proxy claiming more than kMaxContactPatches patches).
std::size_t message_bytes_for(MessageType type, const std::uint8_t* message, std::size_t available) noexcept;

/// True when the CRC-32C stored in the last 4 of `message_bytes` matches. The CRC covers the
/// header fields every segment shares (version, type, transfer id, segment count) and the
/// body; segment indices are covered implicitly by where each chunk lands in the body.
bool crc_matches(std::uint8_t version, MessageType type, std::uint8_t transfer_id, std::uint8_t segment_count,
                 const std::uint8_t* message, std::size_t message_bytes) noexcept;

// Body decoders: `message` holds at least the type's message bytes (CRC already checked).
void decode_device_state(const std::uint8_t* message, DeviceState& out) noexcept;
void decode_contact_proxy(const std::uint8_t* message, ContactProxy& out) noexcept;
/// Reads the body's length from its version (the first two bytes): the prefix before
/// kHelloFingerprintVersion, the whole Hello from it.
void decode_hello(const std::uint8_t* message, Hello& out) noexcept;
/// Message bytes (body + CRC) of a Hello of `protocol_version`.
constexpr std::size_t hello_message_bytes(std::uint16_t protocol_version) noexcept {
  return (protocol_version < kHelloFingerprintVersion ? kHelloPrefixBodyBytes : kHelloBodyBytes) + kCrcBytes;
}

}  // namespace fissure::wire
