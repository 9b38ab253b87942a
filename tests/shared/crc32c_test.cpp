#include "fissure/shared/crc32c.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstring>

namespace fissure::wire {
namespace {

TEST(Crc32c, MatchesTheCatalogueCheckValue) {
  const char* text = "123456789";
  EXPECT_EQ(crc32c(reinterpret_cast<const std::uint8_t*>(text), std::strlen(text)), 0xE3069283u);
  EXPECT_EQ(crc32c(nullptr, 0), 0x00000000u);
}

TEST(Crc32c, IncrementalEqualsOneShot) {
  std::array<std::uint8_t, 100> bytes{};
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<std::uint8_t>(i * 37 + 11);
  std::uint32_t crc = kCrc32cInit;
  crc = crc32c_update(crc, bytes.data(), 33);
  crc = crc32c_update(crc, bytes.data() + 33, bytes.size() - 33);
  EXPECT_EQ(crc32c_finish(crc), crc32c(bytes.data(), bytes.size()));
}

TEST(Crc32c, EverySingleBitFlipChangesIt) {
  std::array<std::uint8_t, 64> bytes{};
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<std::uint8_t>(i);
  const std::uint32_t reference = crc32c(bytes.data(), bytes.size());
  for (std::size_t bit = 0; bit < bytes.size() * 8; ++bit) {
    bytes[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
    EXPECT_NE(crc32c(bytes.data(), bytes.size()), reference) << "bit " << bit;
    bytes[bit / 8] ^= static_cast<std::uint8_t>(1u << (bit % 8));
  }
}

}  // namespace
}  // namespace fissure::wire
