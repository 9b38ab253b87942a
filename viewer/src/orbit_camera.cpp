// Orbit camera maths (look-at + perspective, the usual OpenGL conventions: right-handed eye
// space looking down −z, clip z in [−w, w]).
#include "fissure/viewer/orbit_camera.hpp"

#include <algorithm>
#include <cmath>

namespace fissure::viewer {
namespace {

constexpr float kDegToRad = 3.14159265358979F / 180.0F;
// Mouse orbit sensitivity: a 400 px drag turns the view by 180°.
constexpr float kOrbitDegPerPx = 180.0F / 400.0F;
// Pitch limits: stay short of straight up/down (the look-at's up vector degenerates there).
constexpr float kPitchLimitDeg = 89.0F;
// Each wheel step zooms by 10 %.
constexpr float kZoomPerStep = 0.9F;
// The subject (radius r) fills about half the image height: distance = r / tan(fov/4)·…
constexpr float kDefaultSubjectFraction = 0.5F;

}  // namespace

Eigen::Vector3f OrbitCamera::eye_world_m() const noexcept {
  const float yaw = yaw_deg * kDegToRad, pitch = pitch_deg * kDegToRad;
  const Eigen::Vector3f towards_eye(std::sin(yaw) * std::cos(pitch), std::sin(pitch), std::cos(yaw) * std::cos(pitch));
  return target_world_m + distance_m * towards_eye;
}

Eigen::Matrix4f OrbitCamera::view() const noexcept {
  const Eigen::Vector3f eye = eye_world_m();
  const Eigen::Vector3f forward = (target_world_m - eye).normalized();
  const Eigen::Vector3f right = forward.cross(Eigen::Vector3f::UnitY()).normalized();
  const Eigen::Vector3f up = right.cross(forward);
  Eigen::Matrix4f m = Eigen::Matrix4f::Identity();
  m.block<1, 3>(0, 0) = right.transpose();
  m.block<1, 3>(1, 0) = up.transpose();
  m.block<1, 3>(2, 0) = -forward.transpose();
  m(0, 3) = -right.dot(eye);
  m(1, 3) = -up.dot(eye);
  m(2, 3) = forward.dot(eye);
  return m;
}

Eigen::Matrix4f OrbitCamera::projection(int width_px, int height_px) const noexcept {
  const float aspect = static_cast<float>(std::max(width_px, 1)) / static_cast<float>(std::max(height_px, 1));
  const float f = 1.0F / std::tan(0.5F * fov_y_deg * kDegToRad);
  Eigen::Matrix4f m = Eigen::Matrix4f::Zero();
  m(0, 0) = f / aspect;
  m(1, 1) = f;
  m(2, 2) = (far_m + near_m) / (near_m - far_m);
  m(2, 3) = 2.0F * far_m * near_m / (near_m - far_m);
  m(3, 2) = -1.0F;
  return m;
}

std::optional<Eigen::Vector3f> OrbitCamera::project(const Eigen::Vector3f& p_world_m, int width_px, int height_px) const noexcept {
  const Eigen::Vector4f eye = view() * p_world_m.homogeneous();
  if (eye.z() >= -near_m) return std::nullopt;
  const Eigen::Vector4f clip = projection(width_px, height_px) * eye;
  const float ndc_x = clip.x() / clip.w(), ndc_y = clip.y() / clip.w();
  return Eigen::Vector3f(0.5F * (ndc_x + 1.0F) * static_cast<float>(width_px), 0.5F * (1.0F - ndc_y) * static_cast<float>(height_px),
                         -eye.z());
}

float OrbitCamera::projected_radius_px(const Eigen::Vector3f& centre_world_m, float radius_m, int height_px) const noexcept {
  const float d = (centre_world_m - eye_world_m()).norm();
  if (d <= radius_m) return static_cast<float>(height_px);
  const float half_angle = std::asin(radius_m / d);
  const float focal_px = 0.5F * static_cast<float>(height_px) / std::tan(0.5F * fov_y_deg * kDegToRad);
  return focal_px * std::tan(half_angle);
}

void OrbitCamera::orbit(float dx_px, float dy_px) noexcept {
  yaw_deg -= dx_px * kOrbitDegPerPx;
  pitch_deg = std::clamp(pitch_deg + dy_px * kOrbitDegPerPx, -kPitchLimitDeg, kPitchLimitDeg);
}

void OrbitCamera::zoom(float wheel_steps) noexcept {
  distance_m = std::clamp(distance_m * std::pow(kZoomPerStep, wheel_steps), 4.0F * near_m, 0.5F * far_m);
}

OrbitCamera default_camera(const RenderModel& model) noexcept {
  OrbitCamera camera;
  camera.target_world_m = model.focus_world_m;
  const float half_fov = 0.5F * camera.fov_y_deg * kDegToRad;
  camera.distance_m = model.focus_radius_m / std::sin(half_fov * kDefaultSubjectFraction);
  camera.near_m = 0.05F * model.focus_radius_m;
  camera.far_m = 100.0F * camera.distance_m;
  return camera;
}

}  // namespace fissure::viewer
