#include "fissure/rt_core/tick.hpp"

#include <algorithm>
#include <cmath>

#include "fissure/shared/device_mapping.hpp"
#include "fissure/rt_core/faults.hpp"
#include "fissure/rt_core/force_position.hpp"
#include "fissure/rt_core/forward_kinematics_stage.hpp"
#include "fissure/rt_core/hunt_crossley.hpp"
#include "fissure/rt_core/joint_angles.hpp"
#include "fissure/rt_core/motor_command.hpp"
#include "fissure/rt_core/passivity.hpp"
#include "fissure/rt_core/proxy_blend.hpp"
#include "fissure/rt_core/safety.hpp"
#include "fissure/rt_core/staleness.hpp"
#include "fissure/rt_core/velocity_filter.hpp"

namespace fissure::rt {
namespace {

/// A gap between two device samples longer than this [s] — the rt thread stalled (descheduled,
/// a blocked exchange) while the device kept the last command — breaks the motion history like
/// a device fault: the velocity filter restarts, and the passivity observer restarts its Δp chain
/// and opens a recovery window (passivity.hpp). 10 ms is ten periods at 1 kHz: the wall was a
/// sampled spring held ten times longer than the loop is built for, and the motion across the
/// gap says nothing about the velocity at the loop's rate. Its work under the one command that
/// acted during it is exact, though, and is counted before the observer restarts (tick()).
constexpr double kHistoryBreakGap_s = 0.01;

// Read device → encoder → angles → FK → velocity. Returns the device fault bits of this
// tick (0: p_device_m / v_device_m_per_s hold a good sample).
std::uint32_t read_device(const RtModel& model, RtData& data, falcon::HapticDevice& device, TimeNs now_ns) noexcept {
  const RtConfig& config = model.config;
  data.io_status = device.try_exchange(data.pending_command, data.reading);
  if (data.io_status == falcon::IoStatus::kDisconnected) return kFaultDeviceDisconnected;
  if (data.io_status != falcon::IoStatus::kOk) {
    ++data.faults.io_errors;
    return kFaultDeviceIo;
  }
  const double elapsed_s =
      data.joints.have_reference ? to_seconds(now_ns - data.last_judged_sample_ns) : model.period_s;
  data.last_judged_sample_ns = now_ns;
  switch (encoders_to_joint_angles(config.kinematics.encoder, config.faults, data.joints, data.reading.encoder_counts,
                                   std::max(elapsed_s, model.period_s))) {
    case JointCheck::kJump:
      ++data.faults.encoder_jumps;
      return kFaultEncoderJump;
    case JointCheck::kNonFinite:
      ++data.faults.non_finite;
      return kFaultNonFinite;
    case JointCheck::kOk:
      break;
  }
  if (!solve_position(config.kinematics.geometry, config.kinematics.fk, data.kinematics, data.joints.theta_rad)) {
    ++data.faults.non_finite;
    return kFaultNonFinite;
  }
  const Eigen::Vector3d v =
      update_velocity(model.velocity_filter, data.velocity, data.kinematics.p_device_m, model.period_s);
  if (!v.allFinite()) {
    ++data.faults.non_finite;
    return kFaultNonFinite;
  }
  data.p_device_m = data.kinematics.p_device_m;
  data.v_device_m_per_s = v;
  return 0;
}

// Device faults latch and clear after recovery_ticks clean ticks (disconnect never clears).
void update_device_faults(const RtModel& model, RtData& data, std::uint32_t new_faults) noexcept {
  FaultState& faults = data.faults;
  if (new_faults != 0) {
    faults.latched_device_faults |= new_faults;
    faults.clean_ticks = 0;
    // History is no longer trustworthy: restart the velocity filter and the observer's Δp
    // chain from the next good sample.
    data.velocity.primed = false;
    data.force_position.primed = false;
    restart_observer(data.passivity);
    return;
  }
  if (faults.latched_device_faults == 0) return;
  if (++faults.clean_ticks >= model.config.faults.recovery_ticks) {
    faults.latched_device_faults &= kFaultDeviceDisconnected;
  }
}

// The position epoch (messages.hpp). A rejected sample leaves the published position where the
// last accepted one put it; the next accepted sample may be anywhere — a jumped encoder reading
// now accepted as lost counts, the hand's unobserved motion during an I/O fault, a cold FK
// restart — so it opens a new epoch, and the host re-seats its tool there instead of sweeping
// it through the soft body. The first accepted sample opens epoch 1. A non-finite force found
// after the sample was accepted (tick(), step 4) does not: that sample was published, and the
// next one is judged against it by the jump check, so the published position stays continuous.
void update_position_epoch(RtData& data, std::uint32_t sample_faults) noexcept {
  if (sample_faults != 0) {
    data.position_continuous = false;
    return;
  }
  if (!data.position_continuous) {
    data.position_epoch = next_position_epoch(data.position_epoch);
    data.position_continuous = true;
  }
}

std::uint32_t to_device_status(const RtData& data, std::uint32_t fault_bits) noexcept {
  std::uint32_t status = 0;
  if ((data.reading.homed_mask & 0x7u) == 0x7u) status |= kDeviceHomed;
  if (data.device_is_simulated) status |= kDeviceSimulated;
  if (data.io_status == falcon::IoStatus::kTimeout || data.io_status == falcon::IoStatus::kNotRunning) {
    status |= kDeviceFaultTimeout;
  }
  if (data.io_status == falcon::IoStatus::kTornPacket) status |= kDeviceFaultTornPacket;
  if ((fault_bits & kFaultDeviceDisconnected) != 0u) status |= kDeviceFaultDisconnected;
  if ((fault_bits & kFaultEncoderJump) != 0u) status |= kDeviceFaultEncoderJump;
  if ((fault_bits & kFaultNonFinite) != 0u) status |= kDeviceFaultNonFinite;
  return status;
}

}  // namespace

TickResult tick(const RtModel& model, RtData& data, TickIo& io, const TickTiming& timing) noexcept {
  const RtConfig& config = model.config;
  const TimeNs now_ns = timing.now_ns;
  std::uint32_t flags = 0;

  // 1. read device … velocity (after a stall the history restarts: kHistoryBreakGap_s)
  const bool history_break =
      data.joints.have_reference && to_seconds(now_ns - data.last_judged_sample_ns) > kHistoryBreakGap_s;
  if (history_break) {
    data.velocity.primed = false;
    data.force_position.primed = false;
  }
  const std::uint32_t sample_faults = read_device(model, data, io.device, now_ns);
  data.have_position = sample_faults == 0;
  update_position_epoch(data, sample_faults);
  if (history_break && data.have_position) {
    // The device held the command that was acting when the loop stalled while the hand moved:
    // that work is exact (a zero-order hold held longer) and counts in E before the chain restarts.
    // The debt the stall leaves goes into the stall account (passivity.hpp): collected on the way
    // out of the rest the hand takes, not withheld at it.
    observe_energy(data.passivity, data.p_device_m);
    restart_observer(data.passivity);
    open_stall_account(data.passivity);
  }
  if (data.have_position) observe_energy(data.passivity, data.p_device_m);
  update_device_faults(model, data, sample_faults);

  // 2. latest proxy: wait-free fetch + validate (runs during device faults too, so the
  //    proxy age and the reject counters stay right)
  const ProxyIntake intake = take_latest_proxy(io.proxy_in, data.proxy, now_ns);
  const TimeNs proxy_age = proxy_age_ns(data.proxy, now_ns);
  const bool usable = proxy_usable(config.proxy, data.proxy.have_proxy, data.proxy.invalid_latched, proxy_age);
  if (data.proxy.invalid_latched) flags |= kFaultProxyInvalid;
  if (data.proxy.have_proxy && to_seconds(proxy_age) > config.proxy.stale_after_s) flags |= kFaultProxyStale;

  // 3. Hunt-Crossley at the current position → blend on swap → staleness fade → passivity
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  const double fade_gain = update_fade(config.proxy, data.fade, usable, model.period_s);
  if (data.have_position) {
    // The contact is evaluated at the sub-count position (force_position.hpp); the observer, the
    // soft wall and the published state keep the reading.
    data.tool = device_to_tool(config.mapping, force_position(data.force_position, data.p_device_m),
                               data.v_device_m_per_s);
    Eigen::Vector3d new_force = Eigen::Vector3d::Zero();
    data.max_penetration_m = -1.0;
    data.patches_in_contact = 0;
    double stored_energy_j = 0.0;
    data.friction_force_device_n.setZero();
    data.parts_sliding = 0;
    if (data.proxy.have_proxy) {
      const ContactEvaluation evaluation = evaluate_proxy(active_proxy(data.proxy), config.mapping, data.tool,
                                                          data.part_forces, model.damping_cap, &data.normal_load);
      data.max_penetration_m = evaluation.max_penetration_m;
      data.patches_in_contact = evaluation.patches_in_contact;
      const FrictionEvaluation friction =
          evaluate_friction(model.friction, data.friction, active_proxy(data.proxy), data.normal_load, config.mapping, data.tool);
      data.friction_force_device_n = part_forces_to_device(config.mapping, friction.force_world_n);
      data.parts_sliding = friction.parts_sliding;
      new_force = part_forces_to_device(config.mapping, data.part_forces) + data.friction_force_device_n;
      // The staleness fade and safety's ramp scale the rendered springs (normal and stick), and
      // with them what they store.
      stored_energy_j = fade_gain * data.safety.ramp_gain * model.device_energy_per_world_energy *
                        (evaluation.stored_energy_world_j + friction.stored_energy_world_j);
    } else {
      data.friction = FrictionState{};
    }
    if (history_break) {
      // A proxy accepted in this tick is the one in use: the force it gives here is what the
      // blend walks to; the one it replaces is as stale as the rest (proxy_blend.hpp).
      continue_after_break(data.blend, new_force);
    } else if (intake == ProxyIntake::kAccepted) {
      Eigen::Vector3d old_force = data.friction_force_device_n;  // the first proxy blends its normal force in from zero
      if (data.proxy.have_previous) {
        // Friction is continuous by its own construction (friction_cone.hpp: the anchor walks
        // towards the host's state at a bounded rate), so the swap blends the normal forces only.
        evaluate_proxy(previous_proxy(data.proxy), config.mapping, data.tool, data.part_forces, model.damping_cap);
        old_force = part_forces_to_device(config.mapping, data.part_forces) + data.friction_force_device_n;
      }
      begin_swap(data.blend, old_force, new_force);
    }
    // While a device fault is latched the command is zero and safety brings the force back by
    // its fault ramp-in, which already keeps the return continuous. A swap offset carried
    // across the fault would not: the old proxy was built for where the tool was before the
    // fault, and evaluated where the hand is now (it kept moving while unforced, or the
    // encoders jumped) it can give tens of newtons no contact produces — which the blend then
    // renders for up to (offset / blend_max_step_n) ticks after recovery (encoder_jumps stress
    // case: 25 N walked down over 0.5 s, up to 0.08 J into the hand per fault).
    if (data.faults.latched_device_faults != 0) cancel_swaps(data.blend);
    data.contact_force_device_n = fade_gain * blend(data.blend, new_force, config.proxy.blend_max_step_n);
    // The rendered environment = contact + workspace soft wall; the passivity controller
    // guards both (safety.hpp: a soft wall ramped in around a hand deep in it returns energy).
    const Eigen::Vector3d environment_device_n =
        data.contact_force_device_n + workspace_soft_wall_n(config.safety, data.p_device_m, flags);
    force = passivity_control(config.passivity, data.passivity, environment_device_n, data.v_device_m_per_s,
                              data.velocity.x1, model.period_s, stored_energy_j);
    if ((data.passivity.damping_n_s_per_m) > 0.0) flags |= kFlagPassivityActive;
  } else {
    data.contact_force_device_n.setZero();
  }

  // 4. safety (the last line), then Jᵀ → motor command for the next exchange
  SafetyInput safety_input;
  safety_input.force_device_n = force;
  safety_input.p_device_m = data.p_device_m;
  safety_input.device_fault = data.faults.latched_device_faults != 0;
  safety_input.stop_requested = timing.stop_requested;
  data.force_device_n = apply_safety(config.safety, data.safety, safety_input, model.period_s, flags);
  if (!force_to_command(config.kinematics.geometry, config.kinematics.newton_metre_per_count, data.p_device_m,
                        data.force_device_n, data.pending_command, flags)) {
    data.force_device_n.setZero();
  }
  if ((flags & kFaultNonFinite) != 0u && (sample_faults & kFaultNonFinite) == 0u) {
    // Non-finite force or a Jacobian failure found late: same treatment as a bad sample.
    ++data.faults.non_finite;
    update_device_faults(model, data, kFaultNonFinite);
  }
  record_sent_force(data.passivity, data.force_device_n);
  flags |= data.faults.latched_device_faults | sample_faults;
  if ((flags & kDeviceSideFaults) != 0u) ++data.faults.fault_ticks;

  // 5. DeviceState to the host, telemetry to the logger
  DeviceState state;
  state.sequence = ++data.device_state_sequence;
  // When the encoders were read: the device's receive time if it reports one, else the tick's.
  state.sample_time_ns =
      data.have_position && data.reading.receive_time_ns != 0 ? data.reading.receive_time_ns : now_ns;
  // The last good sample, never the FK stage's own state: after a failed solve that holds the
  // non-converged iterate (a cold start from the workspace centre), and the host would move its
  // tool there — through the soft body — for as long as the fault lasts.
  state.position_device_m = to_vec3(data.p_device_m);
  state.velocity_device_m_per_s = to_vec3(data.v_device_m_per_s);
  state.closing_axis_m = jaw_closing_m(config.mapping, data.p_device_m);
  state.buttons = data.reading.buttons;
  state.status_flags = with_position_epoch(to_device_status(data, flags), data.position_epoch);
  io.state_out.publish(state);

  TelemetrySample sample;
  sample.tick = data.tick_index;
  sample.time_ns = now_ns;
  sample.wakeup_latency_ns = timing.wakeup_latency_ns;
  sample.overruns = timing.overruns;
  sample.position_device_m = state.position_device_m;
  sample.velocity_device_m_per_s = state.velocity_device_m_per_s;
  sample.tool_position_world_m = to_vec3(data.tool.p_tool_world_m);
  sample.contact_force_device_n = to_vec3(data.contact_force_device_n);
  sample.friction_force_device_n = to_vec3(fade_gain * data.friction_force_device_n);
  sample.parts_sliding = static_cast<std::uint8_t>(data.parts_sliding);
  sample.force_device_n = to_vec3(data.force_device_n);
  sample.motor_counts = data.pending_command.motor_counts;
  sample.patches_in_contact = static_cast<std::uint16_t>(data.patches_in_contact);
  sample.jaw_closing_m = state.closing_axis_m;
  sample.max_penetration_m = data.max_penetration_m;
  sample.energy_j = data.passivity.energy_j;
  sample.passivity_damping_n_s_per_m = data.passivity.damping_n_s_per_m;
  sample.fade_gain = fade_gain;
  sample.ramp_gain = data.safety.ramp_gain;
  sample.proxy_age_ns = proxy_age;
  sample.proxy_sequence = data.proxy.have_proxy ? active_proxy(data.proxy).sequence : 0;
  sample.proxies_rejected = data.proxy.rejected_count;
  sample.fault_bits = flags;
  sample.buttons = data.reading.buttons;
  sample.io_status = static_cast<std::uint8_t>(data.io_status);
  sample.fk_iterations = static_cast<std::int8_t>(std::min(data.kinematics.last.iterations, 127));
  if (!io.telemetry.try_push(sample)) ++data.telemetry_dropped;

  ++data.tick_index;
  TickResult result;
  result.fault_bits = flags;
  result.force_device_n = data.force_device_n;
  result.stopped = data.safety.phase == RampPhase::kStopped;
  return result;
}

}  // namespace fissure::rt
