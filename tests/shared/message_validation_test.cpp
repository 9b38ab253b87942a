#include "fissure/shared/message_validation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

namespace fissure {
namespace {

ContactProxy one_patch_proxy() {
  ContactProxy proxy;
  proxy.flags = kProxyValid;
  proxy.patch_count = 1;
  ContactPatch& p = proxy.patches[0];
  p.plane_point_world_m = {0.0, 0.05, 0.0};
  p.normal_world = {0.0, 1.0, 0.0};
  p.stiffness_k = 500.0;
  p.damping_lambda = 2.0;
  p.exponent_n = 1.5;
  return proxy;
}

ContactProxy proxy_with_friction() {
  ContactProxy proxy = one_patch_proxy();
  proxy.flags |= proxy_friction_bit(ToolPart::kTool);
  PartFriction& f = proxy.friction[0];
  f.host_force_world_n = {0.3, 0.0, -0.1};
  f.reference_part_position_world_m = {0.0, 0.1, 0.0};
  f.surface_velocity_world_m_per_s = {0.01, 0.0, 0.0};
  f.static_ratio = 0.5;
  f.kinetic_ratio = 0.4;
  return proxy;
}

TEST(MessageValidation, PartFrictionIsCheckedOnlyWhereItsFlagSaysItIsCarried) {
  EXPECT_EQ(validate(proxy_with_friction()), ProxyError::kNone);
  struct Case {
    const char* what;
    void (*corrupt)(PartFriction&);
    ProxyError expected;
  };
  const Case cases[] = {
      {"nan force", [](PartFriction& f) { f.host_force_world_n[1] = std::numeric_limits<double>::quiet_NaN(); }, ProxyError::kNonFinite},
      {"inf velocity", [](PartFriction& f) { f.surface_velocity_world_m_per_s[0] = std::numeric_limits<double>::infinity(); }, ProxyError::kNonFinite},
      {"negative mu", [](PartFriction& f) { f.static_ratio = -0.1; }, ProxyError::kFrictionOutOfRange},
      {"mu above 2", [](PartFriction& f) { f.static_ratio = 2.5; }, ProxyError::kFrictionOutOfRange},
      {"kinetic above static", [](PartFriction& f) { f.kinetic_ratio = 0.6; }, ProxyError::kFrictionOutOfRange},
      {"absurd force", [](PartFriction& f) { f.host_force_world_n[0] = 1e4; }, ProxyError::kFrictionOutOfRange},
      {"far reference", [](PartFriction& f) { f.reference_part_position_world_m[2] = 50.0; }, ProxyError::kFrictionOutOfRange},
      {"absurd surface speed", [](PartFriction& f) { f.surface_velocity_world_m_per_s[1] = 500.0; }, ProxyError::kFrictionOutOfRange},
  };
  for (const Case& c : cases) {
    ContactProxy proxy = proxy_with_friction();
    c.corrupt(proxy.friction[0]);
    EXPECT_EQ(validate(proxy), c.expected) << c.what;
    EXPECT_STRNE(to_string(c.expected), "unknown proxy error");
    // The same garbage in a part whose flag is clear is not read.
    ContactProxy unflagged = one_patch_proxy();
    unflagged.friction[0] = proxy.friction[0];
    EXPECT_EQ(validate(unflagged), ProxyError::kNone) << c.what;
  }
}

TEST(MessageLayout, ProxyIsByteCopyable) {
  const ContactProxy a = one_patch_proxy();
  ContactProxy b;
  std::memcpy(&b, &a, sizeof a);
  EXPECT_EQ(validate(b), ProxyError::kNone);
  EXPECT_EQ(b.patches[0].stiffness_k, 500.0);
}

TEST(ProxyValidation, AcceptsAWellFormedProxy) {
  EXPECT_EQ(validate(one_patch_proxy()), ProxyError::kNone);
  EXPECT_EQ(validate(ContactProxy{}), ProxyError::kNone) << "an empty proxy (no contact) is valid";
}

TEST(ProxyValidation, RejectsEachKindOfBadInputAndNamesThePatch) {
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  constexpr double inf = std::numeric_limits<double>::infinity();
  struct Case {
    const char* what;
    void (*corrupt)(ContactProxy&);
    ProxyError expected;
  };
  const Case cases[] = {
      {"version", [](ContactProxy& p) { p.protocol_version = kProtocolVersion + 1; }, ProxyError::kWrongVersion},
      {"count", [](ContactProxy& p) { p.patch_count = kMaxContactPatches + 1; }, ProxyError::kTooManyPatches},
      {"nan point", [](ContactProxy& p) { p.patches[0].plane_point_world_m[1] = nan; }, ProxyError::kNonFinite},
      {"inf k", [](ContactProxy& p) { p.patches[0].stiffness_k = inf; }, ProxyError::kNonFinite},
      {"nan quat", [](ContactProxy& p) { p.patches[0].reference_tool_orientation_world[2] = nan; }, ProxyError::kNonFinite},
      {"far point", [](ContactProxy& p) { p.patches[0].plane_point_world_m[0] = 1e3; }, ProxyError::kCoordinateOutOfRange},
      {"zero normal", [](ContactProxy& p) { p.patches[0].normal_world = {0, 0, 0}; }, ProxyError::kNormalNotUnit},
      {"negative k", [](ContactProxy& p) { p.patches[0].stiffness_k = -1; }, ProxyError::kStiffnessOutOfRange},
      {"negative lambda", [](ContactProxy& p) { p.patches[0].damping_lambda = -1; }, ProxyError::kDampingOutOfRange},
      {"n too big", [](ContactProxy& p) { p.patches[0].exponent_n = 7; }, ProxyError::kExponentOutOfRange},
      {"part", [](ContactProxy& p) { p.patches[0].tool_part = static_cast<ToolPart>(9); }, ProxyError::kBadToolPart},
  };
  for (const Case& c : cases) {
    ContactProxy proxy = one_patch_proxy();
    c.corrupt(proxy);
    int bad_patch = 99;
    EXPECT_EQ(validate(proxy, &bad_patch), c.expected) << c.what;
    EXPECT_STRNE(to_string(c.expected), "unknown proxy error");
    if (c.expected != ProxyError::kWrongVersion && c.expected != ProxyError::kTooManyPatches) {
      EXPECT_EQ(bad_patch, 0) << c.what;
    }
  }
}

TEST(ProxyValidation, PatchesBeyondCountAreIgnored) {
  ContactProxy proxy = one_patch_proxy();
  proxy.patches[3].stiffness_k = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(validate(proxy), ProxyError::kNone);
}

TEST(DeviceStateValidation, FiniteCheck) {
  DeviceState state;
  EXPECT_TRUE(is_finite(state));
  state.velocity_device_m_per_s[2] = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(is_finite(state));
}

}  // namespace
}  // namespace fissure
