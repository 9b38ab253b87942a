// A cantilever sagging under gravity (tissue_validation.hpp).
//
// A square beam b × b × L along +x, the nodes of its x = 0 face fixed (clamped), gravity −y on
// every node (Bullet's btDeformableGravityForce on the lumped masses). Quasi-static: Bullet's
// implicit step at a large step, as the punch (tissue_punch.cpp). Euler–Bernoulli: tip
// deflection q L⁴ / (8 E I), q = ρ g b², I = b⁴ / 12; measured as the mean downward displacement
// of the free end's nodes. Small deflection: the default material is stiff enough for ~1 % of L.
#include <cmath>

#include "fissure/eval/tissue_validation.hpp"
#include "fissure/host_sim/fem_world.hpp"
#include "fissure/host_sim/tet_box.hpp"
#include "tissue_detail.hpp"

namespace fissure::eval {

using namespace tissue_detail;

namespace {

constexpr double kGravityMPerS2 = 9.81;
// Quasi-static solve (tissue_detail.hpp settle_implicit): the default beam's first period is
// ~90 ms; the tolerance is ~1e-5 of its ~3 mm sag per second.
constexpr int kMaxSteps = 30;
constexpr double kSpeedToleranceMPerS = 3e-8;

}  // namespace

CantileverResult run_cantilever(const CantileverOptions& o) {
  const double b = o.side_m, l = o.length_m;
  const int along = static_cast<int>(std::lround(o.cells_across * l / b));
  const host::VolumeMesh mesh = host::make_tet_box(host::even_coordinates(0.0, l, along), host::even_coordinates(-0.5 * b, 0.5 * b, o.cells_across),
                                                   host::even_coordinates(-0.5 * b, 0.5 * b, o.cells_across));
  const host::FemWorldConfig config = quasi_static_config(Eigen::Vector3d(0.0, -kGravityMPerS2, 0.0));
  host::FemWorld world(config);
  const int body = world.add_body(mesh, o.material, host::FemContact{});
  world.fix_nodes(body, nodes_where(mesh, [&](const Eigen::Vector3d& p) { return p.x() <= 1e-9 * l; }));
  const std::vector<int> tip = nodes_where(mesh, [&](const Eigen::Vector3d& p) { return p.x() >= l * (1.0 - 1e-9); });

  CantileverResult r;
  r.nodes_count = static_cast<int>(mesh.vertices_m.size());
  r.tetrahedra_count = static_cast<int>(mesh.tetrahedra.size());
  r.steps_count = settle_implicit(world, body, kQuasiStaticStepS, kMaxSteps, kSpeedToleranceMPerS);
  double sag = 0.0;
  for (int n : tip) sag += mesh.vertices_m[static_cast<std::size_t>(n)][1] - world.node_position_m(body, n).y();
  r.tip_deflection_m = sag / static_cast<double>(tip.size());
  const double q = o.material.density_kg_per_m3 * kGravityMPerS2 * b * b, inertia = b * b * b * b / 12.0;
  r.expected_deflection_m = q * l * l * l * l / (8.0 * o.material.youngs_modulus_pa * inertia);
  r.relative_error = r.tip_deflection_m / r.expected_deflection_m - 1.0;
  r.max_speed_m_per_s = world.max_node_speed_m_per_s(body);
  return r;
}

}  // namespace fissure::eval
