#pragma once
// Pipeline stage: Hunt-Crossley contact force per proxy patch, evaluated at the CURRENT
// tool position (BRIEF §4, §5) — this is what makes the contact stiffness felt at the fast
// rate although the host only refreshes the proxy at 50–1000 Hz.
//   x  = (plane_point_world − p_part_world) · n        penetration [m]
//   ẋ  = −v_part_world · n                              penetration rate [m/s] (plane static)
//   F  = max(0, k·xⁿ + λ·xⁿ·ẋ) · n   for x > 0, else 0
// The F ≥ 0 clamp matters when the tool is withdrawn faster than k/λ: the raw formula would
// pull the tool into the surface (everyone clamps: Simbody, RBD.jl, LIGGGHTS).
#include "fissure/shared/device_mapping.hpp"
#include "fissure/shared/messages.hpp"
#include "fissure/shared/session_config.hpp"

namespace fissure::rt {

/// Scalar Hunt-Crossley law [N] for penetration x [m] and rate ẋ [m/s]; ≥ 0, 0 for x ≤ 0.
double hunt_crossley_force_n(double penetration_m, double penetration_rate_m_per_s, double stiffness_k,
                             double damping_lambda, double exponent_n) noexcept;

/// Summary of one proxy evaluation (telemetry).
struct ContactEvaluation {
  double max_penetration_m = 0.0;  ///< deepest patch penetration (≤ 0: no contact)
  int patches_in_contact = 0;
};

/// Adds every patch's force to `forces` (cleared first), world frame, per tool part.
ContactEvaluation evaluate_proxy(const ContactProxy& proxy, const DeviceMapping& mapping, const ToolState& tool,
                                 PartForces& forces) noexcept;

}  // namespace fissure::rt
