#pragma once
// The camera both the window and the frame writer use: it orbits a target point (yaw about
// world y, pitch above the horizon, distance), perspective projection. project() is the same
// maths the shaders get, so a test can say where a world point lands in the image.
#include <optional>

#include <Eigen/Core>

#include "fissure/viewer/render_snapshot.hpp"

namespace fissure::viewer {

struct OrbitCamera {
  Eigen::Vector3f target_world_m = Eigen::Vector3f::Zero();
  float yaw_deg = 30.0F;    ///< about world +y, 0 = looking along −z (from +z)
  float pitch_deg = 25.0F;  ///< above the horizon, looking down
  float distance_m = 0.3F;
  float fov_y_deg = 40.0F;
  float near_m = 0.005F;
  float far_m = 5.0F;

  [[nodiscard]] Eigen::Vector3f eye_world_m() const noexcept;
  [[nodiscard]] Eigen::Matrix4f view() const noexcept;
  [[nodiscard]] Eigen::Matrix4f projection(int width_px, int height_px) const noexcept;
  /// Pixel coordinates (x right, y DOWN from the image's top-left, pixel centres at +0.5) and
  /// the eye-space depth; nullopt behind the camera.
  [[nodiscard]] std::optional<Eigen::Vector3f> project(const Eigen::Vector3f& p_world_m, int width_px, int height_px) const noexcept;
  /// Screen radius [px] of a sphere of `radius_m` centred at `centre_world_m` (the half-angle it
  /// subtends, through the projection's focal length).
  [[nodiscard]] float projected_radius_px(const Eigen::Vector3f& centre_world_m, float radius_m, int height_px) const noexcept;

  /// Mouse: drag by (dx, dy) pixels orbits; wheel steps zoom (each step 10 %).
  void orbit(float dx_px, float dy_px) noexcept;
  void zoom(float wheel_steps) noexcept;
};

/// The default view of a scene: looks at its soft body from the front-right, slightly above,
/// far enough that the subject fills about half the image height.
[[nodiscard]] OrbitCamera default_camera(const RenderModel& model) noexcept;

}  // namespace fissure::viewer
