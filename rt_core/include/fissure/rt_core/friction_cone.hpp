#pragma once
// Pipeline stage: Coulomb friction at the current tool position — the friction cone of
// god-object haptic rendering (Salisbury, Brock, Swarup & Zilles 1995; Melder & Harwin 2003),
// kept in step with the host's friction. For each tool part (the tool, or each clamp jaw) rt_core
// keeps a stick anchor, a point of the tissue surface in the world frame. Every tick:
//   1. the tissue moves on:   anchor += v_s·T        (v_s: the surface's velocity under the part, from the host)
//   2. the anchor walks towards the host's state: the seat  a* = p_ref + F_host,t/K_t + v_s·Δt,
//      where a spring to a* gives the host's friction F_host at the part's position p_ref in the
//      host's step, and the tissue has since moved on by v_s for Δt, the part's travel since p_ref
//      along its velocity, (p − p_ref)·v/|v|², within [0, 0.1 s]. The walk takes the share T/τ
//      of the gap (τ = FrictionConfig::host_follow_s), at most max_step_n/K_t per tick.
//   3. the cone, with n̂, F_n the direction and size of the part's elastic normal force
//      (Σ k·xⁿ·n over its patches, hunt_crossley.hpp):
//        d = (p − anchor) without its component along n̂,  F_t = −K_t·d
//        |F_t| > μ·F_n → slide: the anchor follows to |d| = μ_k·F_n/K_t, F_t = −μ_k·F_n·d̂
//      with μ = μ_s to break away from sticking and μ_k while sliding; the drop from μ_s·F_n to
//      μ_k·F_n at break-away is spread at max_step_n per tick (a few ms).
//
// Why the split: only rt_core knows where the hand is now, and only the host knows what the
// tissue does. The cone at the device rate makes the drag exact and immediate: a part sliding
// over tissue feels μ_k·F_n from the first tick, a hand that stops feels the stick spring hold,
// at a 100 Hz host as at 1 kHz. The walk makes it right over time: a part holding tissue that
// moves with it (a lifted vessel: v_s ≈ the part's velocity) comes to feel what the tissue pulls,
// not a phantom slide, and a hand at rest after a slide comes to feel what the tissue pulls back.
// Why a walk and not a re-seat at each proxy: the host's friction is the sum over the nodes it
// holds, which stick and slip one by one; it jumps by tenths of a newton from step to step
// (spatula-ball-drag at 1 kHz: 0.44–0.87 N around 0.7 N). Re-seated at every proxy and blended
// (proxy_blend.hpp), the force followed rt_core's own stick spring up to the static cone, since
// the hand's motion used up the blend's step budget (docs/decisions.md, issue 23).
// Why the elastic normal force: the damping share λ·xⁿ·ẋ changes sign with every encoder count
// at rest, and a cone that breathes with it would make a stuck hand buzz; the host's cone uses
// the same elastic share (solver_projection.cpp).
//
// Continuity: the force changes per tick by K_t × the hand's motion (the stiffness rendered,
// never smoothed), the walk's ≤ max_step_n, and the cone's bound as F_n changes. The swap
// blend therefore leaves friction out (tick.cpp). Energy: the stick spring stores ½·K_t·|d|²;
// it joins the contact's stored energy in the passivity controller's reference (passivity.hpp).
#include <array>

#include <Eigen/Core>

#include "fissure/shared/device_mapping.hpp"
#include "fissure/shared/messages.hpp"

namespace fissure::rt {

/// Stiffness of the stick spring, as felt at the handle [N/m]. A third of the Falcon's rated
/// 3000 N/m (Novint's specification, safety.hpp) and far under the 6000 N/m Colgate–Schenkel
/// allows on its 3 N·s/m at 1 kHz: at 0.4 × 2 N the stick stretches 0.8 mm before it slides —
/// 16 encoder counts, so a stuck hand feels a spring, not the count quantisation.
inline constexpr double kDefaultFrictionStickStiffness_n_per_m = 1000.0;
/// Time constant of the anchor's walk towards the host's friction state [s]: long beside a 1 kHz
/// host step, so the host's node-by-node stick–slip averages out (its friction swings ±0.2 N
/// from step to step), short beside a grip or a lift (hundreds of ms).
inline constexpr double kDefaultFrictionHostFollow_s = 0.02;
/// Largest force change per tick from the walk [N]: the blend's bound for a proxy swap
/// (ProxyConfig::blend_max_step_n, issue 6), for the same reason: the hand must not feel it as a
/// click.
inline constexpr double kDefaultFrictionMaxStep_n = 0.05;

struct FrictionConfig {
  /// K_t at the device [N/m], in [0, 3000] (0 renders no friction).
  double stick_stiffness_device_n_per_m = kDefaultFrictionStickStiffness_n_per_m;
  /// τ of the walk towards the host's state [s], > 0.
  double host_follow_s = kDefaultFrictionHostFollow_s;
  /// Largest force change per tick from the walk and from the break-away drop, at the device [N], > 0.
  double max_step_n = kDefaultFrictionMaxStep_n;
};

/// What the stage needs from the model, in world units (RtModel derives it from FrictionConfig).
struct FrictionModel {
  double stick_stiffness_world_n_per_m = 0.0;  ///< K_t
  double walk_share = 0.0;                     ///< T/τ, ≤ 1
  double max_walk_m = 0.0;                     ///< max_step_n (world) / K_t
  double max_step_world_n = 0.0;               ///< max_step_n in world newtons: also the static → kinetic drop per tick
  double period_s = 0.0;                       ///< T
};

/// Per tool part (indexed by ToolPart): the patches' elastic normal force.
struct PartNormalLoad {
  std::array<Eigen::Vector3d, 3> elastic_force_world_n{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                                       Eigen::Vector3d::Zero()};  ///< Σ k·xⁿ·n
  std::array<double, 3> elastic_sum_n{0.0, 0.0, 0.0};  ///< Σ k·xⁿ: Coulomb's F_n, summed per contact
};

struct FrictionState {
  std::array<Eigen::Vector3d, 3> anchor_world_m{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                                Eigen::Vector3d::Zero()};
  std::array<bool, 3> anchored{false, false, false};
  std::array<bool, 3> sliding{false, false, false};
  std::array<double, 3> last_force_n{0.0, 0.0, 0.0};  ///< |F_t| rendered last tick (world)
};

/// What one evaluation rendered (telemetry, the passivity reference).
struct FrictionEvaluation {
  PartForces force_world_n{};          ///< friction force per part, world frame
  double stored_energy_world_j = 0.0;  ///< Σ ½·K_t·|d|² over the anchored parts
  int parts_sliding = 0;
  int parts_sticking = 0;
};

/// One tick of the stage for every part of `proxy` that carries friction (see above): a part
/// first touched is anchored at the host's seat; anchors move with the tissue, walk towards the
/// host's state, slide on the cone, and drop out of contact. Non-finite input drops the anchor
/// and gives zero force.
FrictionEvaluation evaluate_friction(const FrictionModel& model, FrictionState& state, const ContactProxy& proxy,
                                     const PartNormalLoad& load, const DeviceMapping& mapping,
                                     const ToolState& tool) noexcept;

}  // namespace fissure::rt
