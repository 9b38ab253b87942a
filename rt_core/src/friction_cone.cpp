#include "fissure/rt_core/friction_cone.hpp"

#include <algorithm>
#include <cmath>

namespace fissure::rt {
namespace {

// Below this elastic normal force a part is out of contact for friction [N]: 1 mN is the
// Falcon's force resolution (~1 mN per motor count, BRIEF §6); a cone narrower than that
// cannot be felt and its direction is numerical noise.
constexpr double kMinNormalForce_n = 1.0e-3;
// Below this part speed [m/s] the lag since the host's step is not estimated (taken as 0): one
// encoder count per 50 ms, where (p − p_ref)·v/|v|² is quantisation noise over noise — and the
// part has barely moved, so the lag changes nothing.
constexpr double kMinLagSpeed_m_per_s = 1.0e-3;
// Longest lag the seat accounts for [s]: ProxyConfig::stale_after_s's 0.1 s — an older proxy is
// being faded out anyway.
constexpr double kMaxLag_s = 0.1;

void drop_anchor(FrictionState& state, std::size_t part) noexcept {
  state.anchored[part] = false;
  state.sliding[part] = false;
  state.last_force_n[part] = 0.0;
}

Eigen::Vector3d tangential(const Eigen::Vector3d& v, const Eigen::Vector3d& unit_normal) noexcept {
  return v - v.dot(unit_normal) * unit_normal;
}

}  // namespace

FrictionEvaluation evaluate_friction(const FrictionModel& model, FrictionState& state, const ContactProxy& proxy,
                                     const PartNormalLoad& load, const DeviceMapping& mapping,
                                     const ToolState& tool) noexcept {
  FrictionEvaluation evaluation;
  const double k_t = model.stick_stiffness_world_n_per_m;
  for (std::size_t part = 0; part < state.anchor_world_m.size(); ++part) {
    const auto tool_part = static_cast<ToolPart>(part);
    const PartFriction& friction = proxy.friction[part];
    const Eigen::Vector3d& normal_force = load.elastic_force_world_n[part];
    const double normal_n = normal_force.norm();
    const double normal_sum_n = load.elastic_sum_n[part];
    const bool carried = (proxy.flags & proxy_friction_bit(tool_part)) != 0u;
    if (!carried || !(friction.static_ratio > 0.0) || !(k_t > 0.0) || !(normal_n > kMinNormalForce_n) ||
        !std::isfinite(normal_n) || !std::isfinite(normal_sum_n)) {
      drop_anchor(state, part);
      continue;
    }
    const PartMotion motion = part_motion(mapping, tool, tool_part);
    const Eigen::Vector3d& p = motion.p_world_m;
    const Eigen::Map<const Eigen::Vector3d> reference(friction.reference_part_position_world_m.data());
    const Eigen::Map<const Eigen::Vector3d> host_force(friction.host_force_world_n.data());
    const Eigen::Map<const Eigen::Vector3d> surface_velocity(friction.surface_velocity_world_m_per_s.data());
    if (!p.allFinite() || !motion.v_world_m_per_s.allFinite() || !reference.allFinite() || !host_force.allFinite() ||
        !surface_velocity.allFinite()) {
      drop_anchor(state, part);
      continue;
    }
    const Eigen::Vector3d n = normal_force / normal_n;
    // The host's seat: a spring to it gives F_host at p_ref; the tissue has since moved on by v_s
    // for as long as the part took to get from p_ref to p.
    const double speed_sq = motion.v_world_m_per_s.squaredNorm();
    const double lag_s = speed_sq > kMinLagSpeed_m_per_s * kMinLagSpeed_m_per_s
                             ? std::clamp((p - reference).dot(motion.v_world_m_per_s) / speed_sq, 0.0, kMaxLag_s)
                             : 0.0;
    const Eigen::Vector3d seat = reference + tangential(host_force, n) / k_t + lag_s * surface_velocity;
    Eigen::Vector3d& anchor = state.anchor_world_m[part];
    if (!state.anchored[part]) {
      anchor = seat;
      state.anchored[part] = true;
      state.sliding[part] = false;
    } else {
      anchor += model.period_s * surface_velocity;
      const Eigen::Vector3d gap = tangential(seat - anchor, n);
      const double gap_m = gap.norm();
      const double walk_m = std::min(model.walk_share * gap_m, model.max_walk_m);
      if (gap_m > 0.0) anchor += (walk_m / gap_m) * gap;
    }
    const Eigen::Vector3d stretch = p - anchor;
    Eigen::Vector3d d = tangential(stretch, n);
    double stretch_m = d.norm();
    // Break away at μ_s; once sliding, keep sliding while the spring would exceed μ_k (Coulomb's
    // two coefficients: a slide that slows to under μ_k·F_n/K_t of stretch sticks again).
    const double kinetic_bound_n = friction.kinetic_ratio * normal_sum_n;
    const double bound_n = state.sliding[part] ? kinetic_bound_n : friction.static_ratio * normal_sum_n;
    if (k_t * stretch_m > bound_n) {
      // The drop from the static to the kinetic cone at break-away is spread at max_step per tick
      // (0.2 N at once for 0.5 / 0.4 × 2 N: a click, measured on spatula-ball-drag).
      const double slide_n = std::max(kinetic_bound_n, std::min(k_t * stretch_m, state.last_force_n[part] - model.max_step_world_n));
      const double slide_stretch_m = slide_n / k_t;
      d *= slide_stretch_m / stretch_m;
      // Only the anchor's in-plane offset to the part changes: its normal offset is kept.
      anchor = p - d - stretch.dot(n) * n;
      stretch_m = slide_stretch_m;
      state.sliding[part] = true;
      ++evaluation.parts_sliding;
    } else {
      state.sliding[part] = false;
      ++evaluation.parts_sticking;
    }
    evaluation.force_world_n.force_world_n[part] = -k_t * d;
    state.last_force_n[part] = k_t * stretch_m;
    evaluation.stored_energy_world_j += 0.5 * k_t * stretch_m * stretch_m;
  }
  return evaluation;
}

}  // namespace fissure::rt
