// The fake device must answer the way BRIEF §6 says the real one does; the driver tests
// are only as good as this.
#include "fissure/falcon_hw/fake_falcon_transport.hpp"

#include <array>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

namespace fissure::falcon {
namespace {

std::vector<std::uint8_t> read_all(FakeFalconTransport& fake, TimeNs timeout_ns) {
  std::vector<std::uint8_t> bytes;
  std::array<std::uint8_t, 64> buffer{};
  while (true) {
    const TransportRead got = fake.read(buffer, timeout_ns);
    if (got.status != TransportStatus::kOk) break;
    bytes.insert(bytes.end(), buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(got.bytes));
  }
  return bytes;
}

TEST(FakeFalconTransport, BootloaderHandshakeSyncAndEcho) {
  LockstepClock clock;
  FakeFalconConfig config;
  config.firmware_image = {1, 2, 3, 4, 5};
  FakeFalconTransport fake(clock, config);
  ASSERT_EQ(fake.set_dtr(false), TransportStatus::kOk);
  ASSERT_EQ(fake.set_dtr(true), TransportStatus::kOk);

  // Wrong baud rate: no answer.
  fake.set_baud_divisor(kFtdiBaudDivisorNormal);
  ASSERT_EQ(fake.write(std::array<std::uint8_t, 3>{0x0A, 0x43, 0x0D}, 1'000'000), TransportStatus::kOk);
  EXPECT_TRUE(read_all(fake, 10'000'000).empty());

  fake.set_baud_divisor(kFtdiBaudDivisor9600);
  ASSERT_EQ(fake.write(std::array<std::uint8_t, 3>{0x0A, 0x43, 0x0D}, 1'000'000), TransportStatus::kOk);
  EXPECT_EQ(read_all(fake, 10'000'000), (std::vector<std::uint8_t>{0x0A, 0x44, 0x2C, 0x0D}));

  fake.set_baud_divisor(kFtdiBaudDivisorFirmware);
  ASSERT_EQ(fake.write(std::array<std::uint8_t, 1>{'A'}, 1'000'000), TransportStatus::kOk);
  EXPECT_EQ(read_all(fake, 10'000'000), (std::vector<std::uint8_t>{'A'}));
  ASSERT_EQ(fake.write(config.firmware_image, 1'000'000), TransportStatus::kOk);
  EXPECT_EQ(read_all(fake, 10'000'000), config.firmware_image);
  EXPECT_FALSE(fake.firmware_running());
  fake.set_baud_divisor(kFtdiBaudDivisorNormal);
  EXPECT_TRUE(fake.firmware_running());
}

TEST(FakeFalconTransport, WrongImageDoesNotStart) {
  LockstepClock clock;
  FakeFalconConfig config;
  config.firmware_image = {1, 2, 3};
  FakeFalconTransport fake(clock, config);
  fake.set_dtr(false);
  fake.set_dtr(true);
  fake.set_baud_divisor(kFtdiBaudDivisor9600);
  fake.write(std::array<std::uint8_t, 3>{0x0A, 0x43, 0x0D}, 0);
  fake.set_baud_divisor(kFtdiBaudDivisorFirmware);
  fake.write(std::array<std::uint8_t, 3>{'A', 1, 2}, 0);  // one byte short
  fake.set_baud_divisor(kFtdiBaudDivisorNormal);
  EXPECT_FALSE(fake.firmware_running());
}

TEST(FakeFalconTransport, OneReplyPerCommandAfterTheReplyLatencyAndTimeoutsAreSimulated) {
  LockstepClock clock;
  FakeFalconConfig config;
  config.firmware_running = true;
  config.reply_latency_ns = 700'000;
  config.encoder_counts = {10, -20, 30};
  FakeFalconTransport fake(clock, config);
  fake.set_baud_divisor(kFtdiBaudDivisorNormal);
  fake.set_buttons(0x9);
  DeviceCommand command;
  command.motor_counts = {100, -200, 300};
  command.leds = kLedBlue;
  ASSERT_EQ(fake.write(encode_command(command), 0), TransportStatus::kOk);

  std::array<std::uint8_t, 64> buffer{};
  const TransportRead early = fake.read(buffer, 500'000);  // before the reply is due
  EXPECT_EQ(early.status, TransportStatus::kTimeout);
  EXPECT_EQ(clock.now(), 500'000);  // the wait was simulated by advancing the clock
  const TransportRead got = fake.read(buffer, 1'000'000);
  ASSERT_EQ(got.status, TransportStatus::kOk);
  EXPECT_EQ(clock.now(), 700'000);
  ASSERT_EQ(got.bytes, kPacketSizeBytes);
  FalconPacket packet{};
  std::copy_n(buffer.begin(), kPacketSizeBytes, packet.begin());
  DeviceReading reading;
  ASSERT_TRUE(decode_reading(packet, reading));
  EXPECT_EQ(reading.encoder_counts, (std::array<std::int16_t, 3>{10, -20, 30}));
  EXPECT_EQ(reading.buttons, 0x9);
  ASSERT_EQ(fake.commands().size(), 1U);
  EXPECT_EQ(fake.commands()[0].motor_counts, command.motor_counts);
  EXPECT_EQ(fake.commands()[0].leds, kLedBlue);
  EXPECT_EQ(fake.read(buffer, 1'000'000).status, TransportStatus::kTimeout);  // strictly one reply
}

TEST(FakeFalconTransport, NoFirmwareMeansNoReplyAndDisconnectIsSticky) {
  LockstepClock clock;
  FakeFalconTransport fake(clock, FakeFalconConfig{});
  fake.set_baud_divisor(kFtdiBaudDivisorNormal);
  fake.write(encode_command(DeviceCommand{}), 0);
  std::array<std::uint8_t, 64> buffer{};
  EXPECT_EQ(fake.read(buffer, 5'000'000).status, TransportStatus::kTimeout);
  fake.disconnect_after_replies(0);
  EXPECT_EQ(fake.write(encode_command(DeviceCommand{}), 0), TransportStatus::kDisconnected);
  EXPECT_EQ(fake.read(buffer, 5'000'000).status, TransportStatus::kDisconnected);
  EXPECT_EQ(fake.purge(FtdiPurge::kBoth), TransportStatus::kDisconnected);
  EXPECT_EQ(clock.now(), 5'000'000);  // the disconnected calls did not wait
}

TEST(FakeFalconTransport, HomingNeedsHomingModeAndPassingTheIndex) {
  LockstepClock clock;
  FakeFalconConfig config;
  config.firmware_running = true;
  config.encoder_counts = {-100, -100, -100};
  config.index_counts = {0, 50, 500};  // the third arm's index is beyond the travel
  FakeFalconTransport fake(clock, config);
  fake.set_baud_divisor(kFtdiBaudDivisorNormal);
  fake.script_pull_out_push_in(200, 10);
  DeviceCommand homing;
  homing.homing_mode = true;
  for (int i = 0; i < 20; ++i) fake.write(encode_command(homing), 0);
  EXPECT_EQ(fake.homed_mask(), 0x3);
  EXPECT_EQ(fake.encoder_counts(), (std::array<std::int16_t, 3>{-100, -100, -100}));  // back in
}

}  // namespace
}  // namespace fissure::falcon
