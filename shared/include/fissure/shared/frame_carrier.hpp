#pragma once
// What moves wire frames between the two ends (BRIEF §2, §8). The leaf drivers differ
// (in-memory loopback, UDP datagrams, SocketCAN), the frames and the codec do not.
// try_send / try_receive never block and never allocate: callable from the rt tick.
#include <cstdint>
#include <stdexcept>
#include <string>

#include "fissure/shared/can_fd_frame.hpp"

namespace fissure::transport {

using wire::CanFdFrame;
using wire::ReceivedFrame;

enum class CarrierStatus : std::uint8_t {
  kOk = 0,
  kEmpty,    ///< try_receive: nothing waiting
  kBusy,     ///< try_send: the transmit queue is full right now; try again next tick
  kBusOff,   ///< the CAN controller is bus-off: nothing can be sent until it restarts
  kError,    ///< any other failure; CarrierHealth::last_errno says which
};
const char* to_string(CarrierStatus status) noexcept;

/// Counters a carrier keeps about itself (link-layer trouble the codec never sees).
struct CarrierHealth {
  std::uint64_t frames_sent = 0;
  std::uint64_t frames_received = 0;
  std::uint64_t send_busy = 0;          ///< try_send returned kBusy
  std::uint64_t send_errors = 0;        ///< try_send failed otherwise
  std::uint64_t receive_errors = 0;     ///< read failures other than "nothing there"
  std::uint64_t malformed_received = 0; ///< datagram/frame of the wrong size or length field
  std::uint64_t error_frames = 0;       ///< SocketCAN error frames received
  std::uint64_t bus_off_events = 0;     ///< error frames reporting bus-off
  std::uint64_t tx_timeouts = 0;        ///< error frames reporting a transmit timeout
  std::uint64_t controller_problems = 0;///< error-passive / warning / overflow reports
  std::uint64_t restarts = 0;           ///< controller restarted after bus-off
  bool bus_off = false;                 ///< currently bus-off (cleared by a restart report)
  int last_errno = 0;                   ///< errno of the last failure (0 if none)
};

class FrameCarrier {
 public:
  virtual ~FrameCarrier() = default;
  /// Queues one frame for transmission. kOk, kBusy (try later), kBusOff or kError.
  [[nodiscard]] virtual CarrierStatus try_send(const CanFdFrame& frame) noexcept = 0;
  /// Takes the next received frame: kOk (out filled), kEmpty, or kError.
  [[nodiscard]] virtual CarrierStatus try_receive(ReceivedFrame& out) noexcept = 0;
  [[nodiscard]] virtual const CarrierHealth& health() const noexcept = 0;
};

/// Opening a carrier failed (setup time only; the hot path returns CarrierStatus). The text
/// names the interface or address and the system error.
class TransportError : public std::runtime_error {
 public:
  enum class Kind : std::uint8_t { kUnsupported, kNoSuchInterface, kConfiguration, kSystem };
  TransportError(Kind kind, const std::string& what) : std::runtime_error(what), kind_(kind) {}
  [[nodiscard]] Kind kind() const noexcept { return kind_; }

 private:
  Kind kind_;
};

}  // namespace fissure::transport
