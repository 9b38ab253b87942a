#include "fissure/falcon_hw/firmware_image.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace fissure::falcon {
namespace {

std::filesystem::path temp_file(const std::string& name, const std::vector<std::uint8_t>& bytes) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() / name;
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  return path;
}

TEST(FirmwareImage, ReadsAFileExactly) {
  const std::vector<std::uint8_t> blob{0x00, 0xFF, 0x41, 0x3C, 0x0A};
  const auto path = temp_file("fissure_fw_ok.bin", blob);
  std::vector<std::uint8_t> image;
  std::string error;
  ASSERT_TRUE(read_firmware_image(path.string(), image, error)) << error;
  EXPECT_EQ(image, blob);
  std::filesystem::remove(path);
}

TEST(FirmwareImage, MissingEmptyAndHugeFilesAreNamedInTheError) {
  std::vector<std::uint8_t> image;
  std::string error;
  EXPECT_FALSE(read_firmware_image("/nonexistent/falcon.bin", image, error));
  EXPECT_NE(error.find("cannot open firmware file '/nonexistent/falcon.bin'"), std::string::npos) << error;

  const auto empty = temp_file("fissure_fw_empty.bin", {});
  EXPECT_FALSE(read_firmware_image(empty.string(), image, error));
  EXPECT_NE(error.find("is empty"), std::string::npos) << error;
  std::filesystem::remove(empty);

  const auto huge = temp_file("fissure_fw_huge.bin", std::vector<std::uint8_t>(kMaxFirmwareImageBytes + 1, 0));
  EXPECT_FALSE(read_firmware_image(huge.string(), image, error));
  EXPECT_NE(error.find("not a Falcon firmware image"), std::string::npos) << error;
  std::filesystem::remove(huge);
}

}  // namespace
}  // namespace fissure::falcon
