#include "fissure/shared/loopback_carrier.hpp"

namespace fissure::transport {

CarrierStatus LoopbackLink::End::try_send(const CanFdFrame& frame) noexcept {
  if (!link_.ring_to(1 - index_).try_push(frame)) {
    ++health_.send_busy;
    return CarrierStatus::kBusy;
  }
  ++health_.frames_sent;
  return CarrierStatus::kOk;
}

CarrierStatus LoopbackLink::End::try_receive(ReceivedFrame& out) noexcept {
  if (!link_.ring_to(index_).try_pop(out.frame)) return CarrierStatus::kEmpty;
  out.receive_time_ns = link_.clock_.now();
  ++health_.frames_received;
  return CarrierStatus::kOk;
}

}  // namespace fissure::transport
