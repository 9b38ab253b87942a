#pragma once
// SocketCAN carrier (BRIEF §8): raw CAN FD frames on a Linux CAN interface (can0, vcan0).
//   * AF_CAN / SOCK_RAW / CAN_RAW with CAN_RAW_FD_FRAMES; the interface MTU must be 72
//     (CANFD_MTU) or opening fails naming the interface and the fix.
//   * SO_TIMESTAMP: receive_time_ns is the kernel's receive time, mapped from CLOCK_REALTIME
//     to CLOCK_MONOTONIC (MonotonicClock's timeline) when the frame is read.
//   * CAN_RAW_ERR_FILTER: error frames (tx timeout, controller problems, no ACK, bus-off,
//     restarted) are consumed by try_receive and reported in CarrierHealth.
//   * A receive filter passes only the wire codec's identifiers (kCanIdBase … +3).
// Where the kernel has no CAN support, construction throws TransportError of kind
// kUnsupported; socketcan_supported() asks without throwing.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fissure/shared/clock.hpp"
#include "fissure/shared/frame_carrier.hpp"

namespace fissure::transport {

/// True when this kernel can create an AF_CAN raw socket. Otherwise false, with the reason
/// (e.g. "AF_CAN unsupported by this kernel (socket: Address family not supported by protocol)")
/// written to `reason` if given.
bool socketcan_supported(std::string* reason = nullptr);

/// What a SocketCAN error frame reports (pure decoding of linux/can/error.h; tested on its own).
struct CanErrorReport {
  bool bus_off = false;
  bool tx_timeout = false;
  bool no_ack = false;
  bool controller_problem = false;  ///< warning / error-passive / buffer overflow
  bool protocol_violation = false;
  bool restarted = false;           ///< controller left bus-off
};
CanErrorReport classify_can_error_frame(std::uint32_t can_id, const std::uint8_t* data, std::size_t length) noexcept;

class SocketCanCarrier final : public FrameCarrier {
 public:
  /// Opens `interface_name`; throws TransportError (kUnsupported, kNoSuchInterface,
  /// kConfiguration for a classic-CAN MTU, kSystem) with a one-line reason.
  /// `clock` only stamps frames the kernel delivered without a timestamp.
  SocketCanCarrier(const std::string& interface_name, const Clock& clock);
  ~SocketCanCarrier() override;
  SocketCanCarrier(const SocketCanCarrier&) = delete;
  SocketCanCarrier& operator=(const SocketCanCarrier&) = delete;

  CarrierStatus try_send(const CanFdFrame& frame) noexcept override;
  /// Returns the next data frame; error frames met on the way update health() and are skipped.
  CarrierStatus try_receive(ReceivedFrame& out) noexcept override;
  const CarrierHealth& health() const noexcept override { return health_; }

  [[nodiscard]] const std::string& interface_name() const noexcept { return interface_name_; }

 private:
  void apply(const CanErrorReport& report) noexcept;

  int fd_ = -1;
  std::string interface_name_;
  const Clock& clock_;
  CarrierHealth health_{};
};

}  // namespace fissure::transport
