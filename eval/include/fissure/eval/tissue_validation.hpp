#pragma once
// Issue 24's tissue validations: Bullet's deformable-world FEM (host_sim fem_world.hpp) against
// analytic anchors, each a quasi-static run of a structured tetrahedral specimen (tet_box.hpp)
// with its boundary conditions set through Bullet — fixed (zero-mass) nodes moved kinematically,
// or frictionless contact with rigid plates — and its load read as a reaction: the sum of Bullet's
// own elastic force on the constrained nodes at equilibrium (FemWorld::elastic_forces).
// One stage per file: tissue_cube.cpp, tissue_punch.cpp, tissue_cantilever.cpp,
// tissue_step_cost.cpp; `fissure bench tissue` (bench_tissue.cpp) runs them at several
// resolutions, the tests (tests/eval/tissue_*_test.cpp) on coarse meshes.
#include <vector>

#include "fissure/host_sim/fem_material.hpp"

namespace fissure::eval {

/// The tissue the validations use unless told otherwise: liver-like (fem_material.hpp's sources).
[[nodiscard]] host::FemMaterial validation_tissue();
/// A vessel wall for the ovalisation check: E 0.5 MPa (arterial wall at low strain, elastin-
/// dominated: ~0.3–1 MPa, docs/scenes.md), ν 0.45, 1040 kg/m³.
[[nodiscard]] host::FemMaterial validation_vessel_wall();

// ---- Uniaxial compression of a cube between two frictionless rigid plates (tissue_cube.cpp).
struct CubeCompressionOptions {
  int cells_per_edge = 6;
  double edge_m = 0.02;
  double target_strain = 0.05;
  host::FemMaterial material = validation_tissue();
};
struct CubeCompressionResult {
  int nodes_count = 0;
  int tetrahedra_count = 0;
  int steps_count = 0;
  double step_s = 0.0;
  double strain = 0.0;               ///< 1 − (mean top y − mean bottom y) / edge, measured on the nodes
  double lateral_strain = 0.0;       ///< mid-height width / edge − 1
  double force_n = 0.0;              ///< mean of the two plates' reactions
  double force_bottom_n = 0.0;       ///< −Σ elastic f_y on the bottom-face nodes
  double force_top_n = 0.0;          ///< Σ elastic f_y on the top-face nodes
  double expected_force_n = 0.0;     ///< E · A · strain (A = edge², engineering)
  double relative_error = 0.0;       ///< force / expected − 1
  double max_speed_m_per_s = 0.0;    ///< at the end: how close to equilibrium
};
[[nodiscard]] CubeCompressionResult run_cube_compression(const CubeCompressionOptions& options);

// ---- A rigid flat cylindrical punch on a thick block (tissue_punch.cpp): Sneddon's
// F = 2 a E d / (1 − ν²) for a half-space.
struct FlatPunchOptions {
  int cells_per_radius = 2;          ///< even cells of a / this under and around the punch
  double punch_radius_m = 0.005;
  double block_half_width_radii = 16.0;  ///< block: ±this × a in x and z, this × a deep
  double growth = 1.3;               ///< cell growth per cell away from the punch
  std::vector<double> depths_m{0.0001, 0.0002};
  host::FemMaterial material = validation_tissue();
};
struct FlatPunchResult {
  int nodes_count = 0;
  int tetrahedra_count = 0;
  int punch_nodes_count = 0;
  int steps_count = 0;
  std::vector<double> forces_n;      ///< reaction on the punch nodes at each depth
  double slope_n_per_m = 0.0;        ///< least-squares slope of force against depth (through the depths)
  double expected_slope_n_per_m = 0.0;  ///< 2 a E / (1 − ν²)
  double relative_error = 0.0;
  double max_speed_m_per_s = 0.0;
};
[[nodiscard]] FlatPunchResult run_flat_punch(const FlatPunchOptions& options);

// ---- A cantilever sagging under gravity (tissue_cantilever.cpp): Euler–Bernoulli tip
// deflection q L⁴ / (8 E I) of a square section b × b, clamped at x = 0.
struct CantileverOptions {
  int cells_across = 3;              ///< cells across the section; along the length: × length / side
  double length_m = 0.1;
  double side_m = 0.01;
  host::FemMaterial material = validation_tissue();
};
struct CantileverResult {
  int nodes_count = 0;
  int tetrahedra_count = 0;
  int steps_count = 0;
  double tip_deflection_m = 0.0;     ///< mean downward displacement of the free end's nodes
  double expected_deflection_m = 0.0;
  double relative_error = 0.0;
  double max_speed_m_per_s = 0.0;
};
[[nodiscard]] CantileverResult run_cantilever(const CantileverOptions& options);

// ---- A vessel resting on the ground (tissue_vessel.cpp): the section's ovalisation under the
// tube's own weight, against Roark's thin ring supported at its base (Table 9.2 case 15):
// ΔD_V = −0.4674 w R⁴ / (E I), ΔD_H = +0.4292 w R⁴ / (E I), per unit length of a long tube
// w = ρ g t and E I = E t³ / (12 (1 − ν²)) (plane strain), R the mean radius.
struct VesselOptions {
  double inner_radius_m = 0.013;     ///< the shipped vessel's 15 mm outer radius, a 2 mm wall
  double outer_radius_m = 0.015;
  double length_m = 0.06;
  int cells_through = 2;
  int cells_around = 32;
  int cells_along = 12;
  host::FemMaterial material = validation_vessel_wall();
};
struct VesselResult {
  int nodes_count = 0;
  int tetrahedra_count = 0;
  int steps_count = 0;
  double vertical_change_m = 0.0;    ///< outer vertical diameter at mid-length, settled − rest (< 0: flattened)
  double horizontal_change_m = 0.0;  ///< outer horizontal diameter, settled − rest (> 0: spread)
  double expected_vertical_change_m = 0.0;
  double expected_horizontal_change_m = 0.0;
  double vertical_relative_error = 0.0;    ///< measured / Roark − 1
  double horizontal_relative_error = 0.0;
  double ovalisation = 0.0;          ///< (D_H − D_V) / D_rest at mid-length, settled
  double max_speed_m_per_s = 0.0;
};
[[nodiscard]] VesselResult run_vessel_on_ground(const VesselOptions& options);

// ---- Cost of one host step against node count (tissue_step_cost.cpp): a block resting on the
// ground under gravity.
struct StepCostOptions {
  int cells_per_edge = 10;
  double edge_m = 0.04;
  double step_s = 1e-3;
  int warmup_steps = 20;
  int timed_steps = 200;
  /// Bullet's implicit step (1 Newton iteration, stable at the host step for any mesh) instead of
  /// the symplectic one (explicit elasticity: unstable once the step exceeds ~h_min / c_p).
  bool implicit = false;
  /// Bullet steps per host step; 0: as many as the symplectic step's stability needs
  /// (host::fem_stable_step_s: Courant 0.3·√2 of the thinnest tetrahedron / c_p), 1 for the implicit step.
  int substeps = 0;
  /// CG cap per Bullet step (FemWorldConfig): measured, the CG runs to its cap whatever its
  /// tolerance, and with mass damping only the system is diagonal (one iteration is exact).
  int cg_max_iterations = 1;
  host::FemMaterial material = validation_tissue();
};
struct StepCostResult {
  int nodes_count = 0;
  int tetrahedra_count = 0;
  double median_ms = 0.0;
  double p95_ms = 0.0;
  bool finite = true;                ///< every node finite after the run
  double max_speed_m_per_s = 0.0;    ///< after the run: a resting block is near 0 when the step is stable
  int substeps = 1;                  ///< Bullet steps per host step, as run
};
[[nodiscard]] StepCostResult time_fem_steps(const StepCostOptions& options);

}  // namespace fissure::eval
