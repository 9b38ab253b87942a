// The ray-only variant (paper Fig. 3 right): the same rays and detection without the pairing /
// exclusion step — both faces of the thin tool push, and soft nodes end on the wrong side. This
// suite asserts that instability, measured against the paired method in the same runs.
#include "soft_scene_fixture.hpp"

#include <gtest/gtest.h>

#include <cstdio>

namespace fissure::host {
namespace {

TEST(RayCollision, BothFacesPushAndNodesCrossWherePairedStaysClean) {
  const ToolNodes tool = test_scene::plate_tool(0.004);
  int ray_crossed_total = 0;
  int ray_both_face_total = 0;
  for (const double speed : {0.1, 1.0, 10.0, 50.0}) {
    test_scene::PlungeSpec spec;
    spec.speed_m_s = speed;
    const auto ray = test_scene::run_sphere_plunge(tool, SceneCollisionMethod::kRay, spec);
    const auto paired = test_scene::run_sphere_plunge(tool, SceneCollisionMethod::kPaired, spec);
    std::printf("[ray vs paired] %5.1f m/s: ray crossed %d, both-face contacts %d (max %d/step), max pen %.3f mm | "
                "paired crossed %d, both-face %d\n",
                speed, ray.crossed_nodes, ray.total_both_face_contacts, ray.max_both_face_contacts,
                ray.max_penetration_m * 1e3, paired.crossed_nodes, paired.total_both_face_contacts);
    ray_crossed_total += ray.crossed_nodes;
    ray_both_face_total += ray.total_both_face_contacts;
    EXPECT_EQ(paired.crossed_nodes, 0);
    EXPECT_EQ(paired.total_both_face_contacts, 0);
    EXPECT_TRUE(ray.forces_finite);
  }
  EXPECT_GT(ray_both_face_total, 0);
  EXPECT_GT(ray_crossed_total, 0);
}

TEST(RayCollision, ReportsItsMethod) {
  test_scene::SoftWorld world(true);
  world.add_sphere();
  const ToolNodes tool = test_scene::plate_tool(0.004);
  EXPECT_EQ(make_ray_collision(tool, world.soft(), ThinBodyCollisionParams{})->method(), SceneCollisionMethod::kRay);
}

}  // namespace
}  // namespace fissure::host
