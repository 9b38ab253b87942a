#include "fissure/falcon_hw/usb_transport.hpp"

#include <algorithm>

namespace fissure::falcon {

const char* to_string(TransportStatus status) noexcept {
  switch (status) {
    case TransportStatus::kOk: return "ok";
    case TransportStatus::kTimeout: return "timeout";
    case TransportStatus::kDisconnected: return "disconnected";
    case TransportStatus::kError: return "transfer error";
  }
  return "unknown";
}

std::size_t strip_ftdi_status_bytes(std::span<const std::uint8_t> transfer, std::size_t max_packet_bytes,
                                    std::span<std::uint8_t> out) noexcept {
  if (max_packet_bytes <= kFtdiStatusBytes) return 0;
  std::size_t copied = 0;
  for (std::size_t start = 0; start < transfer.size(); start += max_packet_bytes) {
    const std::size_t packet_end = std::min(transfer.size(), start + max_packet_bytes);
    const std::size_t payload_start = start + kFtdiStatusBytes;
    if (payload_start >= packet_end) continue;  // a status-only (or truncated) USB packet
    const std::size_t n = std::min(packet_end - payload_start, out.size() - copied);
    std::copy_n(transfer.begin() + static_cast<std::ptrdiff_t>(payload_start), n,
                out.begin() + static_cast<std::ptrdiff_t>(copied));
    copied += n;
    if (copied == out.size()) break;
  }
  return copied;
}

}  // namespace fissure::falcon
