#include "fissure/falcon_hw/falcon_packet.hpp"

namespace fissure::falcon {
namespace {

// Largest nibble value and largest device→host flags value (buttons | homed << 4).
constexpr std::uint8_t kMaxNibble = 0x0F;
constexpr std::uint8_t kMaxDeviceFlags = 0x7F;
constexpr std::size_t kFirstPayloadIndex = 1;
constexpr std::size_t kNibblesPerInt16 = 4;

void put_int16(FalconPacket& packet, std::size_t field, std::int16_t value) noexcept {
  const auto bits = static_cast<std::uint16_t>(value);
  const std::size_t first = kFirstPayloadIndex + field * kNibblesPerInt16;
  for (std::size_t n = 0; n < kNibblesPerInt16; ++n) {
    packet[first + n] = static_cast<std::uint8_t>(((bits >> (4 * n)) & kMaxNibble) + kNibbleOffset);
  }
}

std::int16_t get_int16(const FalconPacket& packet, std::size_t field) noexcept {
  const std::size_t first = kFirstPayloadIndex + field * kNibblesPerInt16;
  std::uint16_t bits = 0;
  for (std::size_t n = 0; n < kNibblesPerInt16; ++n) {
    bits = static_cast<std::uint16_t>(bits | ((packet[first + n] - kNibbleOffset) & kMaxNibble) << (4 * n));
  }
  return static_cast<std::int16_t>(bits);  // two's complement, well defined since C++20
}

FalconPacket framed() noexcept {
  FalconPacket packet{};
  packet.fill(kNibbleOffset);
  packet.front() = kPacketStartByte;
  packet.back() = kPacketEndByte;
  return packet;
}

}  // namespace

const char* to_string(PacketError error) noexcept {
  switch (error) {
    case PacketError::kNone: return "ok";
    case PacketError::kBadStartMarker: return "byte 0 is not '<'";
    case PacketError::kBadEndMarker: return "byte 15 is not '>'";
    case PacketError::kInvalidPayload: return "invalid payload byte";
  }
  return "unknown";
}

bool is_valid_payload_byte(PacketDirection direction, std::size_t index, std::uint8_t byte) noexcept {
  if (index < kFirstPayloadIndex || index > kReservedByteIndex || byte < kNibbleOffset) return false;
  const unsigned value = byte - kNibbleOffset;
  if (index == kFlagsByteIndex && direction == PacketDirection::kDeviceToHost) return value <= kMaxDeviceFlags;
  return value <= kMaxNibble;
}

PacketCheck check_packet(PacketDirection direction, const FalconPacket& packet) noexcept {
  if (packet.front() != kPacketStartByte) return {PacketError::kBadStartMarker, 0};
  for (std::size_t i = kFirstPayloadIndex; i <= kReservedByteIndex; ++i) {
    if (!is_valid_payload_byte(direction, i, packet[i])) {
      return {PacketError::kInvalidPayload, static_cast<std::uint8_t>(i)};
    }
  }
  if (packet.back() != kPacketEndByte) return {PacketError::kBadEndMarker, kPacketSizeBytes - 1};
  return {};
}

FalconPacket encode_command(const DeviceCommand& command) noexcept {
  FalconPacket packet = framed();
  for (std::size_t arm = 0; arm < 3; ++arm) put_int16(packet, arm, command.motor_counts[arm]);
  const auto flags = static_cast<std::uint8_t>((command.leds & kLedMask) | (command.homing_mode ? kHomingModeBit : 0));
  packet[kFlagsByteIndex] = static_cast<std::uint8_t>(flags + kNibbleOffset);
  return packet;
}

bool decode_command(const FalconPacket& packet, DeviceCommand& command) noexcept {
  if (!check_packet(PacketDirection::kHostToDevice, packet).ok()) return false;
  for (std::size_t arm = 0; arm < 3; ++arm) command.motor_counts[arm] = get_int16(packet, arm);
  const auto flags = static_cast<std::uint8_t>(packet[kFlagsByteIndex] - kNibbleOffset);
  command.homing_mode = (flags & kHomingModeBit) != 0;
  command.leds = static_cast<std::uint8_t>(flags & kLedMask);
  return true;
}

FalconPacket encode_reading(const DeviceReading& reading) noexcept {
  FalconPacket packet = framed();
  for (std::size_t arm = 0; arm < 3; ++arm) put_int16(packet, arm, reading.encoder_counts[arm]);
  const auto flags = static_cast<std::uint8_t>((reading.buttons & kButtonsMask) |
                                               ((reading.homed_mask & kHomedMaskAllArms) << kHomedFlagsShift));
  packet[kFlagsByteIndex] = static_cast<std::uint8_t>(flags + kNibbleOffset);
  return packet;
}

bool decode_reading(const FalconPacket& packet, DeviceReading& reading) noexcept {
  if (!check_packet(PacketDirection::kDeviceToHost, packet).ok()) return false;
  for (std::size_t arm = 0; arm < 3; ++arm) reading.encoder_counts[arm] = get_int16(packet, arm);
  const auto flags = static_cast<std::uint8_t>(packet[kFlagsByteIndex] - kNibbleOffset);
  reading.buttons = static_cast<std::uint8_t>(flags & kButtonsMask);
  reading.homed_mask = static_cast<std::uint8_t>((flags >> kHomedFlagsShift) & kHomedMaskAllArms);
  return true;
}

}  // namespace fissure::falcon
