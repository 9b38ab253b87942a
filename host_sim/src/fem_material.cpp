// SI material → Bullet's Lamé parameters (fem_material.hpp).
#include "fissure/host_sim/fem_material.hpp"

#include <cmath>

namespace fissure::host {

const char* to_string(FemModel model) noexcept {
  switch (model) {
    case FemModel::kCorotatedSmoothed: return "corotated_smoothed";
    case FemModel::kCorotatedLinear: return "corotated_linear";
    case FemModel::kNeoHookean: return "neo_hookean";
  }
  return "unknown";
}

LameParameters lame_parameters(const FemMaterial& m) noexcept {
  const double e = m.youngs_modulus_pa, nu = m.poisson_ratio;
  return {e / (2.0 * (1.0 + nu)), e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))};
}

LameParameters bullet_lame_parameters(const FemMaterial& m) noexcept {
  const LameParameters l = lame_parameters(m);
  if (m.model == FemModel::kNeoHookean) return {4.0 / 3.0 * l.mu_pa, l.lambda_pa + 5.0 / 6.0 * l.mu_pa};
  return l;
}

double p_wave_speed_m_per_s(const FemMaterial& m) noexcept {
  const LameParameters l = lame_parameters(m);
  return std::sqrt((l.lambda_pa + 2.0 * l.mu_pa) / m.density_kg_per_m3);
}

}  // namespace fissure::host
