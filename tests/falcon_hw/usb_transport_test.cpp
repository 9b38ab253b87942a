#include "fissure/falcon_hw/usb_transport.hpp"

#include <array>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

namespace fissure::falcon {
namespace {

// Builds an IN transfer the way the FTDI chip sends it: each 64-byte USB packet starts with
// two modem-status bytes (0x31 0x60 is a typical idle status), then up to 62 payload bytes.
std::vector<std::uint8_t> ftdi_transfer(const std::vector<std::uint8_t>& payload) {
  std::vector<std::uint8_t> transfer;
  std::size_t at = 0;
  do {
    transfer.push_back(0x31);
    transfer.push_back(0x60);
    const std::size_t n = std::min<std::size_t>(62, payload.size() - at);
    transfer.insert(transfer.end(), payload.begin() + static_cast<std::ptrdiff_t>(at),
                    payload.begin() + static_cast<std::ptrdiff_t>(at + n));
    at += n;
  } while (at < payload.size());
  return transfer;
}

TEST(StripFtdiStatusBytes, RemovesTheTwoStatusBytesOfEveryUsbPacket) {
  for (const std::size_t size : {0U, 1U, 16U, 61U, 62U, 63U, 124U, 200U}) {
    std::vector<std::uint8_t> payload(size);
    for (std::size_t i = 0; i < size; ++i) payload[i] = static_cast<std::uint8_t>(0x41 + i % 16);
    const std::vector<std::uint8_t> transfer = ftdi_transfer(payload);
    std::array<std::uint8_t, 512> out{};
    const std::size_t n = strip_ftdi_status_bytes(transfer, kFtdiMaxPacketBytes, out);
    ASSERT_EQ(n, size);
    EXPECT_TRUE(std::equal(payload.begin(), payload.end(), out.begin())) << size;
  }
}

TEST(StripFtdiStatusBytes, StatusOnlyTransferHasNoPayloadAndSmallOutputIsNotOverrun) {
  const std::array<std::uint8_t, 2> status_only{0x31, 0x60};
  std::array<std::uint8_t, 8> out{};
  EXPECT_EQ(strip_ftdi_status_bytes(status_only, kFtdiMaxPacketBytes, out), 0U);
  const std::array<std::uint8_t, 1> truncated{0x31};
  EXPECT_EQ(strip_ftdi_status_bytes(truncated, kFtdiMaxPacketBytes, out), 0U);

  std::vector<std::uint8_t> payload(100, 0x42);
  const std::vector<std::uint8_t> transfer = ftdi_transfer(payload);
  std::array<std::uint8_t, 10> small{};
  EXPECT_EQ(strip_ftdi_status_bytes(transfer, kFtdiMaxPacketBytes, small), small.size());
  EXPECT_EQ(strip_ftdi_status_bytes(transfer, 2, small), 0U);  // nonsense packet size: nothing
}

TEST(FtdiConstants, BaudDivisorsGiveTheBriefsRates) {
  // FT232: baud = 3 MHz / (integer part + fraction), fraction code in bits 14–15 (01 = 0.5).
  auto baud = [](std::uint16_t divisor) {
    const double fractions[4] = {0.0, 0.5, 0.25, 0.125};
    return 3e6 / ((divisor & 0x3FFF) + fractions[divisor >> 14]);
  };
  EXPECT_NEAR(baud(kFtdiBaudDivisor9600), 9600.0, 1e-9);
  EXPECT_NEAR(baud(kFtdiBaudDivisorFirmware), 140'000.0, 3'000.0);
  EXPECT_NEAR(baud(kFtdiBaudDivisorNormal), 1.5e6, 1e-9);
  EXPECT_EQ(kFtdiLatencyNormalMs, 1);
}

}  // namespace
}  // namespace fissure::falcon
