#pragma once
// Falcon kinematics (BRIEF §6, Stamper's thesis ch. 3–4): closed-form inverse kinematics,
// the analytic Jacobian, and forward kinematics by damped Newton. Pure functions of
// (geometry, input): no I/O, no globals, no allocation, noexcept — rt_core calls
// forward_kinematics() and jacobian() every tick. Full derivation: docs/falcon_kinematics.md.
//
// Device frame (libnifalcon's): origin at the centre of the base, x to the user's right,
// y up, z out of the device toward the user. Metres, radians.
//
// Workspace. The *reachable* region is where every arm's closed-form IK has a real
// solution on the Falcon's assembly branch — upper arm in front of the base (|θ1| < 90°),
// end effector in front of the base (z > 0) — with the arm kept away from its singular
// configurations (sin θ3 ≥ kMinSinTheta3, sin(θ2 − θ1) ≥ kMinSinKnee). inverse_kinematics()
// reports failure outside it. It is a purely geometric region and somewhat larger than
// what the real device's mechanical stops allow. The documented *workspace* (in_workspace())
// is the ball of radius kWorkspaceRadius_m = 5 cm around kWorkspaceCentre_device_m =
// (0, 0, 0.125) m — the Falcon's advertised ~10 cm reach. It lies wholly inside the reachable
// region with sin(θ2 − θ1) ≥ 0.45 and sin θ3 ≥ 0.85 on every arm and θ1 ∈ [−35°, 82°]
// (tests check the margins), so the Jacobian is well conditioned everywhere in it. A 5 cm
// ball fits with these margins only around z ≈ 0.12–0.125 m on the axis; the cube
// |x|,|y| ≤ 5 cm, z ∈ [7.5, 17.5] cm is NOT fully reachable (its corners fail IK).
#include <array>

#include <Eigen/Core>

#include "fissure/falcon_hw/falcon_geometry.hpp"

