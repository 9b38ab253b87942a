#include "fissure/falcon_hw/haptic_device.hpp"

namespace fissure::falcon {

const char* to_string(IoStatus status) noexcept {
  switch (status) {
    case IoStatus::kOk: return "ok";
    case IoStatus::kTimeout: return "timeout";
    case IoStatus::kTornPacket: return "torn packet";
    case IoStatus::kDisconnected: return "disconnected";
    case IoStatus::kNotRunning: return "not running";
  }
  return "unknown";
}

}  // namespace fissure::falcon
