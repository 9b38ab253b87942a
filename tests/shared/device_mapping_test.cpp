#include "fissure/shared/device_mapping.hpp"

#include <gtest/gtest.h>

namespace fissure {
namespace {

DeviceMapping permuted_mapping() {
  DeviceMapping m;
  m.scale = 2.0;
  m.force_scale = 0.5;
  m.axis_permutation = {2, 0, 1};  // world x ← device z, world y ← device x, world z ← device y
  m.axis_sign = {-1, 1, 1};
  m.device_origin_m = {0.0, 0.0, 0.125};
  m.world_offset_m = {1.0, 2.0, 3.0};
  return m;
}

TEST(DeviceMapping, PositionFollowsScalePermutationSignAndOffsets) {
  const DeviceMapping m = permuted_mapping();
  ASSERT_TRUE(is_valid(m));
  const ToolState tool = device_to_tool(m, Eigen::Vector3d(0.01, 0.02, 0.135), Eigen::Vector3d(0.1, 0.2, 0.3));
  EXPECT_NEAR(tool.p_tool_world_m.x(), 1.0 - 2.0 * 0.01, 1e-15);  // −(z − 0.125)·2
  EXPECT_NEAR(tool.p_tool_world_m.y(), 2.0 + 2.0 * 0.01, 1e-15);
  EXPECT_NEAR(tool.p_tool_world_m.z(), 3.0 + 2.0 * 0.02, 1e-15);
  EXPECT_NEAR(tool.v_tool_world_m_per_s.x(), -0.6, 1e-15);
  EXPECT_NEAR(tool.v_tool_world_m_per_s.y(), 0.2, 1e-15);
  EXPECT_NEAR(tool.v_tool_world_m_per_s.z(), 0.4, 1e-15);
}

TEST(DeviceMapping, ForceGoesBackThroughTheTransposeTimesForceScale) {
  const DeviceMapping m = permuted_mapping();
  PartForces forces;
  forces.force_world_n[0] = Eigen::Vector3d(1.0, 2.0, 3.0);
  const Eigen::Vector3d f_device = part_forces_to_device(m, forces);
  // Virtual work with force_scale = scale: F_device·δp_device = F_world·δp_world · (force_scale/scale).
  const Eigen::Vector3d dp_device(1e-3, -2e-3, 0.5e-3);
  const ToolState a = device_to_tool(m, Eigen::Vector3d(0.0, 0.0, 0.125), Eigen::Vector3d::Zero());
  const ToolState b = device_to_tool(m, Eigen::Vector3d(0.0, 0.0, 0.125) + dp_device, Eigen::Vector3d::Zero());
  const double work_world = forces.force_world_n[0].dot(b.p_tool_world_m - a.p_tool_world_m);
  EXPECT_NEAR(f_device.dot(dp_device), work_world * m.force_scale / m.scale, 1e-15);
}

TEST(DeviceMapping, RejectsBrokenMappings) {
  DeviceMapping m;
  m.axis_permutation = {0, 0, 1};
  EXPECT_FALSE(is_valid(m));
  m = DeviceMapping{};
  m.axis_sign = {1, 0, 1};
  EXPECT_FALSE(is_valid(m));
  m = DeviceMapping{};
  m.scale = 0.0;
  EXPECT_FALSE(is_valid(m));
  m = DeviceMapping{};
  m.closing_axis_world = 3;
  EXPECT_FALSE(is_valid(m));
}

TEST(DeviceMapping, ClampModePinsTheToolAndDrivesTheJaws) {
  DeviceMapping m;
  m.clamp_mode = true;
  m.closing_axis_world = 0;  // world x is the jaw axis, driven by device x
  m.world_offset_m = {0.5, 0.0, 0.0};
  const ToolState tool = device_to_tool(m, Eigen::Vector3d(0.004, 0.01, 0.02), Eigen::Vector3d(0.1, 0.2, 0.0));
  EXPECT_DOUBLE_EQ(tool.p_tool_world_m.x(), 0.5);  // the tool does not move along the jaw axis
  EXPECT_DOUBLE_EQ(tool.v_tool_world_m_per_s.x(), 0.0);
  EXPECT_DOUBLE_EQ(tool.p_tool_world_m.y(), 0.01);
  EXPECT_DOUBLE_EQ(tool.jaw_closing_m, 0.004);
  EXPECT_DOUBLE_EQ(tool.jaw_closing_rate_m_per_s, 0.1);
  EXPECT_DOUBLE_EQ(jaw_closing_m(m, Eigen::Vector3d(0.004, 0.01, 0.02)), 0.004);
  // Closing moves the jaws towards each other: A (on −x) by +c/2, B (on +x) by −c/2.
  EXPECT_DOUBLE_EQ(part_motion(m, tool, ToolPart::kJawA).p_world_m.x(), 0.502);
  EXPECT_DOUBLE_EQ(part_motion(m, tool, ToolPart::kJawB).p_world_m.x(), 0.498);
  EXPECT_DOUBLE_EQ(part_motion(m, tool, ToolPart::kJawA).v_world_m_per_s.x(), 0.05);
}

TEST(DeviceMapping, ClampGripForceOpposesClosingAndPlanarForcesPassThrough) {
  DeviceMapping m;
  m.clamp_mode = true;
  m.closing_axis_world = 0;
  PartForces forces;
  // Tissue squeezed between the jaws pushes A towards −x and B towards +x, 2 N each,
  // and both jaws are pushed up by 1 N.
  forces.force_world_n[static_cast<std::size_t>(ToolPart::kJawA)] = Eigen::Vector3d(-2.0, 1.0, 0.0);
  forces.force_world_n[static_cast<std::size_t>(ToolPart::kJawB)] = Eigen::Vector3d(2.0, 1.0, 0.0);
  const Eigen::Vector3d f_device = part_forces_to_device(m, forces);
  EXPECT_DOUBLE_EQ(f_device.x(), -2.0);  // the hand feels 2 N resisting the closing
  EXPECT_DOUBLE_EQ(f_device.y(), 2.0);
  EXPECT_DOUBLE_EQ(f_device.z(), 0.0);
  // Virtual work on the closing DoF: δclosing = 1 mm moves A by +0.5 mm, B by −0.5 mm.
  const double work = -2.0 * 0.5e-3 + 2.0 * -0.5e-3;
  EXPECT_DOUBLE_EQ(f_device.x() * 1e-3, work);
}

}  // namespace
}  // namespace fissure
