#pragma once
// The Novint Falcon's mechanism dimensions (a const model, built once, BRIEF §10).
// Values: libnifalcon include/falcon/core/FalconGeometry.h, which names them after the
// diagram on p. 30 of R.E. Stamper's thesis (PhD 97-4, "A three degree of freedom parallel
// manipulator with only translational degrees of freedom"). See docs/falcon_kinematics.md.
#include <array>
#include <numbers>

namespace fissure::falcon {

struct FalconGeometry {
  double a_m = 0.060;     ///< upper arm: motor axis to knee
  double b_m = 0.1025;    ///< lower-arm parallelogram side
  double c_m = 0.01443;   ///< parallelogram attachment to end-effector centre, u component
  double d_m = 0.01125;   ///< parallelogram to end-effector joint
  double e_m = 0.01125;   ///< knee to parallelogram joint
  double f_m = -0.025;    ///< parallelogram attachment to end-effector centre, v component
  double r_m = 0.0400;    ///< device origin to arm base, u component
  double s_m = -0.02309;  ///< device origin to arm base, v component
  /// Rotation of each arm's (u, v, w) frame about the device z axis: 105°, −15°, −135°
  /// (libnifalcon: π/2 + π/12, −π/6 + π/12, −5π/6 + π/12).
  std::array<double, 3> phi_rad{std::numbers::pi / 2.0 + std::numbers::pi / 12.0,
                                -std::numbers::pi / 6.0 + std::numbers::pi / 12.0,
                                -5.0 * std::numbers::pi / 6.0 + std::numbers::pi / 12.0};
};

}  // namespace fissure::falcon