namespace fissure::falcon {

/// Centre of the documented workspace ball (device frame). Chosen as the point around
/// which the largest well-conditioned ball fits (scan over z on the axis; docs page).
inline constexpr std::array<double, 3> kWorkspaceCentre_device_m{0.0, 0.0, 0.125};
/// Radius of the documented workspace ball around kWorkspaceCentre_device_m.
inline constexpr double kWorkspaceRadius_m = 0.050;
/// IK refuses arm poses closer than this to the parallelogram-folded singularity (θ3 → 0, π).
inline constexpr double kMinSinTheta3 = 0.2;
/// IK refuses arm poses closer than this to the knee-straight singularity (θ2 − θ1 → 0, π),
/// where ∂θ1/∂p blows up.
inline constexpr double kMinSinKnee = 0.05;

/// All three joint angles of one arm (Stamper's θ1 motor, θ2 knee, θ3 parallelogram).
struct ArmAngles {
  double theta1_rad = 0.0;
  double theta2_rad = 0.0;
  double theta3_rad = 0.0;
};

/// Closed-form IK for all joints of all arms. False, arms unchanged, when p is non-finite
/// or outside the reachable region.
bool arm_angles(const FalconGeometry& geometry, const Eigen::Vector3d& p_device_m,
                std::array<ArmAngles, 3>& arms) noexcept;

/// Motor angles θ1 of the three arms for an end-effector position. False, and θ left
/// unchanged, outside the reachable region (see above) or for non-finite input; never NaN.
bool inverse_kinematics(const FalconGeometry& geometry, const Eigen::Vector3d& p_device_m,
                        Eigen::Vector3d& theta_rad) noexcept;

/// IK and its analytic derivative in one pass (what FK's Newton step needs).
/// Row i of dtheta_dp is ∂θ1ᵢ/∂p = nᵢᵀ Rᵢ / (a sin θ3 sin(θ2 − θ1)), where nᵢ is the
/// direction of arm i's parallelogram side — its z entry is sin θ2 sin θ3 (libnifalcon
/// issue #66 has sin² θ2 there). False, outputs unchanged, outside the reachable region.
bool inverse_kinematics_with_derivative(const FalconGeometry& geometry, const Eigen::Vector3d& p_device_m,
                                        Eigen::Vector3d& theta_rad, Eigen::Matrix3d& dtheta_dp) noexcept;

/// J = ∂p/∂θ1 (columns: motor 1..3), the inverse of the analytic ∂θ1/∂p. Torque τ = Jᵀ F.
/// False, dp_dtheta unchanged, if p is outside the reachable region or J is singular.
bool jacobian(const FalconGeometry& geometry, const Eigen::Vector3d& p_device_m,
              Eigen::Matrix3d& dp_dtheta) noexcept;

/// Default FK tolerance on max |IK(p) − θ| (rad). 1e-9 rad is ≈ 1e-10 m at the centre
/// (|∂p/∂θ| ≈ 0.08 m/rad), far below a 1 µm target and the encoder's 6.4e-4 rad step,
/// and costs at most one more Newton step than 1e-6 (quadratic convergence; see bench).
inline constexpr double kDefaultFkTolerance_rad = 1e-9;
/// Newton iterations allowed: warm starts from the previous 1 kHz sample need ≤ 2 at the
/// default tolerance, cold starts from the workspace centre ≤ 6 over the whole workspace
/// (tests; `fissure bench kinematics` reports the distribution). Only unreachable θ use them all.
inline constexpr int kDefaultFkMaxIterations = 30;

struct FkOptions {
  double tolerance_rad = kDefaultFkTolerance_rad;  ///< stop when max |IK(p) − θ| < this
  int max_iterations = kDefaultFkMaxIterations;    ///< Newton steps allowed (bounded time)
};

struct FkResult {
  bool converged = false;    ///< residual below tolerance within max_iterations
  int iterations = 0;        ///< Newton steps taken
  double residual_rad = 0;   ///< max |IK(p) − θ| at the returned p (inf if IK fails there)
};

/// Forward kinematics: damped Newton on IK(p) − θ = 0 with the analytic ∂θ/∂p, starting
/// from p_device_m (the previous solution: warm start). Backtracking line search on the
/// residual and a step-length limit keep it inside the reachable region; the residual
/// never grows. If the warm start is not reachable (first tick, after a fault: NaN, 0)
/// it starts from the workspace centre. On return p_device_m is the best point found (a
/// reachable point, never NaN). Worst-case cost is bounded: max_iterations Newton steps,
/// each at most 21 IK evaluations (step halvings).
FkResult forward_kinematics(const FalconGeometry& geometry, const Eigen::Vector3d& theta_rad,
                            Eigen::Vector3d& p_device_m, const FkOptions& options) noexcept;

/// forward_kinematics() that also returns J = ∂p/∂θ1 at the returned p, reusing the
/// derivative its last Newton evaluation computed: saves the rt loop a jacobian() call
/// (≈ 90–150 ns) per tick. dp_dtheta_valid is false (dp_dtheta unchanged) if FK failed before
/// any evaluation or J is singular there; when true, J equals jacobian(p) to rounding.
FkResult forward_kinematics_with_jacobian(const FalconGeometry& geometry, const Eigen::Vector3d& theta_rad,
                                          Eigen::Vector3d& p_device_m, const FkOptions& options,
                                          Eigen::Matrix3d& dp_dtheta, bool& dp_dtheta_valid) noexcept;

/// Forward kinematics from kWorkspaceCentre_device_m: converges from anywhere in the
/// workspace (tested over the whole ball). p_device_m is output only.
FkResult forward_kinematics_cold(const FalconGeometry& geometry, const Eigen::Vector3d& theta_rad,
                                 Eigen::Vector3d& p_device_m, const FkOptions& options) noexcept;

/// True inside the documented workspace ball (and reachable). False for non-finite p.
bool in_workspace(const FalconGeometry& geometry, const Eigen::Vector3d& p_device_m) noexcept;

}  // namespace fissure::falcon
