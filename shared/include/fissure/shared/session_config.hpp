#pragma once
// Session configuration shared by both halves: how device axes map to the scene's tool
// (applied by rt_core, known to host_sim), and the scripted hand that holds SimFalcon's
// grip. Pure data; scene files (TOML, parsed in host_sim) fill it in. Not used in the tick
// except DeviceMapping, which is trivially copyable.
#include <array>
#include <cstdint>
#include <vector>

#include "fissure/shared/messages.hpp"

namespace fissure {

/// Device frame → world (tool) frame:
///   p_world = world_offset_m + scale · S · P · (p_device − device_origin_m)
/// where P picks device axis `axis_permutation[i]` for world axis i and S applies
/// `axis_sign[i]`. Forces go back the same way: F_device = force_scale · (S·P)ᵀ · F_world.
/// Clamp mode (the paper's clamp): the tool moves in the plane of the two world axes
/// other than `closing_axis_world`; the device axis that would have driven that world axis
/// opens/closes the jaws instead (jaw closing = device displacement along it, metres, sign
/// per axis_sign), and the jaws' grip force is rendered back along it.
struct DeviceMapping {
  double scale = 1.0;                          ///< world metres per device metre [-]
  double force_scale = 1.0;                    ///< device newtons per world newton [-]
  std::array<std::uint8_t, 3> axis_permutation{0, 1, 2};
  std::array<std::int8_t, 3> axis_sign{1, 1, 1};
  Vec3 device_origin_m{0.0, 0.0, 0.0};         ///< device point that maps to world_offset_m [m]
  Vec3 world_offset_m{0.0, 0.0, 0.0};          ///< world position of device_origin_m [m]
  bool clamp_mode = false;
  std::uint8_t closing_axis_world = 2;         ///< clamp mode: world axis replaced by jaw closing
};
static_assert(std::is_trivially_copyable_v<DeviceMapping>);

/// One leg of the scripted hand: move the hand target in a straight line to
/// `position_device_m` at `speed_m_per_s`, then hold it there for `hold_s`.
struct HandWaypoint {
  Vec3 position_device_m{};
  double speed_m_per_s = 0.1;
  double hold_s = 0.0;
};

/// From `time_s` on (session time), the grip buttons read `buttons`.
struct ButtonEvent {
  double time_s = 0.0;
  std::uint32_t buttons = 0;
};

/// The operator's hand on SimFalcon's grip: a spring-damper pulling the end effector
/// toward a target that follows the waypoints. stiffness/damping are a firm human grip
/// (arm impedance studies put a relaxed-to-firm grip at ~100–1000 N/m, 2–20 N·s/m).
struct HandScript {
  Vec3 start_position_device_m{0.0, 0.0, 0.11};  ///< target at t = 0 (Falcon workspace centre ≈ z 0.11 m)
  std::vector<HandWaypoint> waypoints;
  std::vector<ButtonEvent> button_events;
  double grip_stiffness_n_per_m = 300.0;
  double grip_damping_n_s_per_m = 5.0;
  bool release_at_end = true;  ///< after the last waypoint's hold, let go (hand force 0)
};

}  // namespace fissure
