// libFuzzer harness for FalconStreamParser (optional; see tests/falcon_hw/usb.cmake).
// Invariants: no crash / out-of-bounds (ASan), the counters account for every byte, and the
// packets found are exactly the valid 16-byte windows of the input (markers cannot be
// payload, so valid windows never overlap and each must be recovered).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <vector>

#include "fissure/falcon_hw/falcon_stream_parser.hpp"

using namespace fissure::falcon;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  const PacketDirection direction = (data[0] & 1) != 0 ? PacketDirection::kDeviceToHost : PacketDirection::kHostToDevice;
  const std::size_t chunk = 1 + data[1] % 64;
  const std::span<const std::uint8_t> stream(data + 2, size - 2);

  FalconStreamParser parser(direction);
  std::vector<std::size_t> found_ends;
  for (std::size_t at = 0; at < stream.size(); at += chunk) {
    const std::size_t n = std::min(chunk, stream.size() - at);
    parser.feed(stream.subspan(at, n), [&](const FalconPacket&) { found_ends.push_back(parser.stats().bytes_in); });
  }
  std::vector<std::size_t> valid_ends;
  for (std::size_t i = 0; i + kPacketSizeBytes <= stream.size(); ++i) {
    FalconPacket window{};
    std::copy_n(stream.begin() + static_cast<std::ptrdiff_t>(i), kPacketSizeBytes, window.begin());
    if (check_packet(direction, window).ok()) valid_ends.push_back(i + kPacketSizeBytes);
  }
  const StreamParserStats& s = parser.stats();
  if (found_ends != valid_ends) std::abort();
  if (s.bytes_in != stream.size()) std::abort();
  if (s.bytes_in != kPacketSizeBytes * s.packets + s.total_discarded_bytes() + parser.pending_bytes()) std::abort();
  return 0;
}
