#pragma once
// Pipeline stage: Hunt-Crossley contact force per proxy patch, evaluated at the CURRENT
// tool position (BRIEF §4, §5) — this is what makes the contact stiffness felt at the fast
// rate although the host only refreshes the proxy at 50–1000 Hz.
//   x  = (plane_point_world − p_part_world) · n        penetration [m]
//   ẋ  = −v_part_world · n                              penetration rate [m/s] (plane static)
//   F  = max(0, k·xⁿ + λ·xⁿ·ẋ) · n   for x > 0, else 0
// The F ≥ 0 clamp matters when the tool is withdrawn faster than k/λ: the raw formula would
// pull the tool into the surface (everyone clamps: Simbody, RBD.jl, LIGGGHTS).
//
// Damping cap (Colgate & Schenkel 1997): a sampled wall of stiffness K and damping B at period
// T is passive only while the device's own damping b > K·T/2 + |B|. A patch's local stiffness
// is the tangent n·k·xⁿ⁻¹ and its damping λ·xⁿ (both per unit of tool motion, world frame), so
// the damping rendered is capped at max(0, b_world − n·k·xⁿ⁻¹·T/2), with b_world the device's
// damping seen in the world frame (b / (force_scale·scale): the mapping scales both force and
// motion). Damping beyond that is energy the device cannot dissipate; at high λ/k on a lagging
// filtered velocity it is what the stress runs found active. The cap never raises λ·xⁿ.
//
// Stored energy: the conservative part k·xⁿ stores U = k·xⁿ⁺¹/(n+1) per patch (the integral of
// the spring force over the penetration). The passivity controller's reference follows it
// (passivity.hpp): the environment may return what it stores.
#include <limits>

#include "fissure/rt_core/friction_cone.hpp"
#include "fissure/shared/device_mapping.hpp"
#include "fissure/shared/messages.hpp"
#include "fissure/shared/session_config.hpp"

namespace fissure::rt {

/// Scalar Hunt-Crossley law [N] for penetration x [m] and rate ẋ [m/s]; ≥ 0, 0 for x ≤ 0.
double hunt_crossley_force_n(double penetration_m, double penetration_rate_m_per_s, double stiffness_k,
                             double damping_lambda, double exponent_n) noexcept;

/// Summary of one proxy evaluation (telemetry, and the passivity controller's reference).
struct ContactEvaluation {
  double max_penetration_m = 0.0;  ///< deepest patch penetration (≤ 0: no contact)
  int patches_in_contact = 0;
  double stored_energy_world_j = 0.0;  ///< Σ k·xⁿ⁺¹/(n+1) over the patches in contact (world frame)
};

/// What the device can dissipate, for the damping cap. The default (infinite damping) caps
/// nothing: callers that do not render on a device (the host's own checks) get plain HC.
struct DampingCap {
  double device_damping_world_n_s_per_m = std::numeric_limits<double>::infinity();  ///< b in world units
  double period_s = 0.0;                                                             ///< T of the rendering loop
};

/// Adds every patch's force to `forces` (cleared first), world frame, per tool part, with each
/// patch's damping capped by `cap` (Colgate–Schenkel, above). With `load`, also the elastic
/// normal force per part (the friction cone's input).
ContactEvaluation evaluate_proxy(const ContactProxy& proxy, const DeviceMapping& mapping, const ToolState& tool,
                                 PartForces& forces, const DampingCap& cap = DampingCap{},
                                 PartNormalLoad* load = nullptr) noexcept;

}  // namespace fissure::rt
