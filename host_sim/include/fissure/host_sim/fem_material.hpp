#pragma once
// A soft tissue's material in SI units (issue 24) and how it maps onto the parameters of Bullet's
// deformable-world FEM forces (btDeformableLinearElasticityForce, btDeformableNeoHookeanForce) and
// of the project's smoothed-strain force built on the first (fem_smoothed_strain_force.hpp).
//
// Bullet's conventions, read in its source (bullet3 3.24, BulletSoftBody/):
// * both forces take Lamé parameters (mu, lambda) in Pa: the stress P they compute is multiplied
//   by each tetrahedron's rest volume (Tetra::m_element_measure, m³ from the node positions in m)
//   and by Dm⁻¹ (1/m), so a force in N comes out when positions are metres and node masses kg —
//   Bullet assumes no other unit;
// * btDeformableLinearElasticityForce is corotated linear elasticity: P = R(2μ ε + λ tr(ε) I)
//   with ε = sym(RᵀF) − I; its setYoungsModulus / setPoissonRatio use the textbook
//   E, ν → (μ, λ), so (μ, λ) here are the material's own;
// * btDeformableNeoHookeanForce is the *stable* Neo-Hookean of Smith et al. 2018 (energy
//   μ/2 (I_C − 3) + λ/2 (J − 1 − 3μ/4λ)² − μ/2 log(I_C + 1)): linearised at rest its shear modulus
//   is 3μ/4, so Bullet's own E, ν setters make a body 25 % too soft in shear. Smith et al. §3.4:
//   μ_snh = 4/3 μ, λ_snh = λ + 5/6 μ reproduce the linear material at small strain; used here;
// * damping: mass-proportional α [1/s] (force −α m v on each node) and, for the linear force,
//   stiffness-proportional β [s] (the elastic stress evaluated on the velocity gradient, × β).
//   The Neo-Hookean force has one damping ratio [s], the same role as β.
// * node masses are kg (btSoftBody::setMass); fem_body.cpp lumps density × ¼ tetrahedron volume.
#include <cstdint>

namespace fissure::host {

enum class FemModel : std::uint8_t {
  /// Corotated linear elasticity with smoothed strains (selective FS/NS-FEM: deviatoric strain
  /// averaged over each face's two tetrahedra, volumetric over each node's): the default, because
  /// plain linear tetrahedra lock in bending at tissue's ν (fissure bench tissue's cantilever at
  /// 4 cells across: −40 % with Bullet's force, docs/decisions.md "Tissue (issue 24)").
  kCorotatedSmoothed,
  kCorotatedLinear,  ///< btDeformableLinearElasticityForce: one constant strain per tetrahedron
  kNeoHookean,       ///< btDeformableNeoHookeanForce, reparameterised as above
};

/// The scene file's name of a model ("corotated_smoothed", "corotated_linear", "neo_hookean").
[[nodiscard]] const char* to_string(FemModel model) noexcept;

/// A volumetric soft body's material (const model: what the scene says).
struct FemMaterial {
  FemModel model = FemModel::kCorotatedSmoothed;
  double youngs_modulus_pa = 2000.0;       ///< brain ~1–3 kPa (kBrainYoungsModulusPa)
  double poisson_ratio = 0.45;             ///< nearly incompressible tissue (kTissuePoissonRatio)
  double density_kg_per_m3 = 1040.0;       ///< kTissueDensityKgPerM3
  double mass_damping_per_s = 0.0;         ///< α: −α m v per node
  double stiffness_damping_s = 0.0;        ///< β: stress of the velocity gradient × β
};

/// Defaults with their sources (docs/scenes.md repeats them).
/// Brain: 1–3 kPa (Budday et al. 2015, J. Mech. Behav. Biomed. Mater. 46:318, indentation of
/// human brain tissue, ~1.9 kPa grey, ~1.4 kPa white matter, quasi-static).
inline constexpr double kBrainYoungsModulusPa = 2000.0;
/// Liver: 5–10 kPa (Yeh et al. 2002, Ultrasound Med. Biol. 28:467, normal human liver ~5–6 kPa,
/// fibrotic higher; elastography normal ≤ 7 kPa).
inline constexpr double kLiverYoungsModulusPa = 7000.0;
/// Soft tissue is nearly incompressible: ν 0.45–0.49 in the same references; 0.45 is the low
/// end, because linear tetrahedra lock (are too stiff in bending) more as ν → 0.5 — much less
/// with the smoothed strains of kCorotatedSmoothed (docs/decisions.md, "Tissue (issue 24)").
inline constexpr double kTissuePoissonRatio = 0.45;
/// Soft tissue density ~1040 kg/m³ (ICRP 23 / ICRU 44 soft tissue, brain 1040).
inline constexpr double kTissueDensityKgPerM3 = 1040.0;

/// Plausible ranges the loader enforces (docs/scenes.md): from fat-like gels to cartilage.
inline constexpr double kYoungsModulusMinPa = 10.0;
inline constexpr double kYoungsModulusMaxPa = 1.0e7;
inline constexpr double kPoissonRatioMin = 0.0;
inline constexpr double kPoissonRatioMax = 0.49;  ///< λ grows as 1/(1 − 2ν): 0.5 is a division by zero
inline constexpr double kDensityMinKgPerM3 = 100.0;
inline constexpr double kDensityMaxKgPerM3 = 5000.0;
inline constexpr double kMassDampingMaxPerS = 1000.0;
inline constexpr double kStiffnessDampingMaxS = 0.1;

/// Lamé parameters [Pa].
struct LameParameters {
  double mu_pa = 0.0;
  double lambda_pa = 0.0;
};

/// The material's Lamé parameters: μ = E / (2(1 + ν)), λ = E ν / ((1 + ν)(1 − 2ν)).
[[nodiscard]] LameParameters lame_parameters(const FemMaterial& material) noexcept;

/// The (mu, lambda) to hand Bullet's force for `material.model` so that it reproduces E and ν at
/// small strain (the Neo-Hookean reparameterisation above; the linear force takes them as they are).
[[nodiscard]] LameParameters bullet_lame_parameters(const FemMaterial& material) noexcept;

/// P-wave speed √((λ + 2μ)/ρ) [m/s]: the explicit elastic step is stable below ~h_min / c_p.
[[nodiscard]] double p_wave_speed_m_per_s(const FemMaterial& material) noexcept;

}  // namespace fissure::host
