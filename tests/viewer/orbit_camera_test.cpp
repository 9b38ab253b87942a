// The orbit camera's projection: what the image tests rely on to say where things land.
#include "fissure/viewer/orbit_camera.hpp"

#include <gtest/gtest.h>

namespace fissure::viewer {
namespace {

TEST(OrbitCamera, TargetProjectsToTheImageCentre) {
  OrbitCamera camera;
  camera.target_world_m = {0.1F, 0.05F, -0.2F};
  const auto p = camera.project(camera.target_world_m, 800, 600);
  ASSERT_TRUE(p.has_value());
  EXPECT_NEAR(p->x(), 400.0F, 1e-3F);
  EXPECT_NEAR(p->y(), 300.0F, 1e-3F);
  EXPECT_NEAR(p->z(), camera.distance_m, 1e-5F);
}

TEST(OrbitCamera, AxesLandOnTheExpectedSides) {
  OrbitCamera camera;
  camera.yaw_deg = 0.0F;  // eye on +z, looking along −z: world +x is image right, +y image up
  camera.pitch_deg = 0.0F;
  const auto right = camera.project({0.01F, 0.0F, 0.0F}, 800, 600);
  const auto up = camera.project({0.0F, 0.01F, 0.0F}, 800, 600);
  ASSERT_TRUE(right && up);
  EXPECT_GT(right->x(), 400.0F);
  EXPECT_NEAR(right->y(), 300.0F, 1e-3F);
  EXPECT_LT(up->y(), 300.0F);
  EXPECT_FALSE(camera.project({0.0F, 0.0F, 1.0F}, 800, 600).has_value());  // behind the eye
}

TEST(OrbitCamera, ProjectedRadiusMatchesAPointOnTheSilhouette) {
  OrbitCamera camera;
  camera.yaw_deg = 0.0F;
  camera.pitch_deg = 0.0F;
  camera.distance_m = 0.4F;
  // A sphere at the target: its silhouette's top is where the tangent ray touches.
  const float r = 0.05F, d = 0.4F;
  const float touch_y = r * std::sqrt(d * d - r * r) / d, touch_z = r * r / d;
  const auto top = camera.project({0.0F, touch_y, touch_z}, 800, 600);
  ASSERT_TRUE(top);
  EXPECT_NEAR(300.0F - top->y(), camera.projected_radius_px(Eigen::Vector3f::Zero(), r, 600), 0.05F);
}

TEST(OrbitCamera, DefaultCameraFramesTheSubjectAtHalfTheHeight) {
  RenderModel model;
  model.focus_world_m = {0.0F, 0.05F, 0.0F};
  model.focus_radius_m = 0.05F;
  const OrbitCamera camera = default_camera(model);
  const float radius_px = camera.projected_radius_px(model.focus_world_m, model.focus_radius_m, 720);
  EXPECT_NEAR(2.0F * radius_px / 720.0F, 0.5F, 0.02F);
}

TEST(OrbitCamera, OrbitAndZoomMoveTheEye) {
  OrbitCamera camera;
  const float yaw = camera.yaw_deg, distance = camera.distance_m;
  camera.orbit(40.0F, 1000.0F);
  EXPECT_LT(camera.yaw_deg, yaw);
  EXPECT_LE(camera.pitch_deg, 89.0F);  // clamped short of straight down
  camera.zoom(1.0F);
  EXPECT_NEAR(camera.distance_m, 0.9F * distance, 1e-5F);
}

}  // namespace
}  // namespace fissure::viewer
