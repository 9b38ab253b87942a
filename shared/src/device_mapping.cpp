#include "fissure/shared/device_mapping.hpp"

#include <cmath>

namespace fissure {

bool is_valid(const DeviceMapping& m) noexcept {
  bool seen[3] = {false, false, false};
  for (int i = 0; i < 3; ++i) {
    if (m.axis_permutation[i] > 2 || seen[m.axis_permutation[i]]) return false;
    seen[m.axis_permutation[i]] = true;
    if (m.axis_sign[i] != 1 && m.axis_sign[i] != -1) return false;
    if (!std::isfinite(m.device_origin_m[i]) || !std::isfinite(m.world_offset_m[i])) return false;
  }
  return std::isfinite(m.scale) && m.scale > 0.0 && std::isfinite(m.force_scale) && m.force_scale >= 0.0 &&
         m.closing_axis_world <= 2;
}

double jaw_closing_m(const DeviceMapping& m, const Eigen::Vector3d& p_device_m) noexcept {
  if (!m.clamp_mode) return 0.0;
  const int c = m.closing_axis_world;
  const int d = m.axis_permutation[c];
  return m.axis_sign[c] * (p_device_m[d] - m.device_origin_m[d]);
}

ToolState device_to_tool(const DeviceMapping& m, const Eigen::Vector3d& p_device_m,
                         const Eigen::Vector3d& v_device_m_per_s) noexcept {
  ToolState tool;
  for (int i = 0; i < 3; ++i) {
    const int d = m.axis_permutation[i];
    const double sign = m.axis_sign[i];
    tool.p_tool_world_m[i] = m.world_offset_m[i] + m.scale * sign * (p_device_m[d] - m.device_origin_m[d]);
    tool.v_tool_world_m_per_s[i] = m.scale * sign * v_device_m_per_s[d];
  }
  if (m.clamp_mode) {
    // The closing axis drives the jaws, not the tool: pin the tool on its world offset.
    const int c = m.closing_axis_world;
    const int d = m.axis_permutation[c];
    tool.jaw_closing_m = m.axis_sign[c] * (p_device_m[d] - m.device_origin_m[d]);
    tool.jaw_closing_rate_m_per_s = m.axis_sign[c] * v_device_m_per_s[d];
    tool.p_tool_world_m[c] = m.world_offset_m[c];
    tool.v_tool_world_m_per_s[c] = 0.0;
  }
  return tool;
}

PartMotion part_motion(const DeviceMapping& m, const ToolState& tool, ToolPart part) noexcept {
  PartMotion motion{tool.p_tool_world_m, tool.v_tool_world_m_per_s};
  if (!m.clamp_mode || part == ToolPart::kTool) return motion;
  const double side = part == ToolPart::kJawA ? 1.0 : -1.0;
  const int c = m.closing_axis_world;
  motion.p_world_m[c] += side * 0.5 * m.scale * tool.jaw_closing_m;
  motion.v_world_m_per_s[c] += side * 0.5 * m.scale * tool.jaw_closing_rate_m_per_s;
  return motion;
}

Eigen::Vector3d part_forces_to_device(const DeviceMapping& m, const PartForces& forces) noexcept {
  const Eigen::Vector3d& f_tool = forces.force_world_n[static_cast<std::size_t>(ToolPart::kTool)];
  const Eigen::Vector3d& f_jaw_a = forces.force_world_n[static_cast<std::size_t>(ToolPart::kJawA)];
  const Eigen::Vector3d& f_jaw_b = forces.force_world_n[static_cast<std::size_t>(ToolPart::kJawB)];
  Eigen::Vector3d total_world = f_tool + f_jaw_a + f_jaw_b;
  if (m.clamp_mode) {
    // The tool cannot move along e_c, so the net force along it is carried by the clamp's
    // mount, not the hand; what the hand feels on that axis is the grip (virtual work).
    const int c = m.closing_axis_world;
    total_world[c] = 0.5 * (f_jaw_a[c] - f_jaw_b[c]);
  }
  Eigen::Vector3d f_device = Eigen::Vector3d::Zero();
  for (int i = 0; i < 3; ++i) {
    f_device[m.axis_permutation[i]] = m.force_scale * m.axis_sign[i] * total_world[i];
  }
  return f_device;
}

}  // namespace fissure
