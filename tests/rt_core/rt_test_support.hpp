#pragma once
// Shared helpers of the rt_core suites: proxies, fake devices.
#include <array>
#include <cstdint>

#include "fissure/falcon_hw/encoder_mapping.hpp"
#include "fissure/falcon_hw/haptic_device.hpp"
#include "fissure/falcon_hw/kinematics.hpp"
#include "fissure/shared/messages.hpp"

namespace fissure::rt::testing {

/// A one-plane proxy: plane through `point`, force along `normal` (unit), HC (k, λ, n).
inline ContactProxy plane_proxy(std::uint64_t sequence, const Vec3& point, const Vec3& normal, double k,
                                double lambda = 0.0, double n = 1.0) {
  ContactProxy proxy;
  proxy.sequence = sequence;
  proxy.flags = kProxyValid;
  proxy.patch_count = 1;
  ContactPatch& patch = proxy.patches[0];
  patch.plane_point_world_m = point;
  patch.normal_world = normal;
  patch.stiffness_k = k;
  patch.damping_lambda = lambda;
  patch.exponent_n = n;
  return proxy;
}

/// A device that holds still at a given position (encoder counts from the real IK) and
/// returns a configurable status: the simplest thing the tick can be tested against.
class StillDevice final : public falcon::HapticDevice {
 public:
  explicit StillDevice(const Eigen::Vector3d& p_device_m) { place(p_device_m); }
  void place(const Eigen::Vector3d& p_device_m) {
    Eigen::Vector3d theta;
    if (!falcon::inverse_kinematics(falcon::FalconGeometry{}, p_device_m, theta)) throw std::runtime_error("unreachable");
    counts = falcon::theta_to_encoders(falcon::EncoderMapping{}, theta);
  }
  [[nodiscard]] const char* name() const noexcept override { return "still"; }
  falcon::IoStatus try_exchange(const falcon::DeviceCommand& command, falcon::DeviceReading& reading) noexcept override {
    last_command = command;
    ++exchanges;
    if (status != falcon::IoStatus::kOk) return status;
    reading.encoder_counts = counts;
    reading.homed_mask = 0x7;
    return falcon::IoStatus::kOk;
  }
  std::array<std::int16_t, 3> counts{};
  falcon::IoStatus status = falcon::IoStatus::kOk;
  falcon::DeviceCommand last_command{};
  std::int64_t exchanges = 0;
};

}  // namespace fissure::rt::testing
