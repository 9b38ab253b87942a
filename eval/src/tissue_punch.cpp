// A rigid flat cylindrical punch indenting a thick block (tissue_validation.hpp).
//
// The block is a graded structured mesh (tet_box.hpp): even cells of a / k within 1.5 a of the
// punch's axis and below the surface, growing outwards to ±W and down to depth W. Its bottom face
// is fixed; the punch is the set of top-face nodes within the radius a (r ≤ a), fixed and moved
// down together (a bonded rigid punch: for ν → 0.5 bonded and frictionless punches coincide, and
// at ν = 0.45 they differ by well under 1 % — Spence 1975); the side faces are free. Each depth is
// a quasi-static solve with Bullet's implicit (backward Euler, Newton) step at a large step, which
// the fixed-node problem allows (fem_world.hpp). Force at each depth: minus the sum of the
// elastic force on the punch nodes; the slope is the least-squares line through the depths.
// Sneddon (1965): F = 2 a E* d, E* = E / (1 − ν²), for a half-space; the block is finite (W =
// 16 a by default), which makes it stiffer — part of what the bound has to hold.
#include <cmath>

#include "fissure/eval/tissue_validation.hpp"
#include "fissure/host_sim/fem_world.hpp"
#include "fissure/host_sim/tet_box.hpp"
#include "tissue_detail.hpp"

namespace fissure::eval {

using namespace tissue_detail;

namespace {

// The even region's half width and depth, in punch radii.
constexpr double kFineRadii = 1.5;
// Quasi-static solve per depth (tissue_detail.hpp settle_implicit): the block's slowest period
// is ~0.1 s at 5 kPa; the tolerance is 1e-3 of the smallest depth per second.
constexpr int kMaxStepsPerDepth = 30;
constexpr double kSpeedToleranceMPerS = 1e-7;

}  // namespace

FlatPunchResult run_flat_punch(const FlatPunchOptions& o) {
  const double a = o.punch_radius_m, w = o.block_half_width_radii * a, h = a / o.cells_per_radius;
  const std::vector<double> xz = host::graded_coordinates(kFineRadii * a, h, w, o.growth);
  const host::VolumeMesh mesh = host::make_tet_box(xz, host::graded_coordinates_down(-w, 0.0, kFineRadii * a, h, o.growth), xz);
  const host::FemWorldConfig config = quasi_static_config();
  host::FemWorld world(config);
  const int body = world.add_body(mesh, o.material, host::FemContact{});
  const std::vector<int> punch = nodes_where(mesh, [&](const Eigen::Vector3d& p) {
    return std::abs(p.y()) <= 1e-9 * w && p.x() * p.x() + p.z() * p.z() <= a * a * (1.0 + 1e-9);
  });
  const std::vector<int> base = nodes_where(mesh, [&](const Eigen::Vector3d& p) { return p.y() <= -w * (1.0 - 1e-9); });
  world.fix_nodes(body, punch);
  world.fix_nodes(body, base);

  FlatPunchResult r;
  r.nodes_count = static_cast<int>(mesh.vertices_m.size());
  r.tetrahedra_count = static_cast<int>(mesh.tetrahedra.size());
  r.punch_nodes_count = static_cast<int>(punch.size());
  std::vector<Eigen::Vector3d> force;
  for (double d : o.depths_m) {
    for (int n : punch) {
      const Vec3& p = mesh.vertices_m[static_cast<std::size_t>(n)];
      world.move_fixed_node(body, n, Eigen::Vector3d(p[0], p[1] - d, p[2]));
    }
    r.steps_count += settle_implicit(world, body, kQuasiStaticStepS, kMaxStepsPerDepth, kSpeedToleranceMPerS);
    world.elastic_forces(body, force);
    r.forces_n.push_back(sum_over(force, punch).y());  // the block pushes the punch up: + y
  }
  // Least-squares slope through the origin-free line F = s d + c.
  const double n = static_cast<double>(o.depths_m.size());
  double sd = 0, sf = 0, sdd = 0, sdf = 0;
  for (std::size_t i = 0; i < o.depths_m.size(); ++i) {
    sd += o.depths_m[i];
    sf += r.forces_n[i];
    sdd += o.depths_m[i] * o.depths_m[i];
    sdf += o.depths_m[i] * r.forces_n[i];
  }
  r.slope_n_per_m = (n * sdf - sd * sf) / (n * sdd - sd * sd);
  const double nu = o.material.poisson_ratio;
  r.expected_slope_n_per_m = 2.0 * a * o.material.youngs_modulus_pa / (1.0 - nu * nu);
  r.relative_error = r.slope_n_per_m / r.expected_slope_n_per_m - 1.0;
  r.max_speed_m_per_s = world.max_node_speed_m_per_s(body);
  return r;
}

}  // namespace fissure::eval
