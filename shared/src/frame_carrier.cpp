#include "fissure/shared/frame_carrier.hpp"

namespace fissure::transport {

const char* to_string(CarrierStatus status) noexcept {
  switch (status) {
    case CarrierStatus::kOk: return "ok";
    case CarrierStatus::kEmpty: return "empty";
    case CarrierStatus::kBusy: return "transmit queue full";
    case CarrierStatus::kBusOff: return "CAN bus-off";
    case CarrierStatus::kError: return "error";
  }
  return "unknown carrier status";
}

}  // namespace fissure::transport
