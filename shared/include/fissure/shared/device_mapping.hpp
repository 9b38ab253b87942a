#pragma once
// Device frame ↔ world (tool) frame, from the session's DeviceMapping (session_config.hpp):
// rt_core applies it in its tick and the host places the tool and its jaws with it, so both
// halves share one definition.
//   p_world = world_offset_m + scale · S·P · (p_device − device_origin_m)
//   F_device = force_scale · (S·P)ᵀ · F_world
// Clamp mode (the paper's clamp): world axis c = closing_axis_world is not driven by the
// device; the device axis that would have driven it opens/closes the jaws instead:
//   jaw_closing_m = axis_sign[c] · (p_device[perm[c]] − device_origin_m[perm[c]])   (device metres)
// and the tool stays at world_offset_m[c] along e_c. Jaw positions (the convention the
// host's proxy builder must use for kJawA / kJawB patches):
//   p_jawA_world = p_tool_world + (scale · jaw_closing_m / 2) · e_c
//   p_jawB_world = p_tool_world − (scale · jaw_closing_m / 2) · e_c
// i.e. jaw A sits on the −e_c side and jaw B on the +e_c side, and a positive closing moves
// them towards each other. The grip force rendered on the closing axis is the generalised
// force of the jaw forces on the closing DoF (virtual work), with force_scale as the gain:
//   F_device[perm[c]] = force_scale · axis_sign[c] · ((F_jawA − F_jawB) · e_c) / 2
// Outside clamp mode every patch acts on the tool point and the parts are summed.
#include <array>

#include <Eigen/Core>

#include "fissure/shared/messages.hpp"
#include "fissure/shared/session_config.hpp"

namespace fissure {

/// Where the tool and its jaws are, world frame, derived from the device sample.
struct ToolState {
  Eigen::Vector3d p_tool_world_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_tool_world_m_per_s = Eigen::Vector3d::Zero();
  double jaw_closing_m = 0.0;                ///< clamp mode only, device metres
  double jaw_closing_rate_m_per_s = 0.0;     ///< clamp mode only
};

/// Position and velocity of one tool part (tool origin or a jaw), world frame.
struct PartMotion {
  Eigen::Vector3d p_world_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_world_m_per_s = Eigen::Vector3d::Zero();
};

/// World-frame force sums per tool part, indexed by static_cast<size_t>(ToolPart).
struct PartForces {
  std::array<Eigen::Vector3d, 3> force_world_n{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                               Eigen::Vector3d::Zero()};
  void clear() noexcept {
    for (Eigen::Vector3d& f : force_world_n) f.setZero();
  }
};

/// True when the mapping is usable: permutation of {0,1,2}, signs ±1, finite positive scales,
/// closing axis in 0..2. (Checked once when the model is built, never in the tick.)
bool is_valid(const DeviceMapping& mapping) noexcept;

ToolState device_to_tool(const DeviceMapping& mapping, const Eigen::Vector3d& p_device_m,
                         const Eigen::Vector3d& v_device_m_per_s) noexcept;

PartMotion part_motion(const DeviceMapping& mapping, const ToolState& tool, ToolPart part) noexcept;

/// The device-frame force [N] that renders the per-part world forces.
Eigen::Vector3d part_forces_to_device(const DeviceMapping& mapping, const PartForces& forces) noexcept;

/// Jaw closing [m] from a device position (0 outside clamp mode); used for DeviceState.
double jaw_closing_m(const DeviceMapping& mapping, const Eigen::Vector3d& p_device_m) noexcept;

}  // namespace fissure
