#include "fissure/falcon_hw/falcon_packet.hpp"

#include <cstdint>
#include <limits>

#include <gtest/gtest.h>

namespace fissure::falcon {
namespace {

constexpr int kInt16Min = std::numeric_limits<std::int16_t>::min();
constexpr int kInt16Max = std::numeric_limits<std::int16_t>::max();

TEST(FalconPacket, WireLayoutIsLeastSignificantNibbleFirstPlus0x41) {
  DeviceCommand command;
  command.motor_counts = {0x1234, -1, 0};
  command.homing_mode = true;
  command.leds = kLedRed | kLedGreen;
  const FalconPacket packet = encode_command(command);
  const FalconPacket expected{'<', 'E', 'D', 'C', 'B',            // 0x1234: 4 3 2 1
                              'P', 'P', 'P', 'P',                  // -1 = 0xFFFF
                              'A', 'A', 'A', 'A',                  // 0
                              static_cast<std::uint8_t>('A' + 0xB),  // red 0x8 | green 0x2 | homing 0x1
                              'A', '>'};
  EXPECT_EQ(packet, expected);
}

TEST(FalconPacket, CommandRoundTripsEveryInt16InEveryField) {
  for (std::size_t field = 0; field < 3; ++field) {
    for (int value = kInt16Min; value <= kInt16Max; ++value) {
      DeviceCommand command;
      command.motor_counts[field] = static_cast<std::int16_t>(value);
      command.motor_counts[(field + 1) % 3] = static_cast<std::int16_t>(~value);  // neighbours must not bleed
      DeviceCommand decoded;
      decoded.motor_counts = {7, 7, 7};
      const FalconPacket packet = encode_command(command);
      ASSERT_TRUE(check_packet(PacketDirection::kHostToDevice, packet).ok()) << value;
      ASSERT_TRUE(decode_command(packet, decoded)) << "field " << field << " value " << value;
      ASSERT_EQ(decoded.motor_counts, command.motor_counts) << "field " << field << " value " << value;
    }
  }
}

TEST(FalconPacket, ReadingRoundTripsEveryInt16InEveryField) {
  for (std::size_t field = 0; field < 3; ++field) {
    for (int value = kInt16Min; value <= kInt16Max; ++value) {
      DeviceReading reading;
      reading.encoder_counts[field] = static_cast<std::int16_t>(value);
      reading.encoder_counts[(field + 2) % 3] = static_cast<std::int16_t>(value ^ 0x5A5A);
      DeviceReading decoded;
      const FalconPacket packet = encode_reading(reading);
      ASSERT_TRUE(decode_reading(packet, decoded)) << "field " << field << " value " << value;
      ASSERT_EQ(decoded.encoder_counts, reading.encoder_counts) << "field " << field << " value " << value;
    }
  }
}

TEST(FalconPacket, CommandFlagsRoundTripAndLedsAreMasked) {
  for (int leds = 0; leds < 256; ++leds) {
    for (const bool homing : {false, true}) {
      DeviceCommand command;
      command.leds = static_cast<std::uint8_t>(leds);
      command.homing_mode = homing;
      DeviceCommand decoded;
      ASSERT_TRUE(decode_command(encode_command(command), decoded));
      EXPECT_EQ(decoded.leds, leds & kLedMask);
      EXPECT_EQ(decoded.homing_mode, homing);
    }
  }
}

TEST(FalconPacket, ReadingFlagsRoundTripAndMatchLibnifalconsByte13) {
  for (int buttons = 0; buttons < 16; ++buttons) {
    for (int homed = 0; homed < 8; ++homed) {
      DeviceReading reading;
      reading.buttons = static_cast<std::uint8_t>(buttons);
      reading.homed_mask = static_cast<std::uint8_t>(homed);
      const FalconPacket packet = encode_reading(reading);
      // libnifalcon: buttons = (raw[13] - 0x41) & 0xf, homing = ((raw[13] - 0x41) >> 4) & 7.
      EXPECT_EQ((packet[kFlagsByteIndex] - 0x41) & 0xF, buttons);
      EXPECT_EQ(((packet[kFlagsByteIndex] - 0x41) >> 4) & 7, homed);
      DeviceReading decoded;
      ASSERT_TRUE(decode_reading(packet, decoded));
      EXPECT_EQ(decoded.buttons, buttons);
      EXPECT_EQ(decoded.homed_mask, homed);
    }
  }
  DeviceReading all;
  all.buttons = 0xFF;     // masked to the low nibble
  all.homed_mask = 0xFF;  // masked to three arms
  EXPECT_EQ(encode_reading(all)[kFlagsByteIndex], 0xC0);
}

TEST(FalconPacket, EveryInvalidPayloadByteIsRejectedAtEveryPosition) {
  DeviceCommand command;
  command.motor_counts = {-1234, 4095, -4095};
  DeviceReading reading;
  reading.encoder_counts = {321, -321, 0};
  for (const PacketDirection direction : {PacketDirection::kHostToDevice, PacketDirection::kDeviceToHost}) {
    const FalconPacket good =
        direction == PacketDirection::kHostToDevice ? encode_command(command) : encode_reading(reading);
    for (std::size_t index = 1; index <= kReservedByteIndex; ++index) {
      int accepted = 0;
      for (int byte = 0; byte < 256; ++byte) {
        FalconPacket packet = good;
        packet[index] = static_cast<std::uint8_t>(byte);
        const bool wide = direction == PacketDirection::kDeviceToHost && index == kFlagsByteIndex;
        const bool valid = byte >= 0x41 && byte <= (wide ? 0xC0 : 0x50);
        const PacketCheck check = check_packet(direction, packet);
        EXPECT_EQ(check.ok(), valid) << "direction " << static_cast<int>(direction) << " index " << index
                                     << " byte " << byte;
        EXPECT_EQ(is_valid_payload_byte(direction, index, static_cast<std::uint8_t>(byte)), valid);
        if (!valid) {
          EXPECT_EQ(check.error, PacketError::kInvalidPayload);
          EXPECT_EQ(check.byte_index, index);
        }
        DeviceCommand c;
        DeviceReading r;
        if (direction == PacketDirection::kHostToDevice) {
          EXPECT_EQ(decode_command(packet, c), valid);
        } else {
          EXPECT_EQ(decode_reading(packet, r), valid);
        }
        accepted += valid ? 1 : 0;
      }
      const bool wide = direction == PacketDirection::kDeviceToHost && index == kFlagsByteIndex;
      EXPECT_EQ(accepted, wide ? 128 : 16);
    }
  }
}

TEST(FalconPacket, MarkersAreChecked) {
  FalconPacket packet = encode_command(DeviceCommand{});
  packet[0] = 'A';
  EXPECT_EQ(check_packet(PacketDirection::kHostToDevice, packet).error, PacketError::kBadStartMarker);
  packet = encode_command(DeviceCommand{});
  packet[15] = '<';
  EXPECT_EQ(check_packet(PacketDirection::kHostToDevice, packet).error, PacketError::kBadEndMarker);
  DeviceCommand untouched;
  untouched.motor_counts = {1, 2, 3};
  EXPECT_FALSE(decode_command(packet, untouched));
  EXPECT_EQ(untouched.motor_counts, (std::array<std::int16_t, 3>{1, 2, 3}));
  // Markers can never be payload: this is what resynchronisation relies on.
  for (std::size_t index = 1; index <= kReservedByteIndex; ++index) {
    for (const PacketDirection d : {PacketDirection::kHostToDevice, PacketDirection::kDeviceToHost}) {
      EXPECT_FALSE(is_valid_payload_byte(d, index, kPacketStartByte));
      EXPECT_FALSE(is_valid_payload_byte(d, index, kPacketEndByte));
    }
  }
}

}  // namespace
}  // namespace fissure::falcon
