#pragma once
// Pipeline stage: the one last-line safety function. Whatever the stages before it did,
// the force that leaves it is finite, within the Falcon's rating, changes no faster than
// the rate limit, and is ramped in at start (and after a device fault) and ramped out at
// stop. Order inside apply_safety():
//   1. device fault or non-finite input → zero (and the ramp restarts from 0)
//   2. magnitude clamp to max_force_n, scaling the vector (direction kept)
//   3. × ramp gain (ramp-in 0→1 over ramp_in_s, ramp-out 1→0 over ramp_out_s)
//   4. force-rate limit |ΔF| ≤ max_force_rate_n_per_s·T per tick (a fault's zero is exempt:
//      cutting the force is always the safe direction)
// The workspace soft wall (a spring beyond the wall radius, pointing inwards) is computed
// here too, but the tick adds it to the contact force BEFORE the passivity controller: it is
// part of the rendered environment, and like any rendered spring it returns energy it never
// stored when it is ramped in around a hand that is already deep in it — after an encoder
// jump to a position 4–9 cm outside the workspace (stress case encoder_jumps: 8 N ramped in,
// 26 mJ in 80 ms) — which the controller must be able to take back; added after the
// controller, that energy would reach the hand where nothing can take it back.
#include <cstdint>

#include <Eigen/Core>

#include "fissure/falcon_hw/kinematics.hpp"

namespace fissure::rt {

/// The Falcon's rated continuous force [N] (Novint spec; CHAI3D's Falcon maxForce, BRIEF §5).
inline constexpr double kFalconMaxForce_n = 8.0;
/// CHAI3D's Falcon maxLinearStiffness [N/m] (BRIEF §5): the stiffest wall the device is
/// specified to render stably; used for the soft walls and as the Z-width reference.
inline constexpr double kFalconMaxStiffness_n_per_m = 3000.0;
/// CHAI3D's Falcon maxLinearDamping [N·s/m] (BRIEF §5).
inline constexpr double kFalconMaxDamping_n_s_per_m = 20.0;
/// The Falcon mechanism's viscous damping b [N·s/m] (motor back-EMF, capstan and joint friction
/// lumped): nominal, "a few N·s/m" per the published identifications the issue-3 brief quotes,
/// the same value as SimFalcon's kSimViscousDamping_n_s_per_m (falcon_hw/sim_falcon.hpp); not
/// measured on a unit. The b of Colgate–Schenkel's b > K·T/2 + |B| that caps rendered damping.
inline constexpr double kFalconDeviceDamping_n_s_per_m = 3.0;
/// CHAI3D's Falcon workspace radius [m] (BRIEF §5). Inside falcon_hw's documented 5 cm
/// well-conditioned ball and inside SimFalcon's 4.7 cm end stops, so the soft wall acts
/// before the mechanism's limits do.
inline constexpr double kFalconWorkspaceRadius_m = 0.04;
/// Force-rate limit [N/s]: full scale (8 N) in 2 ms. Rendering a 3000 N/m wall hit at
/// 1 m/s needs 3000 N/s, so real contact is never limited; a step from a bug is.
inline constexpr double kDefaultMaxForceRate_n_per_s = 4000.0;
/// Soft wall stiffness [N/m]: a third of the Falcon's rated stiffness, well inside the
/// Z-width at 500 Hz (bench rt), firm enough to stop a hand within ~8 mm at 8 N.
inline constexpr double kDefaultSoftWallStiffness_n_per_m = 1000.0;
/// Ramp-in at start [s]: a user holding the grip feels the scene's force come up over half
/// a second instead of a jolt (libfranka-style "motion generator" start).
inline constexpr double kDefaultRampIn_s = 0.5;
/// Ramp-out at stop [s]: short enough for Ctrl-C to feel immediate, long enough that 8 N
/// is not released as a step (8 N/0.2 s = 40 N/s).
inline constexpr double kDefaultRampOut_s = 0.2;
/// Ramp-in after a device fault cleared [s].
inline constexpr double kDefaultFaultRampIn_s = 0.25;

struct SafetyConfig {
  double max_force_n = kFalconMaxForce_n;
  double max_force_rate_n_per_s = kDefaultMaxForceRate_n_per_s;
  Eigen::Vector3d workspace_centre_device_m{falcon::kWorkspaceCentre_device_m[0], falcon::kWorkspaceCentre_device_m[1],
                                            falcon::kWorkspaceCentre_device_m[2]};
  double workspace_radius_m = kFalconWorkspaceRadius_m;
  double soft_wall_stiffness_n_per_m = kDefaultSoftWallStiffness_n_per_m;
  double ramp_in_s = kDefaultRampIn_s;
  double ramp_out_s = kDefaultRampOut_s;
  double fault_ramp_in_s = kDefaultFaultRampIn_s;
};

enum class RampPhase : std::uint8_t { kRampIn, kRunning, kRampOut, kStopped };

struct SafetyState {
  Eigen::Vector3d last_force_device_n = Eigen::Vector3d::Zero();  ///< what went out last tick
  double ramp_gain = 0.0;
  double ramp_in_s = 0.0;  ///< duration of the ramp-in under way (start or fault recovery)
  RampPhase phase = RampPhase::kRampIn;
};

struct SafetyInput {
  Eigen::Vector3d force_device_n = Eigen::Vector3d::Zero();
  Eigen::Vector3d p_device_m = Eigen::Vector3d::Zero();
  bool device_fault = false;     ///< any device-side fault this tick: zero at once
  bool stop_requested = false;   ///< ramp out, then stay at zero
};

/// Starts (or restarts after a fault) the ramp-in of the given duration.
void start_ramp_in(SafetyState& state, double ramp_in_s) noexcept;

/// Workspace soft wall at p_device_m [N]: soft_wall_stiffness·(distance − radius) towards
/// the centre beyond workspace_radius_m, else zero; ORs kFlagSoftWall into `flags` when it acts.
Eigen::Vector3d workspace_soft_wall_n(const SafetyConfig& config, const Eigen::Vector3d& p_device_m,
                                      std::uint32_t& flags) noexcept;

/// The magnitude clamp of apply_safety (step 2): force_n scaled down to max_force_n, direction
/// kept. The passivity controller uses it too, to act on the force the device will render.
Eigen::Vector3d clamp_force_magnitude(const Eigen::Vector3d& force_n, double max_force_n) noexcept;

/// The last line. Returns the force to command; ORs kFlag*/kFaultNonFinite bits into `flags`.
Eigen::Vector3d apply_safety(const SafetyConfig& config, SafetyState& state, const SafetyInput& input,
                             double period_s, std::uint32_t& flags) noexcept;

}  // namespace fissure::rt
