// Uniaxial compression of a cube between two frictionless rigid plates (tissue_validation.hpp).
//
// The cube stands on Bullet's static ground (top face y = 0) under a kinematic plate; both are
// frictionless, so the end faces slide freely sideways (uniaxial stress: a cube with its ends
// fixed to the plates is stiffer by its barrelling, docs/decisions.md "Tissue"). The plate is lowered to the target strain, the cube settles, the strain is
// measured on the nodes (the contacts let nodes sit within the margin of the plates, so the
// plate's travel is not the strain), the plate corrected once by the difference, and the cube
// settled again. Load: the elastic force Bullet's force object puts on the end-face nodes,
// which at equilibrium is balanced by the plates' contact impulses alone.
#include <algorithm>
#include <cmath>

#include "fissure/eval/tissue_validation.hpp"
#include "fissure/host_sim/fem_world.hpp"
#include "fissure/host_sim/tet_box.hpp"
#include "tissue_detail.hpp"

namespace fissure::eval {

using namespace tissue_detail;

host::FemMaterial validation_tissue() {
  host::FemMaterial m;
  m.youngs_modulus_pa = 5000.0;  // liver, low end (fem_material.hpp kLiverYoungsModulusPa's source)
  m.poisson_ratio = host::kTissuePoissonRatio;
  m.density_kg_per_m3 = host::kTissueDensityKgPerM3;
  return m;
}

namespace {

constexpr double kPi = 3.14159265358979323846;
// Phases of the quasi-static run, in multiples of the cube's axial period 4 L / √(E/ρ) (~37 ms
// for the 20 mm, 5 kPa cube): ramp the plate, settle, correct, settle. With the damping below
// the slowest mode decays by e^-π per period; the end speed is reported.
constexpr double kRampPeriods = 4.0;
constexpr double kSettlePeriods = 8.0;
// Plate: a box wider than the cube by far, thick enough that no node can pass it.
constexpr double kPlateHalfWidthEdges = 2.5;
constexpr double kPlateHalfThicknessEdges = 0.5;

}  // namespace

CubeCompressionResult run_cube_compression(const CubeCompressionOptions& o) {
  const double l = o.edge_m;
  const host::VolumeMesh mesh = host::make_tet_box(host::even_coordinates(-0.5 * l, 0.5 * l, o.cells_per_edge), host::even_coordinates(0.0, l, o.cells_per_edge),
                                                   host::even_coordinates(-0.5 * l, 0.5 * l, o.cells_per_edge));
  host::FemMaterial material = o.material;
  // Mass damping at twice the axial mode's angular frequency (π/2 · √(E/ρ) / L): critical for it,
  // over-critical for the higher ones; it only sets how fast the equilibrium is reached.
  const double bar_speed = std::sqrt(material.youngs_modulus_pa / material.density_kg_per_m3);
  material.mass_damping_per_s = kPi * bar_speed / l;
  host::FemWorldConfig config;
  config.has_ground = true;
  config.ground_top_y_m = 0.0;
  config.ground_friction_ratio = 0.0;
  host::FemWorld world(config);
  const int body = world.add_body(mesh, material, host::FemContact{});
  const Eigen::Vector3d plate_half(kPlateHalfWidthEdges * l, kPlateHalfThicknessEdges * l, kPlateHalfWidthEdges * l);
  const int plate = world.add_kinematic_box(plate_half, Eigen::Vector3d(0.0, l + plate_half.y(), 0.0), 0.0);

  CubeCompressionResult r;
  r.nodes_count = static_cast<int>(mesh.vertices_m.size());
  r.tetrahedra_count = static_cast<int>(mesh.tetrahedra.size());
  r.step_s = host::fem_stable_step_s(mesh, material);
  const double period_s = 4.0 * l / bar_speed;
  const auto steps_for = [&](double periods) { return static_cast<int>(std::ceil(periods * period_s / r.step_s)); };
  const std::vector<int> bottom = nodes_where(mesh, [&](const Eigen::Vector3d& p) { return p.y() <= 1e-9 * l; });
  const std::vector<int> top = nodes_where(mesh, [&](const Eigen::Vector3d& p) { return p.y() >= l * (1.0 - 1e-9); });
  const std::vector<int> mid = nodes_where(mesh, [&](const Eigen::Vector3d& p) { return std::abs(p.y() - 0.5 * l) <= 1e-9 * l; });
  const auto mean_y = [&](const std::vector<int>& nodes) {
    double s = 0.0;
    for (int n : nodes) s += world.node_position_m(body, n).y();
    return s / static_cast<double>(nodes.size());
  };
  const auto measured_strain = [&] { return 1.0 - (mean_y(top) - mean_y(bottom)) / l; };
  const auto place_plate = [&](double face_y) { world.set_box_centre(plate, Eigen::Vector3d(0.0, face_y + plate_half.y(), 0.0)); };

  const int ramp = steps_for(kRampPeriods);
  double face_y = l * (1.0 - o.target_strain);
  for (int s = 1; s <= ramp; ++s) {
    place_plate(l + (face_y - l) * s / ramp);
    world.step(r.step_s);
  }
  const int settle = steps_for(kSettlePeriods);
  for (int s = 0; s < settle; ++s) world.step(r.step_s);
  face_y -= (o.target_strain - measured_strain()) * l;
  place_plate(face_y);
  for (int s = 0; s < settle; ++s) world.step(r.step_s);
  r.steps_count = ramp + 2 * settle;

  std::vector<Eigen::Vector3d> force;
  world.elastic_forces(body, force);
  r.force_bottom_n = -sum_over(force, bottom).y();
  r.force_top_n = sum_over(force, top).y();
  r.force_n = 0.5 * (r.force_bottom_n + r.force_top_n);
  r.strain = measured_strain();
  double lo = 1e300, hi = -1e300;
  for (int n : mid) {
    lo = std::min(lo, world.node_position_m(body, n).x());
    hi = std::max(hi, world.node_position_m(body, n).x());
  }
  r.lateral_strain = (hi - lo) / l - 1.0;
  r.expected_force_n = material.youngs_modulus_pa * l * l * r.strain;
  r.relative_error = r.force_n / r.expected_force_n - 1.0;
  r.max_speed_m_per_s = world.max_node_speed_m_per_s(body);
  return r;
}

}  // namespace fissure::eval
