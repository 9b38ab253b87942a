#pragma once
// Internal: the closed-form per-arm IK shared by kinematics.cpp and forward_kinematics.cpp.
// Header-only so the Newton loop inlines it. Derivation: docs/falcon_kinematics.md.
#include <array>
#include <cmath>

#include <Eigen/Core>

#include "fissure/falcon_hw/falcon_geometry.hpp"
#include "fissure/falcon_hw/kinematics.hpp"

namespace fissure::falcon::detail {

/// cos φᵢ, sin φᵢ of the three arms: computed once per call of a public function, not per
/// Newton iteration (three sincos would otherwise be a large share of an FK solve).
struct ArmFrames {
  std::array<double, 3> cos_phi{};
  std::array<double, 3> sin_phi{};
};

/// std::cos/std::sin of the stock φ doubles (π/2 + π/12, …) as x86-64 glibc computes them,
/// so the fast path matches the general one bit for bit there (within an ulp elsewhere).
inline constexpr ArmFrames kStockArmFrames{
    {-0.25881904510252063, 0.96592582628906831, -0.70710678118654746},
    {0.96592582628906831, -0.25881904510252074, -0.70710678118654757}};

inline ArmFrames make_arm_frames(const FalconGeometry& geometry) noexcept {
  // Fast path: six sin/cos calls cost ~60 ns, a seventh of a warm FK solve. Only taken when
  // φ is bit-for-bit the stock value; any other geometry is computed.
  const FalconGeometry stock;
  if (geometry.phi_rad == stock.phi_rad) return kStockArmFrames;
  ArmFrames frames;
  for (int i = 0; i < 3; ++i) {
    frames.cos_phi[i] = std::cos(geometry.phi_rad[i]);
    frames.sin_phi[i] = std::sin(geometry.phi_rad[i]);
  }
  return frames;
}

/// One arm's solution, kept as cosines/sines so the derivative needs no further trig.
struct ArmSolution {
  double tan_half_theta1 = 0.0;   // t = tan(θ1/2); θ1 = 2 atan t only when asked (atan ≈ 19 ns)
  double cos1 = 0.0, sin1 = 0.0;  // θ1 motor arm
  double cos2 = 0.0, sin2 = 0.0;  // θ2 knee
  double cos3 = 0.0, sin3 = 0.0;  // θ3 parallelogram
};

/// Arm i's joint angles for end-effector position p (device frame).
///
/// In the arm frame (u, v, w) = (Rᵢ p − (r, s, 0)), with Rᵢ the rotation by −φᵢ about z:
///   u = a cos θ1 − c + L cos θ2,  v = b cos θ3 − f,  w = a sin θ1 + L sin θ2,
///   L = d + e + b sin θ3.
/// θ3 comes from v. Eliminating θ2 gives (u + c − a cos θ1)² + (w − a sin θ1)² = L², a
/// quadratic l2 t² + l1 t + l0 = 0 in t = tan(θ1/2). The Falcon's assembly branch is the
/// root t = (−l1 − √D)/(2 l2), computed as 2 l0 / (−l1 + √D) (no cancellation, no division
/// by l2, which can be small). Returns false if the pose is not reachable (including
/// mirror poses behind the base: requires |θ1| < 90° and w > 0) or too close to a
/// singularity (kMinSinTheta3, kMinSinKnee).
inline bool solve_arm(const FalconGeometry& g, const ArmFrames& frames, int i, const Eigen::Vector3d& p,
                      ArmSolution& arm) noexcept {
  const double cphi = frames.cos_phi[i];
  const double sphi = frames.sin_phi[i];
  const double u = cphi * p.x() + sphi * p.y() - g.r_m;
  const double v = -sphi * p.x() + cphi * p.y() - g.s_m;
  const double w = p.z();

  const double cos3 = (v + g.f_m) / g.b_m;
  const double sin3_squared = 1.0 - cos3 * cos3;
  // Negated comparison so NaN (from non-finite p) fails too.
  if (!(sin3_squared >= kMinSinTheta3 * kMinSinTheta3)) return false;
  const double sin3 = std::sqrt(sin3_squared);

  const double link = g.d_m + g.e_m + g.b_m * sin3;  // L
  const double uc = u + g.c_m;
  const double k = uc * uc + g.a_m * g.a_m + w * w - link * link;
  // D/4 = 4a²(u_c² + w²) − K²: the two circles (arm of radius a, link of radius L) meet.
  const double quarter_discriminant = 4.0 * g.a_m * g.a_m * (uc * uc + w * w) - k * k;
  if (!(quarter_discriminant >= 0.0)) return false;
  const double l0 = k - 2.0 * g.a_m * uc;
  const double denominator = 2.0 * g.a_m * w + std::sqrt(quarter_discriminant);  // (−l1 + √D)/2
  if (!(denominator > 0.0)) return false;
  const double t = l0 / denominator;

  const double t_squared = t * t;
  const double cos1 = (1.0 - t_squared) / (1.0 + t_squared);
  const double sin1 = 2.0 * t / (1.0 + t_squared);
  const double cos2 = (uc - g.a_m * cos1) / link;
  const double sin2 = (w - g.a_m * sin1) / link;
  // sin(θ2 − θ1): zero where the arm and the link line up (the two roots merge, ∂θ1/∂p → ∞).
  const double sin_knee = sin2 * cos1 - cos2 * sin1;
  if (!(sin_knee >= kMinSinKnee)) return false;
  // The closed form also solves mirror poses with the upper arm swung behind the base
  // (e.g. z < 0, θ1 ≈ 160°); the hardware cannot reach them. cos θ1 > 0 ⇔ |θ1| < 90°.
  if (!(cos1 > 0.0) || !(w > 0.0)) return false;

  arm.tan_half_theta1 = t;
  arm.cos1 = cos1;
  arm.sin1 = sin1;
  arm.cos2 = cos2;
  arm.sin2 = sin2;
  arm.cos3 = cos3;
  arm.sin3 = sin3;
  return true;
}

/// Row i of ∂θ1/∂p. Differentiating the arm's loop-closure equation and projecting on the
/// parallelogram-side direction n = (sin θ3 cos θ2, cos θ3, sin θ3 sin θ2) (perpendicular
/// to the velocities θ2 and θ3 can produce) gives a sin θ3 sin(θ2 − θ1) dθ1 = n · Rᵢ dp.
/// The z entry is sin θ3 sin θ2 — libnifalcon (issue #66) writes sin² θ2.
inline Eigen::RowVector3d arm_derivative_row(const FalconGeometry& g, const ArmFrames& frames, int i,
                                             const ArmSolution& arm) noexcept {
  const double n_u = arm.sin3 * arm.cos2;
  const double n_v = arm.cos3;
  const double n_w = arm.sin3 * arm.sin2;
  const double sin_knee = arm.sin2 * arm.cos1 - arm.cos2 * arm.sin1;
  const double inverse_denominator = 1.0 / (g.a_m * arm.sin3 * sin_knee);
  const double cphi = frames.cos_phi[i];
  const double sphi = frames.sin_phi[i];
  // n · R dp with u = cφ x + sφ y, v = −sφ x + cφ y.
  return Eigen::RowVector3d{(n_u * cphi - n_v * sphi) * inverse_denominator,
                            (n_u * sphi + n_v * cphi) * inverse_denominator, n_w * inverse_denominator};
}

/// θ1 of all arms and, optionally, ∂θ1/∂p. Outputs are written only on success.
inline bool solve_all(const FalconGeometry& g, const ArmFrames& frames, const Eigen::Vector3d& p,
                      Eigen::Vector3d& theta_rad, Eigen::Matrix3d* dtheta_dp) noexcept {
  std::array<ArmSolution, 3> arms;
  for (int i = 0; i < 3; ++i) {
    if (!solve_arm(g, frames, i, p, arms[i])) return false;
  }
  theta_rad = {2.0 * std::atan(arms[0].tan_half_theta1), 2.0 * std::atan(arms[1].tan_half_theta1),
               2.0 * std::atan(arms[2].tan_half_theta1)};
  if (dtheta_dp != nullptr) {
    for (int i = 0; i < 3; ++i) dtheta_dp->row(i) = arm_derivative_row(g, frames, i, arms[i]);
  }
  return true;
}

/// atan(x), exact to double rounding, without a libm call when |x| < 0.01: the series
/// x − x³/3 + x⁵/5 − x⁷/7 + x⁹/9 then truncates below x¹¹/11 < 1e-22 |x|.
inline double accurate_atan(double x) noexcept {
  if (!(std::abs(x) < 0.01)) return std::atan(x);
  const double x2 = x * x;
  return x * (1.0 - x2 * (1.0 / 3.0 - x2 * (1.0 / 5.0 - x2 * (1.0 / 7.0 - x2 * (1.0 / 9.0)))));
}

/// FK's residual r = θ1(p) − θ1* without computing θ1(p): with t = tan(θ1/2) and
/// t* = tan(θ1*/2), θ1 − θ1* = 2 atan((t − t*)/(1 + t t*)) (valid as |θ1|, |θ1*| < 90°, so
/// t t* > −1). Near convergence the argument is tiny and accurate_atan needs no libm call,
/// which makes a warm Newton step ~30 % cheaper. Outputs written only on success.
inline bool solve_residual(const FalconGeometry& g, const ArmFrames& frames, const Eigen::Vector3d& p,
                           const Eigen::Vector3d& tan_half_target, Eigen::Vector3d& residual_rad,
                           Eigen::Matrix3d& dtheta_dp) noexcept {
  std::array<ArmSolution, 3> arms;
  for (int i = 0; i < 3; ++i) {
    if (!solve_arm(g, frames, i, p, arms[i])) return false;
  }
  for (int i = 0; i < 3; ++i) {
    const double t = arms[i].tan_half_theta1;
    const double t_target = tan_half_target[i];
    residual_rad[i] = 2.0 * accurate_atan((t - t_target) / (1.0 + t * t_target));
    dtheta_dp.row(i) = arm_derivative_row(g, frames, i, arms[i]);
  }
  return true;
}

/// dp_dtheta = dtheta_dp⁻¹; false (output unchanged) if singular or non-finite.
/// Defined in kinematics.cpp.
bool invert_derivative(const Eigen::Matrix3d& dtheta_dp, Eigen::Matrix3d& dp_dtheta) noexcept;

}  // namespace fissure::falcon::detail
