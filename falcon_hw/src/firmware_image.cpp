#include "fissure/falcon_hw/firmware_image.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>

namespace fissure::falcon {

bool read_firmware_image(const std::string& path, std::vector<std::uint8_t>& image, std::string& error) {
  std::ifstream file(path, std::ios::binary | std::ios::ate);
  if (!file) {
    error = "cannot open firmware file '" + path + "': " + std::strerror(errno);
    return false;
  }
  const std::streamoff size = file.tellg();
  if (size <= 0) {
    error = "firmware file '" + path + "' is empty";
    return false;
  }
  if (static_cast<std::size_t>(size) > kMaxFirmwareImageBytes) {
    error = "firmware file '" + path + "' is " + std::to_string(size) + " bytes, more than " +
            std::to_string(kMaxFirmwareImageBytes) + ": not a Falcon firmware image";
    return false;
  }
  image.resize(static_cast<std::size_t>(size));
  file.seekg(0);
  if (!file.read(reinterpret_cast<char*>(image.data()), size)) {
    error = "cannot read firmware file '" + path + "'";
    return false;
  }
  return true;
}

}  // namespace fissure::falcon
