#pragma once
// The loop's const model (MuJoCo's mjModel, libfranka's limits): RtConfig is what a session
// sets, RtModel is RtConfig plus everything derived from it once (period, filter
// coefficients). Every limit is a constexpr with its unit in the name and its source in the
// comment, in the stage header that uses it (safety.hpp, joint_angles.hpp, ...).
#include "fissure/falcon_hw/encoder_mapping.hpp"
#include "fissure/falcon_hw/falcon_geometry.hpp"
#include "fissure/falcon_hw/kinematics.hpp"
#include "fissure/falcon_hw/motor_command.hpp"
#include "fissure/rt_core/friction_cone.hpp"
#include "fissure/rt_core/hunt_crossley.hpp"
#include "fissure/rt_core/joint_angles.hpp"
#include "fissure/rt_core/passivity.hpp"
#include "fissure/rt_core/safety.hpp"
#include "fissure/rt_core/staleness.hpp"
#include "fissure/rt_core/velocity_filter.hpp"
#include "fissure/shared/session_config.hpp"
#include "fissure/shared/time.hpp"

namespace fissure::rt {

/// Slowest supported rate [Hz]: below ~500 Hz a 3000 N/m wall cannot be passive on the
/// Falcon's few N·s/m of damping (Colgate–Schenkel b > K·T/2: 3 N·s/m ⇒ K < 3000 N/m at 500 Hz).
inline constexpr double kMinRate_hz = 500.0;
/// Fastest supported rate [Hz]: the USB Falcon's ping-pong tops out near 1 kHz; 10 kHz is for
/// SimFalcon/HIL and future devices, and leaves 100 µs per tick for a ~1 µs tick.
inline constexpr double kMaxRate_hz = 10'000.0;
/// Default rate [Hz]: the USB Falcon's native ping-pong rate (BRIEF §6).
inline constexpr double kDefaultRate_hz = 1000.0;

struct KinematicsConfig {
  falcon::FalconGeometry geometry{};
  falcon::EncoderMapping encoder{};
  falcon::FkOptions fk{};
  /// Motor calibration [N·m per command count]; falcon_hw's default is libnifalcon's
  /// uncalibrated 1e-4 (motor_command.hpp) — SimFalcon uses the same by default.
  double newton_metre_per_count = falcon::kDefaultNewtonMetrePerCount;
};

struct RtConfig {
  double rate_hz = kDefaultRate_hz;
  DeviceMapping mapping{};
  KinematicsConfig kinematics{};
  VelocityFilterConfig velocity{};
  ProxyConfig proxy{};
  FrictionConfig friction{};
  PassivityConfig passivity{};
  SafetyConfig safety{};
  FaultConfig faults{};
};

struct RtModel {
  RtConfig config{};
  TimeNs period_ns = 0;
  double period_s = 0.0;
  VelocityFilterCoefficients velocity_filter{};
  double velocity_lag_s = 0.0;  ///< documented lag of the velocity estimate at this rate
  DampingCap damping_cap{};     ///< the device's damping in world units, and T (hunt_crossley.hpp)
  /// Device-port joules per world joule of stored contact energy: F_device·Δp_device =
  /// (force_scale / scale)·F_world·Δp_world (device_mapping.hpp).
  double device_energy_per_world_energy = 1.0;
  /// The friction stage in world units (friction_cone.hpp): K_t = K_device / (force_scale·scale).
  FrictionModel friction{};
};

/// First problem in `config` as a static string naming the field ("rate_hz must be in
/// [500, 10000] Hz"), or nullptr when it is usable. Not for the tick (called once).
const char* check_config(const RtConfig& config) noexcept;

/// Builds the model. False (and `*error` set from check_config) when the config is unusable.
bool build_model(const RtConfig& config, RtModel& model, const char** error = nullptr) noexcept;

}  // namespace fissure::rt
