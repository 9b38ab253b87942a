// host_sim/src/fem_material.cpp: E, ν → Lamé, the stable Neo-Hookean's reparameterisation and
// the P-wave speed, against hand-computed values.
#include "fissure/host_sim/fem_material.hpp"

#include <cmath>

#include <gtest/gtest.h>

namespace fissure::host {
namespace {

TEST(FemMaterial, LameParametersOfBrainTissue) {
  FemMaterial m;
  m.youngs_modulus_pa = 3000.0;
  m.poisson_ratio = 0.45;
  const LameParameters l = lame_parameters(m);
  EXPECT_NEAR(l.mu_pa, 3000.0 / 2.9, 1e-9);                  // 1034.48 Pa
  EXPECT_NEAR(l.lambda_pa, 3000.0 * 0.45 / (1.45 * 0.1), 1e-9);  // 9310.34 Pa
  // Back to E and ν (the conversion Bullet's force uses for its own E, ν).
  EXPECT_NEAR(l.mu_pa * (3.0 * l.lambda_pa + 2.0 * l.mu_pa) / (l.lambda_pa + l.mu_pa), 3000.0, 1e-9);
  EXPECT_NEAR(l.lambda_pa / (2.0 * (l.lambda_pa + l.mu_pa)), 0.45, 1e-12);
}

TEST(FemMaterial, LinearModelHandsBulletTheMaterialsOwnLame) {
  FemMaterial m;
  const LameParameters l = lame_parameters(m), b = bullet_lame_parameters(m);
  EXPECT_DOUBLE_EQ(b.mu_pa, l.mu_pa);
  EXPECT_DOUBLE_EQ(b.lambda_pa, l.lambda_pa);
}

TEST(FemMaterial, NeoHookeanIsReparameterisedToMatchAtSmallStrain) {
  FemMaterial m;
  m.model = FemModel::kNeoHookean;
  const LameParameters l = lame_parameters(m), b = bullet_lame_parameters(m);
  EXPECT_DOUBLE_EQ(b.mu_pa, 4.0 / 3.0 * l.mu_pa);
  EXPECT_DOUBLE_EQ(b.lambda_pa, l.lambda_pa + 5.0 / 6.0 * l.mu_pa);
  // The stable Neo-Hookean's linearisation at F = I: shear modulus 3/4 μ_snh, Lamé λ_snh − 5/6 ·
  // (3/4 μ_snh)·… (Smith et al. 2018 §3.4): both back to the material's.
  EXPECT_NEAR(0.75 * b.mu_pa, l.mu_pa, 1e-9);
  EXPECT_NEAR(b.lambda_pa - 5.0 / 6.0 * 0.75 * b.mu_pa, l.lambda_pa, 1e-9);
}

TEST(FemMaterial, PWaveSpeed) {
  FemMaterial m;
  m.youngs_modulus_pa = 5000.0;
  m.poisson_ratio = 0.45;
  m.density_kg_per_m3 = 1040.0;
  // λ + 2μ = E (1 − ν) / ((1 + ν)(1 − 2ν)) = 18,965.5 Pa → 4.270 m/s.
  EXPECT_NEAR(p_wave_speed_m_per_s(m), std::sqrt(5000.0 * 0.55 / (1.45 * 0.1) / 1040.0), 1e-12);
}

}  // namespace
}  // namespace fissure::host
