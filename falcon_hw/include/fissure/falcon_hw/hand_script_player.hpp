#pragma once
// The scripted operator's hand on SimFalcon's grip. A HandScript (shared/
// session_config.hpp, filled in from the scene/session file) is a list of straight-line legs
// "go to this point at this speed, then hold for this long", plus a button script. The player
// turns it into a function of session time:
//   target(t)  — where the hand is trying to put the grip, and how fast that point moves;
//   force(t, p, v) = k·(x_target − p) + c·(v_target − v)   — the grip spring-damper;
//   buttons(t) — which grip buttons the hand holds down.
// It is stateless after construction (every query is a pure function of t), so SimFalcon is
// deterministic however often or irregularly it asks. Construction validates and precomputes
// (allocates, may throw); every query is noexcept and allocation-free.
#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "fissure/shared/session_config.hpp"

namespace fissure::falcon {

/// Where the hand wants the grip at one instant.
struct HandTarget {
  Eigen::Vector3d position_device_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_device_m_per_s = Eigen::Vector3d::Zero();
  bool holding_grip = true;  ///< false once the hand has let go (release_at_end, after the script)
};

class HandScriptPlayer {
 public:
  /// Validates the script (finite positions, speed > 0, hold ≥ 0, non-negative finite
  /// stiffness/damping, finite button times) and throws std::invalid_argument naming the
  /// offending field, e.g. "hand script: waypoints[2].speed_m_per_s must be > 0 (got 0)".
  /// Button events are sorted by time (stable, so equal times keep file order).
  explicit HandScriptPlayer(const HandScript& script);

  /// Target at session time t (seconds since the session started). Before t = 0 the target
  /// is the start position; after the last hold it stays at the last waypoint (and is
  /// released if the script says so).
  [[nodiscard]] HandTarget target_at(double session_time_s) const noexcept;

  /// Force the hand applies to the grip, device frame [N]; zero once released.
  [[nodiscard]] Eigen::Vector3d force_on_grip_device_n(double session_time_s, const Eigen::Vector3d& p_device_m,
                                                       const Eigen::Vector3d& v_device_m_per_s) const noexcept;

  /// Button bits pressed at session time t: the last event with time_s ≤ t, 0 before any.
  [[nodiscard]] std::uint32_t buttons_at(double session_time_s) const noexcept;

  /// Session time at which the last hold ends (0 for a script without waypoints).
  [[nodiscard]] double script_end_s() const noexcept { return legs_.empty() ? 0.0 : legs_.back().leave_s; }
  [[nodiscard]] std::size_t leg_count() const noexcept { return legs_.size(); }
  /// When leg i's target reaches its waypoint, and when its hold ends (for tests and logs).
  [[nodiscard]] double leg_arrival_s(std::size_t leg) const noexcept { return legs_[leg].arrive_s; }
  [[nodiscard]] double leg_departure_s(std::size_t leg) const noexcept { return legs_[leg].leave_s; }
  [[nodiscard]] const HandScript& script() const noexcept { return script_; }

 private:
  struct Leg {
    Eigen::Vector3d from_device_m;
    Eigen::Vector3d to_device_m;
    Eigen::Vector3d velocity_device_m_per_s;  ///< constant along the leg
    double start_s;                           ///< target leaves from_device_m
    double arrive_s;                          ///< target reaches to_device_m
    double leave_s;                           ///< hold ends; the next leg starts
  };

  HandScript script_;  // button_events sorted by time
  std::vector<Leg> legs_;
};

}  // namespace fissure::falcon
