// The scripted tool trajectory of a scene: straight legs at constant speed, then holds.
#include <algorithm>
#include <cmath>

#include "fissure/host_sim/scene_description.hpp"

namespace fissure::host {

namespace {

double leg_duration_s(const Vec3& from, const Vec3& to, double speed_m_per_s) noexcept {
  const double dx = to[0] - from[0], dy = to[1] - from[1], dz = to[2] - from[2];
  return std::sqrt(dx * dx + dy * dy + dz * dz) / speed_m_per_s;
}

double start_gap_m(const SceneDescription& scene) noexcept {
  return scene.trajectory.start_jaw_gap_m >= 0.0 ? scene.trajectory.start_jaw_gap_m : scene.tool.clamp.jaw_gap_open_m;
}

}  // namespace

double trajectory_duration_s(const SceneDescription& scene) noexcept {
  double total_s = 0.0;
  Vec3 from = scene.trajectory.start.position_world_m;
  double gap = start_gap_m(scene);
  for (const TrajectoryWaypoint& wp : scene.trajectory.waypoints) {
    const double gap_to = wp.jaw_gap_m >= 0.0 ? wp.jaw_gap_m : gap;
    total_s += std::max(leg_duration_s(from, wp.position_world_m, wp.speed_m_per_s), std::abs(gap_to - gap) / wp.speed_m_per_s) + wp.hold_s;
    from = wp.position_world_m;
    gap = gap_to;
  }
  return total_s;
}

TrajectorySample sample_trajectory(const SceneDescription& scene, double t_s) noexcept {
  TrajectorySample out;
  out.pose = scene.trajectory.start;
  out.jaw_gap_m = start_gap_m(scene);
  double leg_start_s = 0.0;
  for (const TrajectoryWaypoint& wp : scene.trajectory.waypoints) {
    const Vec3 from = out.pose.position_world_m;
    const double gap_from = out.jaw_gap_m;
    const double gap_to = wp.jaw_gap_m >= 0.0 ? wp.jaw_gap_m : gap_from;
    // A leg moves the tool and the jaws together, neither faster than the leg's speed.
    const double move_s = std::max(leg_duration_s(from, wp.position_world_m, wp.speed_m_per_s), std::abs(gap_to - gap_from) / wp.speed_m_per_s);
    if (t_s < leg_start_s + move_s) {
      const double a = move_s > 0.0 ? std::clamp((t_s - leg_start_s) / move_s, 0.0, 1.0) : 1.0;
      for (int i = 0; i < 3; ++i) out.pose.position_world_m[i] = from[i] + a * (wp.position_world_m[i] - from[i]);
      out.jaw_gap_m = gap_from + a * (gap_to - gap_from);
      return out;
    }
    out.pose.position_world_m = wp.position_world_m;
    out.jaw_gap_m = gap_to;
    leg_start_s += move_s + wp.hold_s;
    if (t_s < leg_start_s) return out;
  }
  return out;
}

}  // namespace fissure::host
