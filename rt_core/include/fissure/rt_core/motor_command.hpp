#pragma once
// Pipeline stage: Jᵀ and the motor command. τ = Jᵀ·F with J = ∂p/∂θ1 at the current
// position, then counts through the calibration gain with falcon_hw's direction-keeping
// ±4095 clamp. A Jacobian that cannot be formed (outside the reachable region) or a
// non-finite result gives a zero command and kFaultNonFinite.
#include <cstdint>

#include <Eigen/Core>

#include "fissure/falcon_hw/falcon_geometry.hpp"
#include "fissure/falcon_hw/haptic_device.hpp"

namespace fissure::rt {

/// Writes the command for `force_device_n` at `p_device_m` into `command.motor_counts`;
/// ORs kFlagMotorSaturated / kFaultNonFinite into `flags`. False → zero command.
bool force_to_command(const falcon::FalconGeometry& geometry, double newton_metre_per_count,
                      const Eigen::Vector3d& p_device_m, const Eigen::Vector3d& force_device_n,
                      falcon::DeviceCommand& command, std::uint32_t& flags) noexcept;

}  // namespace fissure::rt
