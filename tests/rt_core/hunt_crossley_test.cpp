#include "fissure/rt_core/hunt_crossley.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace fissure::rt {
namespace {

TEST(HuntCrossley, MatchesTheClosedFormForKnownPenetrationsAndSpeeds) {
  const double k = 800.0, lambda = 150.0;
  for (const double n : {1.0, 1.5, 2.0, 1.3}) {
    for (const double x : {1e-4, 1e-3, 5e-3, 2e-2}) {
      for (const double x_dot : {-0.2, 0.0, 0.05, 0.5}) {
        const double expected = std::max(0.0, k * std::pow(x, n) + lambda * std::pow(x, n) * x_dot);
        EXPECT_NEAR(hunt_crossley_force_n(x, x_dot, k, lambda, n), expected, 1e-12 * (1.0 + expected))
            << "n=" << n << " x=" << x << " xdot=" << x_dot;
      }
    }
  }
}

TEST(HuntCrossley, NoForceOutOfContactAndNoJumpAtContact) {
  EXPECT_EQ(hunt_crossley_force_n(0.0, 1.0, 1000.0, 10.0, 1.5), 0.0);
  EXPECT_EQ(hunt_crossley_force_n(-1e-3, 1.0, 1000.0, 10.0, 1.5), 0.0);
  EXPECT_EQ(hunt_crossley_force_n(std::nan(""), 1.0, 1000.0, 10.0, 1.5), 0.0);
  EXPECT_LT(hunt_crossley_force_n(1e-9, 1.0, 1000.0, 10.0, 1.0), 1e-5);
}

TEST(HuntCrossley, WithdrawingFasterThanKOverLambdaIsClampedToZeroNotPulling) {
  const double k = 1000.0, lambda = 100.0;  // k/λ = 10 m/s
  EXPECT_GT(hunt_crossley_force_n(1e-3, -9.0, k, lambda, 1.0), 0.0);
  EXPECT_EQ(hunt_crossley_force_n(1e-3, -11.0, k, lambda, 1.0), 0.0);  // raw formula: −0.001 N
}

ContactProxy wall_proxy(double stiffness, double lambda, double n) {
  ContactProxy proxy;
  proxy.flags = kProxyValid;
  proxy.patch_count = 1;
  ContactPatch& p = proxy.patches[0];
  p.plane_point_world_m = {0.0, 0.0, 0.0};
  p.normal_world = {0.0, 1.0, 0.0};
  p.stiffness_k = stiffness;
  p.damping_lambda = lambda;
  p.exponent_n = n;
  return proxy;
}

TEST(HuntCrossley, ProxyEvaluationUsesTheCurrentPositionAndPointsAlongTheNormal) {
  const ContactProxy proxy = wall_proxy(2000.0, 50.0, 1.5);
  DeviceMapping identity;
  ToolState tool;
  tool.p_tool_world_m = Eigen::Vector3d(0.3, -0.004, 0.1);  // 4 mm below the plane
  tool.v_tool_world_m_per_s = Eigen::Vector3d(0.0, -0.1, 0.0);  // pressing in: ẋ = +0.1
  PartForces forces;
  const ContactEvaluation evaluation = evaluate_proxy(proxy, identity, tool, forces);
  const double expected = 2000.0 * std::pow(0.004, 1.5) * (1.0 + 50.0 / 2000.0 * 0.1);
  EXPECT_NEAR(forces.force_world_n[0].y(), expected, 1e-12);
  EXPECT_EQ(forces.force_world_n[0].x(), 0.0);
  EXPECT_NEAR(evaluation.max_penetration_m, 0.004, 1e-15);
  EXPECT_EQ(evaluation.patches_in_contact, 1);

  tool.p_tool_world_m.y() = 0.001;  // above the plane
  EXPECT_EQ(evaluate_proxy(proxy, identity, tool, forces).patches_in_contact, 0);
  EXPECT_EQ(forces.force_world_n[0], Eigen::Vector3d::Zero());
}

TEST(HuntCrossley, PatchesSumPerToolPart) {
  ContactProxy proxy = wall_proxy(1000.0, 0.0, 1.0);
  proxy.patch_count = 3;
  proxy.patches[1] = proxy.patches[0];
  proxy.patches[1].normal_world = {1.0, 0.0, 0.0};
  proxy.patches[2] = proxy.patches[0];
  proxy.patches[2].tool_part = ToolPart::kJawB;
  DeviceMapping identity;
  ToolState tool;
  tool.p_tool_world_m = Eigen::Vector3d(-0.002, -0.001, 0.0);
  PartForces forces;
  evaluate_proxy(proxy, identity, tool, forces);
  EXPECT_NEAR((forces.force_world_n[0] - Eigen::Vector3d(2.0, 1.0, 0.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((forces.force_world_n[2] - Eigen::Vector3d(0.0, 1.0, 0.0)).norm(), 0.0, 1e-12);
}

// Colgate–Schenkel: a patch renders damping λ·xⁿ only up to b − n·k·xⁿ⁻¹·T/2 (the device's
// damping b less what the sampled stiffness already needs of it); the elastic part is untouched.
TEST(HuntCrossley, CapsTheRenderedDampingAtWhatTheDeviceCanDissipate) {
  DeviceMapping identity;
  ToolState tool;
  tool.p_tool_world_m = Eigen::Vector3d(0.0, -0.004, 0.0);      // x = 4 mm
  tool.v_tool_world_m_per_s = Eigen::Vector3d(0.0, -0.1, 0.0);  // ẋ = +0.1 m/s
  PartForces forces;
  const DampingCap cap{3.0, 1e-3};  // SimFalcon's nominal b, 1 kHz
  const double k = 2000.0, n = 1.5, x = 0.004, x_n = std::pow(x, n);
  const double max_damping = 3.0 - 0.5 * n * k * std::pow(x, n - 1.0) * 1e-3;  // 2.905 N·s/m
  // λ·xⁿ = 50·2.5e-4 = 0.013 N·s/m: far below the cap, plain HC.
  evaluate_proxy(wall_proxy(k, 50.0, n), identity, tool, forces, cap);
  EXPECT_NEAR(forces.force_world_n[0].y(), k * x_n + 50.0 * x_n * 0.1, 1e-12);
  // λ·xⁿ = 5e4·2.5e-4 = 12.6 N·s/m: capped at 2.905 N·s/m.
  const ContactEvaluation evaluation = evaluate_proxy(wall_proxy(k, 5e4, n), identity, tool, forces, cap);
  EXPECT_NEAR(forces.force_world_n[0].y(), k * x_n + max_damping * 0.1, 1e-12);
  // The stored energy is the elastic part's: k·xⁿ⁺¹/(n+1).
  EXPECT_NEAR(evaluation.stored_energy_world_j, k * std::pow(x, n + 1.0) / (n + 1.0), 1e-15);
  // So stiff that K·T/2 alone exceeds b: no damping at all (the elastic force stays).
  const double stiff_k = 1e5;  // tangent 1.5·1e5·0.063 = 9487 N/m: K·T/2 = 4.7 > 3
  evaluate_proxy(wall_proxy(stiff_k, 5e4, n), identity, tool, forces, cap);
  EXPECT_NEAR(forces.force_world_n[0].y(), stiff_k * x_n, 1e-9);
  // Without a cap (the default, as the host evaluates the proxy) the damping is the proxy's.
  evaluate_proxy(wall_proxy(k, 5e4, n), identity, tool, forces);
  EXPECT_NEAR(forces.force_world_n[0].y(), k * x_n * (1.0 + 5e4 / k * 0.1), 1e-9);
}

}  // namespace
}  // namespace fissure::rt
