// eval/src/tissue_cube.cpp: uniaxial compression of a cube to 5 % strain between frictionless
// plates — the force within 10 % of E·A·ε (issue 24's bound), for each elasticity model, on a
// coarse mesh (a homogeneous strain is exact on any tetrahedral mesh, smoothed or not).
#include <cmath>

#include <gtest/gtest.h>

#include "fissure/eval/tissue_validation.hpp"

namespace fissure::eval {
namespace {

constexpr double kForceBound = 0.10;  // issue 24

CubeCompressionResult coarse(host::FemModel model) {
  CubeCompressionOptions o;
  o.cells_per_edge = 4;
  o.material.model = model;
  return run_cube_compression(o);
}

TEST(TissueCube, CorotatedLinearForceIsEAEpsilon) {
  const CubeCompressionResult r = coarse(host::FemModel::kCorotatedLinear);
  EXPECT_NEAR(r.strain, 0.05, 0.005);
  EXPECT_LE(std::abs(r.relative_error), kForceBound);
  // Both plates carry the same load (equilibrium), and the sides bulge by ν ε (free ends).
  EXPECT_NEAR(r.force_top_n, r.force_bottom_n, 1e-3 * r.expected_force_n);
  EXPECT_NEAR(r.lateral_strain, 0.45 * r.strain, 0.1 * 0.45 * r.strain);
  EXPECT_LT(r.max_speed_m_per_s, 1e-4);
}

TEST(TissueCube, SmoothedStrainForceIsBulletsUnderAHomogeneousStrain) {
  const CubeCompressionResult smoothed = coarse(host::FemModel::kCorotatedSmoothed);
  const CubeCompressionResult bullets = coarse(host::FemModel::kCorotatedLinear);
  EXPECT_LE(std::abs(smoothed.relative_error), kForceBound);
  EXPECT_NEAR(smoothed.force_n, bullets.force_n, 1e-3 * bullets.force_n);
  EXPECT_NEAR(smoothed.lateral_strain, bullets.lateral_strain, 1e-3 * bullets.lateral_strain);
}

TEST(TissueCube, NeoHookeanForceIsEAEpsilon) {
  const CubeCompressionResult r = coarse(host::FemModel::kNeoHookean);
  EXPECT_NEAR(r.strain, 0.05, 0.005);
  EXPECT_LE(std::abs(r.relative_error), kForceBound);
  EXPECT_LT(r.max_speed_m_per_s, 1e-4);
}

}  // namespace
}  // namespace fissure::eval
