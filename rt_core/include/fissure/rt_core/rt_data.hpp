#pragma once
// The loop's mutable data (MuJoCo's mjData): every byte the tick touches, preallocated,
// one sub-struct per pipeline stage. Trivially destructible, no pointers to the heap.
#include <cstdint>

#include <Eigen/Core>

#include "fissure/falcon_hw/haptic_device.hpp"
#include "fissure/shared/device_mapping.hpp"
#include "fissure/rt_core/force_position.hpp"
#include "fissure/rt_core/friction_cone.hpp"
#include "fissure/rt_core/forward_kinematics_stage.hpp"
#include "fissure/rt_core/joint_angles.hpp"
#include "fissure/rt_core/passivity.hpp"
#include "fissure/rt_core/proxy_blend.hpp"
#include "fissure/rt_core/proxy_intake.hpp"
#include "fissure/rt_core/rt_config.hpp"
#include "fissure/rt_core/safety.hpp"
#include "fissure/rt_core/staleness.hpp"
#include "fissure/rt_core/velocity_filter.hpp"
#include "fissure/shared/messages.hpp"

namespace fissure::rt {

/// Fault bookkeeping (faults.hpp says how each bit recovers).
struct FaultState {
  std::uint32_t latched_device_faults = 0;  ///< device-side bits holding the command at zero
  int clean_ticks = 0;                      ///< consecutive fault-free ticks since the last device fault
  std::uint64_t io_errors = 0;              ///< exchanges that returned timeout/torn/not running
  std::uint64_t encoder_jumps = 0;
  std::uint64_t non_finite = 0;             ///< ticks with NaN/inf or FK/Jacobian failure
  std::uint64_t fault_ticks = 0;            ///< ticks that commanded zero because of a device fault
};

struct RtData {
  std::uint64_t tick_index = 0;
  bool device_is_simulated = false;

  // read device
  falcon::DeviceCommand pending_command{};  ///< computed last tick; goes out with this tick's exchange
  falcon::DeviceReading reading{};
  falcon::IoStatus io_status = falcon::IoStatus::kOk;
  TimeNs last_judged_sample_ns = 0;         ///< time of the last reading the jump check saw
  // encoder → angles → FK → velocity
  JointState joints{};
  KinematicsState kinematics{};
  VelocityFilterState velocity{};
  Eigen::Vector3d p_device_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_device_m_per_s = Eigen::Vector3d::Zero();
  bool have_position = false;               ///< p_device_m came from a good sample this tick
  // Position epoch (messages.hpp, DeviceState::status_flags bits 24..31): advanced at the first
  // accepted sample after one or more rejected ones, and at the very first accepted sample.
  std::uint8_t position_epoch = 0;          ///< epoch of the position published (0: no sample accepted yet)
  bool position_continuous = false;         ///< the next accepted sample continues the published position
  // mapping, proxy, HC, blend, fade
  ForcePositionState force_position{};      ///< the contact's sub-count position (force_position.hpp)
  ToolState tool{};
  ProxyState proxy{};
  PartForces part_forces{};
  PartNormalLoad normal_load{};             ///< the friction cone's input from the proxy in use
  FrictionState friction{};                 ///< stick anchors per tool part (friction_cone.hpp)
  Eigen::Vector3d friction_force_device_n = Eigen::Vector3d::Zero();  ///< friction share of new_force
  int parts_sliding = 0;
  BlendState blend{};
  FadeState fade{};
  double max_penetration_m = -1.0;
  int patches_in_contact = 0;
  Eigen::Vector3d contact_force_device_n = Eigen::Vector3d::Zero();
  // passivity, safety
  PassivityState passivity{};
  SafetyState safety{};
  Eigen::Vector3d force_device_n = Eigen::Vector3d::Zero();  ///< commanded (after safety)
  // faults and outputs
  FaultState faults{};
  std::uint64_t device_state_sequence = 0;
  std::uint64_t telemetry_dropped = 0;
};

/// A fresh data block for `model`: ramp-in armed, FK cold. (Call before the first tick.)
void reset_data(const RtModel& model, RtData& data) noexcept;

}  // namespace fissure::rt
