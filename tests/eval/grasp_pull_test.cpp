// The pull-out experiment (eval/src/grasp_pull.cpp) on the shipped retraction scene: a gripped,
// end-anchored vessel pulled along its length slides through the jaws, the friction force along
// the pull stays within 10 % below the Coulomb limit μ·(both jaws' normal force), and a firmer grip
// pulls harder.
#include "fissure/eval/grasp.hpp"

#include <gtest/gtest.h>

namespace fissure::eval {
namespace {

GraspPullResult pull(double jaw_gap_m) {
  GraspPullOptions options;
  options.scene = grasp_pull_scene();
  options.jaw_gap_m = jaw_gap_m;
  options.friction_ratio = 0.3;
  options.pull_distance_m = 0.02;  // the bench's pull: the last quarter of it is steady sliding
  return run_grasp_pull(options);
}

TEST(GraspPull, TheVesselSlidesThroughTheJawsWithinTheCoulombLimitAndAFirmerGripPullsHarder) {
  const GraspPullResult loose = pull(0.024);
  const GraspPullResult firm = pull(0.018);
  for (const GraspPullResult* r : {&loose, &firm}) {
    ASSERT_TRUE(r->finite);
    EXPECT_EQ(r->crossed_nodes_max, 0);
    EXPECT_GT(r->grip_n, 0.05);
    EXPECT_GT(r->slip_m, 0.5 * 0.02) << "anchored, the vessel cannot follow the jaws: they slide along it";
    // Sliding friction never exceeds μ·(F_A + F_B) = 2μ·grip (a node's cone is its own normal force).
    EXPECT_GT(r->pull_out_n, 0.0);
    EXPECT_LE(r->pull_out_n, 2.0 * 0.3 * r->grip_n * 1.05);
    // ... and sliding, it is Coulomb's, not a stick–slip average below it (issue 23: the slope
    // against the grip is 2μ within 10 %; here each grip's own ratio).
    EXPECT_GE(r->pull_out_n, 2.0 * 0.3 * r->grip_n * 0.90) << "grip " << r->grip_n << " N";
  }
  EXPECT_GT(firm.grip_n, 2.0 * loose.grip_n);
  EXPECT_GT(firm.pull_out_n, 2.0 * loose.pull_out_n);
}

}  // namespace
}  // namespace fissure::eval
