#pragma once
// The Novint Falcon's 16-byte wire packet (BRIEF §6), as pure encode/decode functions.
//
//   byte 0        '<'
//   bytes 1–12    three int16, four nibble bytes each, least-significant nibble first
//                 (host→device: motor commands; device→host: encoder counts)
//   byte 13       flags (see below)
//   byte 14       reserved nibble: the host sends 'A' (0); the device's value is ignored
//   byte 15       '>'
// Every payload byte is value + 0x41, so a nibble travels as 'A'..'P'.
//
// Byte 13 is the one exception to "one nibble per byte", and the two directions differ:
// * host→device it is a nibble: bit 0 homing mode, 0x2 green, 0x4 blue, 0x8 red LED.
// * device→host it carries 7 bits in ONE byte: byte − 0x41 = buttons (low nibble) |
//   homed flags (bits 4–6, bit i = arm i). That is how libnifalcon decodes the real device
//   (`(raw[13] − 0x41) & 0xf` buttons, `((raw[13] − 0x41) >> 4) & 7` homing status) and how
//   its homing works on hardware, so a homed device sends bytes above 'P' (up to 0xC0).
//   We therefore accept 0x41..0xC0 there (bit 7 of the value must be 0) and put nothing in
//   byte 14. The "two nibbles" of the flags are thus the low and high half of byte 13's
//   value, not bytes 13 and 14. '<' (0x3C) and '>' (0x3E) stay below every valid payload
//   byte in both directions, which is what makes resynchronisation on them unambiguous.
#include <array>
#include <cstddef>
#include <cstdint>

#include "fissure/falcon_hw/haptic_device.hpp"

namespace fissure::falcon {

inline constexpr std::size_t kPacketSizeBytes = 16;
inline constexpr std::uint8_t kPacketStartByte = '<';
inline constexpr std::uint8_t kPacketEndByte = '>';
/// Offset added to every payload value on the wire ('A' = 0x41, BRIEF §6).
inline constexpr std::uint8_t kNibbleOffset = 0x41;
/// Index of the flags byte and of the reserved byte within the packet.
inline constexpr std::size_t kFlagsByteIndex = 13;
inline constexpr std::size_t kReservedByteIndex = 14;

/// Byte 13 host→device bits (BRIEF §6, libnifalcon FalconFirmware.h).
inline constexpr std::uint8_t kHomingModeBit = 0x1;
inline constexpr std::uint8_t kLedGreen = 0x2;
inline constexpr std::uint8_t kLedBlue = 0x4;
inline constexpr std::uint8_t kLedRed = 0x8;
inline constexpr std::uint8_t kLedMask = kLedGreen | kLedBlue | kLedRed;
/// Byte 13 device→host: low nibble buttons, bits 4–6 homed flags (one per arm).
inline constexpr std::uint8_t kButtonsMask = 0x0F;
inline constexpr std::uint8_t kHomedMaskAllArms = 0x07;
inline constexpr unsigned kHomedFlagsShift = 4;

using FalconPacket = std::array<std::uint8_t, kPacketSizeBytes>;

enum class PacketDirection : std::uint8_t {
  kHostToDevice,  ///< motor commands + homing/LED nibble
  kDeviceToHost,  ///< encoder counts + buttons/homed byte
};

enum class PacketError : std::uint8_t {
  kNone = 0,
  kBadStartMarker,  ///< byte 0 is not '<'
  kBadEndMarker,    ///< byte 15 is not '>'
  kInvalidPayload,  ///< a payload byte outside its allowed range (see byte_index)
};
const char* to_string(PacketError error) noexcept;

struct PacketCheck {
  PacketError error = PacketError::kNone;
  std::uint8_t byte_index = 0;  ///< the offending byte for kInvalidPayload / marker errors
  [[nodiscard]] bool ok() const noexcept { return error == PacketError::kNone; }
};

/// Whether `byte` may appear at payload position `index` (1..14) of a packet travelling in
/// `direction`. Markers and out-of-range indices are never valid payload.
[[nodiscard]] bool is_valid_payload_byte(PacketDirection direction, std::size_t index, std::uint8_t byte) noexcept;

/// Full validation of a received packet: markers, then every payload byte.
[[nodiscard]] PacketCheck check_packet(PacketDirection direction, const FalconPacket& packet) noexcept;

/// Host→device. The LEDs are masked to kLedMask (bit 0 belongs to homing_mode).
[[nodiscard]] FalconPacket encode_command(const DeviceCommand& command) noexcept;
/// Inverse of encode_command (used by the fake device). Returns false, leaving `command`
/// untouched, when check_packet(kHostToDevice) fails.
[[nodiscard]] bool decode_command(const FalconPacket& packet, DeviceCommand& command) noexcept;

/// Device→host (used by the fake device). buttons masked to 4 bits, homed_mask to 3.
[[nodiscard]] FalconPacket encode_reading(const DeviceReading& reading) noexcept;
/// Inverse of encode_reading. receive_time_ns is not on the wire and is left untouched.
/// Returns false, leaving `reading` untouched, when check_packet(kDeviceToHost) fails.
[[nodiscard]] bool decode_reading(const FalconPacket& packet, DeviceReading& reading) noexcept;

}  // namespace fissure::falcon
