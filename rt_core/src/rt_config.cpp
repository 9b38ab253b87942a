#include "fissure/rt_core/rt_config.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "fissure/shared/device_mapping.hpp"

namespace fissure::rt {
namespace {

bool positive(double x) noexcept { return std::isfinite(x) && x > 0.0; }
bool non_negative(double x) noexcept { return std::isfinite(x) && x >= 0.0; }

}  // namespace

const char* check_config(const RtConfig& c) noexcept {
  if (!(std::isfinite(c.rate_hz) && c.rate_hz >= kMinRate_hz && c.rate_hz <= kMaxRate_hz)) {
    return "rate_hz must be in [500, 10000] Hz";
  }
  if (!is_valid(c.mapping)) {
    return "mapping: axis_permutation must permute {0,1,2}, axis_sign be ±1, scale > 0, force_scale ≥ 0, "
           "closing_axis_world in 0..2, offsets finite";
  }
  if (!std::isfinite(c.kinematics.encoder.radians_per_count) || c.kinematics.encoder.radians_per_count == 0.0 ||
      !std::isfinite(c.kinematics.encoder.offset_rad)) {
    return "kinematics.encoder: radians_per_count must be finite and non-zero, offset_rad finite";
  }
  if (!positive(c.kinematics.newton_metre_per_count)) return "kinematics.newton_metre_per_count must be > 0";
  if (!positive(c.kinematics.fk.tolerance_rad) || c.kinematics.fk.max_iterations < 1) {
    return "kinematics.fk: tolerance_rad must be > 0 and max_iterations ≥ 1";
  }
  if (!(positive(c.velocity.cutoff_hz) && c.velocity.cutoff_hz < 0.5 * c.rate_hz)) {
    return "velocity.cutoff_hz must be in (0, rate_hz/2)";
  }
  if (!positive(c.proxy.blend_max_step_n)) return "proxy.blend_max_step_n must be > 0";
  if (!positive(c.proxy.stale_after_s)) return "proxy.stale_after_s must be > 0";
  if (!non_negative(c.proxy.fade_s)) return "proxy.fade_s must be ≥ 0";
  if (!(non_negative(c.friction.stick_stiffness_device_n_per_m) &&
        c.friction.stick_stiffness_device_n_per_m <= kFalconMaxStiffness_n_per_m)) {
    return "friction.stick_stiffness_device_n_per_m must be in [0, 3000] N/m (the Falcon's rated stiffness)";
  }
  if (!positive(c.friction.host_follow_s)) return "friction.host_follow_s must be > 0";
  if (!positive(c.friction.max_step_n)) return "friction.max_step_n must be > 0";
  if (!non_negative(c.passivity.max_damping_n_s_per_m)) return "passivity.max_damping_n_s_per_m must be ≥ 0";
  if (!positive(c.passivity.min_speed_m_per_s)) return "passivity.min_speed_m_per_s must be > 0";
  if (!positive(c.passivity.margin_j)) return "passivity.margin_j must be > 0";
  if (!positive(c.passivity.max_correction_step_n)) return "passivity.max_correction_step_n must be > 0";
  if (!positive(c.passivity.dissipation_time_s)) return "passivity.dissipation_time_s must be > 0";
  if (!non_negative(c.passivity.damping_ramp_s)) return "passivity.damping_ramp_s must be ≥ 0";
  if (!(positive(c.safety.max_force_n) && c.safety.max_force_n <= kFalconMaxForce_n)) {
    return "safety.max_force_n must be in (0, 8] N (the Falcon's rating)";
  }
  // The controller bounds the energy of the force the device will render, i.e. after safety's
  // clamp; a different clamp here would let it predict a force that is never sent (or miss one).
  if (c.passivity.max_force_n != c.safety.max_force_n) {
    return "passivity.max_force_n must equal safety.max_force_n (the controller acts on the force safety lets through)";
  }
  if (!positive(c.safety.max_force_rate_n_per_s)) return "safety.max_force_rate_n_per_s must be > 0";
  if (!c.safety.workspace_centre_device_m.allFinite() || !positive(c.safety.workspace_radius_m)) {
    return "safety.workspace_centre_device_m must be finite and workspace_radius_m > 0";
  }
  if (!non_negative(c.safety.soft_wall_stiffness_n_per_m)) return "safety.soft_wall_stiffness_n_per_m must be ≥ 0";
  if (!non_negative(c.safety.ramp_in_s) || !non_negative(c.safety.ramp_out_s) ||
      !non_negative(c.safety.fault_ramp_in_s)) {
    return "safety.ramp_in_s, ramp_out_s and fault_ramp_in_s must be ≥ 0";
  }
  if (!positive(c.faults.max_joint_rate_rad_per_s)) return "faults.max_joint_rate_rad_per_s must be > 0";
  if (c.faults.recovery_ticks < 0) return "faults.recovery_ticks must be ≥ 0";
  if (!non_negative(c.passivity.device_damping_n_s_per_m)) return "passivity.device_damping_n_s_per_m must be ≥ 0";
  return nullptr;
}

bool build_model(const RtConfig& config, RtModel& model, const char** error) noexcept {
  const char* problem = check_config(config);
  if (error != nullptr) *error = problem;
  if (problem != nullptr) return false;
  model.config = config;
  model.period_ns = period_from_rate_hz(config.rate_hz);
  model.period_s = to_seconds(model.period_ns);
  model.velocity_filter = design_velocity_filter(config.velocity.cutoff_hz, config.rate_hz);
  model.velocity_lag_s = velocity_lag_s(config.velocity.cutoff_hz, config.rate_hz);
  // F_device = force_scale·F_world and Δp_world = scale·Δp_device: a world damping B renders
  // force_scale·scale·B at the device, so the device's b is b / (force_scale·scale) in the world.
  const double world_per_device_damping = config.mapping.force_scale * config.mapping.scale;
  model.damping_cap.device_damping_world_n_s_per_m = world_per_device_damping > 0.0
                                                         ? config.passivity.device_damping_n_s_per_m / world_per_device_damping
                                                         : std::numeric_limits<double>::infinity();
  model.damping_cap.period_s = model.period_s;
  model.device_energy_per_world_energy = config.mapping.force_scale / config.mapping.scale;
  // A world spring K renders force_scale·scale·K at the device (as the damping above).
  model.friction.stick_stiffness_world_n_per_m =
      world_per_device_damping > 0.0 ? config.friction.stick_stiffness_device_n_per_m / world_per_device_damping : 0.0;
  model.friction.walk_share = std::min(1.0, model.period_s / config.friction.host_follow_s);
  // max_step_n at the device is max_step_n / force_scale in the world; over K_t, a length.
  model.friction.max_walk_m = model.friction.stick_stiffness_world_n_per_m > 0.0 && config.mapping.force_scale > 0.0
                                  ? config.friction.max_step_n / config.mapping.force_scale /
                                        model.friction.stick_stiffness_world_n_per_m
                                  : 0.0;
  model.friction.max_step_world_n = config.mapping.force_scale > 0.0 ? config.friction.max_step_n / config.mapping.force_scale : 0.0;
  model.friction.period_s = model.period_s;
  return true;
}

}  // namespace fissure::rt
