#include "fissure/falcon_hw/hand_script_player.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace fissure::falcon {
namespace {

[[noreturn]] void reject(const std::string& field, const std::string& requirement, double value) {
  throw std::invalid_argument("hand script: " + field + " must be " + requirement + " (got " + std::to_string(value) +
                              ")");
}

void require_finite_point(const Vec3& point, const std::string& field) {
  for (std::size_t axis = 0; axis < 3; ++axis) {
    if (!std::isfinite(point[axis])) reject(field + "[" + std::to_string(axis) + "]", "finite", point[axis]);
  }
}

void require_non_negative(double value, const std::string& field) {
  if (!std::isfinite(value) || value < 0.0) reject(field, "finite and >= 0", value);
}

}  // namespace

HandScriptPlayer::HandScriptPlayer(const HandScript& script) : script_(script) {
  require_finite_point(script_.start_position_device_m, "start_position_device_m");
  require_non_negative(script_.grip_stiffness_n_per_m, "grip_stiffness_n_per_m");
  require_non_negative(script_.grip_damping_n_s_per_m, "grip_damping_n_s_per_m");

  legs_.reserve(script_.waypoints.size());
  Eigen::Vector3d from = as_eigen(script_.start_position_device_m);
  double t_s = 0.0;
  for (std::size_t i = 0; i < script_.waypoints.size(); ++i) {
    const HandWaypoint& waypoint = script_.waypoints[i];
    const std::string field = "waypoints[" + std::to_string(i) + "]";
    require_finite_point(waypoint.position_device_m, field + ".position_device_m");
    if (!std::isfinite(waypoint.speed_m_per_s) || waypoint.speed_m_per_s <= 0.0) {
      reject(field + ".speed_m_per_s", "finite and > 0", waypoint.speed_m_per_s);
    }
    require_non_negative(waypoint.hold_s, field + ".hold_s");

    Leg leg{};
    leg.from_device_m = from;
    leg.to_device_m = as_eigen(waypoint.position_device_m);
    const Eigen::Vector3d displacement = leg.to_device_m - leg.from_device_m;
    const double distance_m = displacement.norm();
    const double travel_s = distance_m / waypoint.speed_m_per_s;
    leg.velocity_device_m_per_s =
        distance_m > 0.0 ? Eigen::Vector3d(displacement / travel_s) : Eigen::Vector3d::Zero();
    leg.start_s = t_s;
    leg.arrive_s = t_s + travel_s;
    leg.leave_s = leg.arrive_s + waypoint.hold_s;
    legs_.push_back(leg);

    t_s = leg.leave_s;
    from = leg.to_device_m;
  }

  for (std::size_t i = 0; i < script_.button_events.size(); ++i) {
    require_non_negative(script_.button_events[i].time_s, "button_events[" + std::to_string(i) + "].time_s");
  }
  std::stable_sort(script_.button_events.begin(), script_.button_events.end(),
                   [](const ButtonEvent& a, const ButtonEvent& b) { return a.time_s < b.time_s; });
}

HandTarget HandScriptPlayer::target_at(double session_time_s) const noexcept {
  HandTarget target;
  if (legs_.empty()) {
    target.position_device_m = as_eigen(script_.start_position_device_m);
    target.holding_grip = !script_.release_at_end;
    return target;
  }
  if (!(session_time_s > 0.0)) {  // also catches NaN: hold the start
    target.position_device_m = legs_.front().from_device_m;
    return target;
  }
  // First leg whose hold has not ended yet; legs are in time order, so binary search keeps
  // the lookup O(log n) and independent of how the caller steps time.
  const auto leg = std::upper_bound(legs_.begin(), legs_.end(), session_time_s,
                                    [](double t_s, const Leg& candidate) { return t_s < candidate.leave_s; });
  if (leg == legs_.end()) {
    target.position_device_m = legs_.back().to_device_m;
    target.holding_grip = !script_.release_at_end;
    return target;
  }
  if (session_time_s < leg->arrive_s) {
    target.position_device_m = leg->from_device_m + leg->velocity_device_m_per_s * (session_time_s - leg->start_s);
    target.velocity_device_m_per_s = leg->velocity_device_m_per_s;
  } else {
    target.position_device_m = leg->to_device_m;
  }
  return target;
}

Eigen::Vector3d HandScriptPlayer::force_on_grip_device_n(double session_time_s, const Eigen::Vector3d& p_device_m,
                                                         const Eigen::Vector3d& v_device_m_per_s) const noexcept {
  const HandTarget target = target_at(session_time_s);
  if (!target.holding_grip) return Eigen::Vector3d::Zero();
  return script_.grip_stiffness_n_per_m * (target.position_device_m - p_device_m) +
         script_.grip_damping_n_s_per_m * (target.velocity_device_m_per_s - v_device_m_per_s);
}

std::uint32_t HandScriptPlayer::buttons_at(double session_time_s) const noexcept {
  const auto& events = script_.button_events;
  const auto after = std::upper_bound(events.begin(), events.end(), session_time_s,
                                      [](double t_s, const ButtonEvent& event) { return t_s < event.time_s; });
  return after == events.begin() ? 0u : std::prev(after)->buttons;
}

}  // namespace fissure::falcon
