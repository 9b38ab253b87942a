#pragma once
// Reading the user-supplied Falcon firmware file. We never ship the firmware (BRIEF §6:
// it is Novint's); the user points `fissure device firmware --file F` at their copy.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace fissure::falcon {

/// Upper bound on a plausible firmware image; the Falcon's is a few tens of kilobytes, so
/// anything this large is the wrong file.
inline constexpr std::size_t kMaxFirmwareImageBytes = 1U << 20;

/// Reads `path` into `image`. On failure returns false and sets `error` to one line naming
/// the file and the problem (missing, unreadable, empty, too large). Not for the RT thread.
bool read_firmware_image(const std::string& path, std::vector<std::uint8_t>& image, std::string& error);

}  // namespace fissure::falcon
