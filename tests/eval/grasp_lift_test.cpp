// The grasp-and-lift experiment (eval/src/grasp_lift.cpp) on the shipped lift scene: with the
// shipped friction the vessel goes up with the jaws and stays put on them; with μ = 0.05 it slips
// out and stays on the ground; the friction that holds it carries its weight. Issue 23's targets.
#include "fissure/eval/grasp.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace fissure::eval {
namespace {

constexpr double kGravity_m_per_s2 = 9.81;

TEST(GraspLift, TheShippedFrictionLiftsTheVesselWithTheJawsAndNoNodeSlidesDuringTheHold) {
  GraspLiftOptions options;
  options.scene = grasp_lift_scene();
  const GraspLiftResult r = run_grasp_lift(options);
  ASSERT_TRUE(r.finite);
  EXPECT_NEAR(r.jaw_rise_m, 0.020, 1e-6) << "the script lifts 20 mm";
  EXPECT_LE(r.rise_shortfall_max_m, 2.0e-3) << "the vessel's centre of mass rises with the jaws within 2 mm";
  EXPECT_GT(r.hold_contact_nodes, 10);
  EXPECT_LE(r.hold_slide_max_m, 0.5e-3) << "no node on a jaw slides more than 0.5 mm during the 1 s hold";
  EXPECT_EQ(r.crossed_nodes_max, 0);
  EXPECT_EQ(r.cut_triangles_max, 0);
  // Held in the air, the jaws' friction carries the vessel's weight (the ground no longer does).
  EXPECT_NEAR(r.hold_friction_up_n, r.vessel_mass_kg * kGravity_m_per_s2, 0.15 * r.vessel_mass_kg * kGravity_m_per_s2);
  EXPECT_GT(r.hold_grip_n, 0.1);
  // The trace has a row per step with per-jaw normal and friction force and the jaw gap.
  EXPECT_EQ(r.time_s.size(), r.jaw_a_friction_n.size());
  EXPECT_EQ(r.time_s.size(), r.jaw_gap_m.size());
  // The jaws let go: the force reaches 0 N and stays there once they clear the vessel.
  EXPECT_GE(r.release_delay_s, 0.0);
  EXPECT_LE(r.release_delay_s, 5e-3) << "0 N within 5 ms of the jaws clearing the vessel (issue 23)";
  EXPECT_DOUBLE_EQ(r.jaw_a_normal_n.back() + r.jaw_b_normal_n.back() + r.jaw_a_friction_n.back() + r.jaw_b_friction_n.back(), 0.0);
}

TEST(GraspLift, AtMuFiveHundredthsTheVesselSlipsOutOfTheJaws) {
  GraspLiftOptions options;
  options.scene = grasp_lift_scene();
  options.friction_ratio_override = 0.05;
  const GraspLiftResult r = run_grasp_lift(options);
  ASSERT_TRUE(r.finite);
  EXPECT_LT(r.centroid_rise_m, 0.5 * r.jaw_rise_m);
  EXPECT_EQ(r.crossed_nodes_max, 0);
}

TEST(GraspLift, FrictionlessJawsLiftNothing) {
  GraspLiftOptions options;
  options.scene = grasp_lift_scene();
  options.friction_ratio_override = 0.0;
  const GraspLiftResult r = run_grasp_lift(options);
  ASSERT_TRUE(r.finite);
  EXPECT_LT(r.centroid_rise_m, 2.0e-3);
  EXPECT_DOUBLE_EQ(r.hold_friction_up_n, 0.0);
}

}  // namespace
}  // namespace fissure::eval
