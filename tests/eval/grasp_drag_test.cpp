// The drag experiment (eval/src/grasp_drag.cpp) on the shipped scene: a lockstep session in which
// SimFalcon's scripted hand slides the spatula across the ball's top. What the hand is commanded
// across the contact normal is μ_k times what it is commanded along it, at a 100 Hz host too.
#include "fissure/eval/grasp.hpp"

#include <gtest/gtest.h>

#include <cstdio>

namespace fissure::eval {
namespace {

TEST(GraspDrag, TheHandFeelsKineticFrictionTimesTheNormalForceWhileTheSpatulaSlides) {
  for (const double host_rate_hz : {1000.0, 100.0}) {
    GraspDragOptions options;
    options.scene = grasp_drag_scene();
    options.host_rate_hz = host_rate_hz;
    const GraspDragResult r = run_grasp_drag(options);
    std::printf("host %.0f Hz: slide ticks %d at %.3f m/s, normal %.3f N, tangential %.3f N, ratio %.4f (p10 %.4f p90 %.4f), "
                "host %.3f / %.3f N, cone sliding %.2f\n",
                host_rate_hz, r.slide_ticks, r.slide_speed_median_m_per_s, r.normal_median_n, r.tangential_median_n, r.ratio_median,
                r.ratio_p10, r.ratio_p90, r.host_friction_median_n, r.host_normal_median_n, r.sliding_tick_share);
    ASSERT_TRUE(r.finite);
    EXPECT_EQ(r.crossed_nodes_max, 0);
    EXPECT_GT(r.slide_ticks, 150) << "the scripted slide is 0.4 s";
    EXPECT_NEAR(r.normal_median_n, 2.0, 0.3) << "the scene presses with ~2 N";
    EXPECT_NEAR(r.ratio_median / r.friction_kinetic_ratio, 1.0, 0.10) << host_rate_hz << " Hz";
    // Never more than the static cone (a few % for the blend and the passivity controller).
    EXPECT_LE(r.ratio_p90, 1.05 * r.friction_static_ratio);
    EXPECT_GT(r.host_friction_median_n, 0.0) << "the host's own friction acts too";
  }
}

}  // namespace
}  // namespace fissure::eval
