// Cost of one FEM host step against node count (tissue_validation.hpp): a cube of tissue resting
// on Bullet's ground under gravity, stepped as a host would (one host step of step_s, in
// `substeps` Bullet steps), wall clock per host step.
#include <algorithm>
#include <chrono>
#include <cmath>

#include <BulletSoftBody/btSoftBody.h>

#include "fissure/eval/tissue_validation.hpp"
#include "fissure/host_sim/fem_world.hpp"
#include "fissure/host_sim/tet_box.hpp"
#include "tissue_detail.hpp"

namespace fissure::eval {

StepCostResult time_fem_steps(const StepCostOptions& o) {
  const double l = o.edge_m;
  const host::VolumeMesh mesh = host::make_tet_box(host::even_coordinates(-0.5 * l, 0.5 * l, o.cells_per_edge), host::even_coordinates(0.0, l, o.cells_per_edge),
                                                   host::even_coordinates(-0.5 * l, 0.5 * l, o.cells_per_edge));
  host::FemWorldConfig config;
  config.has_ground = true;
  config.ground_friction_ratio = 0.5;
  config.gravity_world_m_per_s2 = Eigen::Vector3d(0.0, -9.81, 0.0);
  config.implicit = o.implicit;
  config.cg_max_iterations = o.cg_max_iterations;
  host::FemWorld world(config);
  const int body = world.add_body(mesh, o.material, host::FemContact{});
  StepCostResult r;
  r.nodes_count = static_cast<int>(mesh.vertices_m.size());
  r.tetrahedra_count = static_cast<int>(mesh.tetrahedra.size());
  r.substeps = o.substeps > 0 ? o.substeps : (o.implicit ? 1 : static_cast<int>(std::ceil(o.step_s / host::fem_stable_step_s(mesh, o.material))));
  const double substep_s = o.step_s / r.substeps;
  const auto host_step = [&] {
    for (int k = 0; k < r.substeps; ++k) world.step(substep_s);
  };
  for (int s = 0; s < o.warmup_steps; ++s) host_step();
  std::vector<double> ms;
  ms.reserve(static_cast<std::size_t>(o.timed_steps));
  for (int s = 0; s < o.timed_steps; ++s) {
    const auto t0 = std::chrono::steady_clock::now();
    host_step();
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(ms.begin(), ms.end());
  r.median_ms = ms[ms.size() / 2];
  r.p95_ms = ms[std::min(ms.size() - 1, static_cast<std::size_t>(0.95 * static_cast<double>(ms.size())))];
  const btSoftBody& b = world.body(body);
  for (int i = 0; i < b.m_nodes.size(); ++i) r.finite = r.finite && std::isfinite(b.m_nodes[i].m_x.x()) && std::isfinite(b.m_nodes[i].m_x.y()) && std::isfinite(b.m_nodes[i].m_x.z());
  r.max_speed_m_per_s = world.max_node_speed_m_per_s(body);
  return r;
}

}  // namespace fissure::eval
