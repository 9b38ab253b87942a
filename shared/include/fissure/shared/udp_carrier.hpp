#pragma once
// UDP carrier: each datagram holds one CAN FD frame, so the codec, segmentation and
// reassembly exercised over UDP (and in CI, on 127.0.0.1) are exactly what runs on the bus.
// Datagram layout (little-endian), mirroring Linux's struct canfd_frame:
//   bytes 0–3 can_id, byte 4 length (0…64), byte 5 flags, bytes 6–7 zero, then `length` data bytes.
// IPv4, non-blocking socket; try_send / try_receive are single syscalls, no allocation.
#include <cstdint>
#include <string>

#include <netinet/in.h>

#include "fissure/shared/clock.hpp"
#include "fissure/shared/frame_carrier.hpp"

namespace fissure::transport {

struct UdpCarrierConfig {
  std::string local_address = "0.0.0.0";  ///< address to bind (numeric IPv4 or host name)
  std::uint16_t local_port = 0;            ///< 0: the kernel picks an ephemeral port
  /// Where frames go. Empty: reply to whoever sent the last valid frame (the listening end
  /// of `udp:HOST:PORT`); until someone has, try_send reports kError (ENOTCONN).
  std::string remote_address;
  std::uint16_t remote_port = 0;
};

inline constexpr std::size_t kUdpFrameHeaderBytes = 8;

class UdpCarrier final : public FrameCarrier {
 public:
  /// Opens and binds the socket; throws TransportError naming the address on failure.
  /// Receive timestamps are `clock.now()` when the datagram is read.
  UdpCarrier(const UdpCarrierConfig& config, const Clock& clock);
  ~UdpCarrier() override;
  UdpCarrier(const UdpCarrier&) = delete;
  UdpCarrier& operator=(const UdpCarrier&) = delete;

  CarrierStatus try_send(const CanFdFrame& frame) noexcept override;
  CarrierStatus try_receive(ReceivedFrame& out) noexcept override;
  const CarrierHealth& health() const noexcept override { return health_; }

  /// The bound port (the ephemeral one when local_port was 0).
  [[nodiscard]] std::uint16_t local_port() const noexcept { return local_port_; }
  [[nodiscard]] bool has_remote() const noexcept { return has_remote_; }

 private:
  int fd_ = -1;
  const Clock& clock_;
  std::uint16_t local_port_ = 0;
  bool learn_remote_ = false;
  bool has_remote_ = false;
  sockaddr_in remote_{};
  CarrierHealth health_{};
};

/// Packs / unpacks the datagram layout above (pure; tested on their own). unpack returns
/// false for a datagram whose size or length field is wrong.
std::size_t pack_udp_frame(const CanFdFrame& frame, std::uint8_t* out) noexcept;
bool unpack_udp_frame(const std::uint8_t* datagram, std::size_t size, CanFdFrame& out) noexcept;

}  // namespace fissure::transport
