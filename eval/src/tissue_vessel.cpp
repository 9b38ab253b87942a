// A vessel resting on the ground (tissue_validation.hpp): the section's ovalisation under the
// tube's own weight.
//
// A straight tube along z (make_tet_tube), the wall along its lowest generator fixed — the
// ground's line contact: the wall's bending stiffness carries the weight, so the contact stays a
// line — and gravity −y on every node. Quasi-static by Bullet's implicit step, as the cantilever
// (tissue_cantilever.cpp). Measured at the middle section, away from the free ends: the outer
// vertical diameter (top generator − bottom) and horizontal diameter (the generators at ±90°).
// Anchor: Roark's thin ring supported at its base and loaded by its own weight (Table 9.2 case
// 15; checked by Castigliano's theorem, docs/decisions.md): ΔD_V = −0.4674 w R⁴ / (E I),
// ΔD_H = +0.4292 w R⁴ / (E I), per unit length of a long tube w = ρ g t, E I = E t³ / (12 (1 − ν²)).
#include <cmath>
#include <stdexcept>

#include "fissure/eval/tissue_validation.hpp"
#include "fissure/host_sim/fem_world.hpp"
#include "fissure/host_sim/tet_box.hpp"
#include "tissue_detail.hpp"

namespace fissure::eval {

using namespace tissue_detail;

host::FemMaterial validation_vessel_wall() {
  host::FemMaterial m;
  m.youngs_modulus_pa = 5.0e5;
  m.poisson_ratio = host::kTissuePoissonRatio;
  m.density_kg_per_m3 = host::kTissueDensityKgPerM3;
  return m;
}

namespace {

constexpr double kGravityMPerS2 = 9.81;
// Roark, Table 9.2 case 15 (ring supported at the base, own weight).
constexpr double kRoarkVertical = -0.4674;
constexpr double kRoarkHorizontal = 0.4292;
// Quasi-static solve, as the cantilever's: the ring's first bending period is ~20 ms for the
// default wall; the tolerance is ~1e-5 of its ~1 mm change per second.
constexpr int kMaxSteps = 30;
constexpr double kSpeedToleranceMPerS = 1e-8;

}  // namespace

VesselResult run_vessel_on_ground(const VesselOptions& o) {
  if (o.cells_around % 4 != 0) throw std::invalid_argument("run_vessel_on_ground: cells_around must be a multiple of 4 (generators at 0, 90, 180, 270 degrees)");
  host::TetTube tube;
  tube.inner_radius_m = o.inner_radius_m;
  tube.outer_radius_m = o.outer_radius_m;
  tube.length_m = o.length_m;
  tube.cells_through = o.cells_through;
  tube.cells_around = o.cells_around;
  tube.cells_along = o.cells_along;
  const host::VolumeMesh mesh = host::make_tet_tube(tube);
  const host::FemWorldConfig config = quasi_static_config(Eigen::Vector3d(0.0, -kGravityMPerS2, 0.0));
  host::FemWorld world(config);
  const int body = world.add_body(mesh, o.material, host::FemContact{});
  // make_tet_tube's numbering: vertex (i radial, j around from the lowest generator, k along).
  const int nr = o.cells_through + 1, nt = o.cells_around;
  const auto vertex = [&](int i, int j, int k) { return (k * nt + j) * nr + i; };
  // The whole wall along the lowest generator: a line of outer nodes alone is a hinge the tube
  // balances on and tips over about; by symmetry the ring's base section does not turn, so
  // holding it through the wall adds no moment the ring would not carry.
  std::vector<int> ground_line;
  for (int k = 0; k <= o.cells_along; ++k) {
    for (int i = 0; i < nr; ++i) ground_line.push_back(vertex(i, 0, k));
  }
  world.fix_nodes(body, ground_line);

  VesselResult r;
  r.nodes_count = static_cast<int>(mesh.vertices_m.size());
  r.tetrahedra_count = static_cast<int>(mesh.tetrahedra.size());
  const int mid = o.cells_along / 2;
  const int bottom = vertex(nr - 1, 0, mid), right = vertex(nr - 1, nt / 4, mid), top = vertex(nr - 1, nt / 2, mid), left = vertex(nr - 1, 3 * nt / 4, mid);
  const auto rest = [&](int v) { return e3(mesh.vertices_m[static_cast<std::size_t>(v)]); };
  const double rest_vertical = rest(top).y() - rest(bottom).y(), rest_horizontal = rest(right).x() - rest(left).x();
  r.steps_count = settle_implicit(world, body, kQuasiStaticStepS, kMaxSteps, kSpeedToleranceMPerS);
  const double vertical = world.node_position_m(body, top).y() - world.node_position_m(body, bottom).y();
  const double horizontal = world.node_position_m(body, right).x() - world.node_position_m(body, left).x();
  r.vertical_change_m = vertical - rest_vertical;
  r.horizontal_change_m = horizontal - rest_horizontal;
  r.ovalisation = (horizontal - vertical) / rest_vertical;

  const double t = o.outer_radius_m - o.inner_radius_m, radius = 0.5 * (o.outer_radius_m + o.inner_radius_m);
  const double w = o.material.density_kg_per_m3 * kGravityMPerS2 * t;
  const double nu = o.material.poisson_ratio;
  const double bending = o.material.youngs_modulus_pa * t * t * t / (12.0 * (1.0 - nu * nu));
  const double scale = w * radius * radius * radius * radius / bending;
  r.expected_vertical_change_m = kRoarkVertical * scale;
  r.expected_horizontal_change_m = kRoarkHorizontal * scale;
  r.vertical_relative_error = r.vertical_change_m / r.expected_vertical_change_m - 1.0;
  r.horizontal_relative_error = r.horizontal_change_m / r.expected_horizontal_change_m - 1.0;
  r.max_speed_m_per_s = world.max_node_speed_m_per_s(body);
  return r;
}

}  // namespace fissure::eval
