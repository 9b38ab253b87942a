// `fissure bench tissue` (bench_tissue.hpp). The bounds are issue 24's: cube force within 10 % of
// E·A·ε, punch slope within 15 % of Sneddon, cantilever tip within 15 % of Euler–Bernoulli, the
// punch's change between its two finest meshes ≤ 5 %, a vessel's section ovalisation ≤ 10 % on
// the ground (its flattening against Roark's ring, with the cantilever's 15 %), and ≤ 2 ms per host step at ~4,800 nodes
// (Sase et al. 2015 ran < 20 ms at 4,807 nodes on a GPU).
#include "fissure/eval/bench_tissue.hpp"

#include <chrono>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "fissure/eval/sim_report.hpp"
#include "fissure/eval/tissue_validation.hpp"

namespace fissure::eval {

namespace {

constexpr double kCubeBound = 0.10;
constexpr double kPunchBound = 0.15;
constexpr double kCantileverBound = 0.15;
constexpr double kConvergenceBound = 0.05;
constexpr double kOvalisationBound = 0.10;
// The issue names no bound for the ring against Roark; it is a bending anchor like the
// cantilever, so it takes the cantilever's.
constexpr double kVesselRoarkBound = 0.15;
constexpr double kStepBoundMs = 2.0;
constexpr int kAnchorNodes = 4807;  // Sase et al. 2015's mesh
// The model the checks hold: the default a scene gets (fem_material.hpp).
constexpr host::FemModel kDefaultModel = host::FemMaterial{}.model;

double seconds_since(std::chrono::steady_clock::time_point t0) { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); }

nlohmann::json check(const std::string& name, double value, double bound, const std::string& what) {
  const bool pass = std::abs(value) <= bound;
  std::printf("  %-44s %+9.4f  bound ±%.3f  %s\n", name.c_str(), value, bound, pass ? "pass" : "MISS");
  return {{"name", name}, {"value", value}, {"bound", bound}, {"pass", pass}, {"measures", what}};
}

}  // namespace

nlohmann::json run_bench_tissue(const BenchTissueOptions& options) {
  nlohmann::json out;
  out["machine"] = sim_machine_info();
  out["quick"] = options.quick;
  const host::FemMaterial tissue = validation_tissue();
  out["material"] = {{"youngs_modulus_pa", tissue.youngs_modulus_pa}, {"poisson_ratio", tissue.poisson_ratio}, {"density_kg_per_m3", tissue.density_kg_per_m3}};
  nlohmann::json checks = nlohmann::json::array();

  std::printf("uniaxial compression of a 20 mm cube between frictionless plates (E = %.0f Pa, nu = %.2f):\n", tissue.youngs_modulus_pa, tissue.poisson_ratio);
  nlohmann::json cube = nlohmann::json::array();
  double cube_error = 0.0;
  for (const int cells : options.quick ? std::vector<int>{4, 6} : std::vector<int>{4, 6, 10}) {
    for (const host::FemModel model : {host::FemModel::kCorotatedSmoothed, host::FemModel::kCorotatedLinear, host::FemModel::kNeoHookean}) {
      CubeCompressionOptions o;
      o.cells_per_edge = cells;
      o.material.model = model;
      const auto t0 = std::chrono::steady_clock::now();
      const CubeCompressionResult r = run_cube_compression(o);
      const double wall = seconds_since(t0);
      const char* name = host::to_string(model);
      std::printf("  %-18s %2d cells/edge %5d nodes: strain %.4f force %.5f N (top %.5f, bottom %.5f) expected %.5f N error %+.4f lateral %.4f, %d steps of %.1f us, %.1f s\n",
                  name, cells, r.nodes_count, r.strain, r.force_n, r.force_top_n, r.force_bottom_n, r.expected_force_n, r.relative_error, r.lateral_strain, r.steps_count,
                  r.step_s * 1e6, wall);
      cube.push_back({{"model", name}, {"cells_per_edge", cells}, {"nodes", r.nodes_count}, {"tetrahedra", r.tetrahedra_count}, {"strain", r.strain},
                      {"lateral_strain", r.lateral_strain}, {"force_n", r.force_n}, {"force_top_n", r.force_top_n}, {"force_bottom_n", r.force_bottom_n},
                      {"expected_force_n", r.expected_force_n}, {"relative_error", r.relative_error}, {"steps", r.steps_count}, {"step_s", r.step_s},
                      {"max_speed_m_per_s", r.max_speed_m_per_s}, {"wall_s", wall}});
      if (std::abs(r.relative_error) > std::abs(cube_error)) cube_error = r.relative_error;
    }
  }
  out["cube"] = cube;

  std::printf("flat punch (a = 5 mm) on a block of +-16 a, 16 a deep, bottom fixed:\n");
  nlohmann::json punch = nlohmann::json::array();
  std::vector<double> slopes;
  double punch_error = 0.0;
  for (const int k : options.quick ? std::vector<int>{1, 2} : std::vector<int>{2, 3, 4}) {
    FlatPunchOptions o;
    o.cells_per_radius = k;
    const auto t0 = std::chrono::steady_clock::now();
    const FlatPunchResult r = run_flat_punch(o);
    const double wall = seconds_since(t0);
    std::printf("  %d cells/radius %6d nodes (%d under the punch): slope %.3f N/m expected %.3f N/m error %+.4f, forces", k, r.nodes_count, r.punch_nodes_count,
                r.slope_n_per_m, r.expected_slope_n_per_m, r.relative_error);
    for (double f : r.forces_n) std::printf(" %.5f", f);
    std::printf(" N, %.1f s\n", wall);
    punch.push_back({{"model", host::to_string(o.material.model)}, {"cells_per_radius", k}, {"nodes", r.nodes_count}, {"tetrahedra", r.tetrahedra_count}, {"punch_nodes", r.punch_nodes_count},
                     {"forces_n", r.forces_n}, {"slope_n_per_m", r.slope_n_per_m}, {"expected_slope_n_per_m", r.expected_slope_n_per_m},
                     {"relative_error", r.relative_error}, {"max_speed_m_per_s", r.max_speed_m_per_s}, {"wall_s", wall}});
    slopes.push_back(r.slope_n_per_m);
    punch_error = r.relative_error;  // the finest mesh's
  }
  out["punch"] = punch;
  const double convergence = slopes[slopes.size() - 1] / slopes[slopes.size() - 2] - 1.0;

  std::printf("cantilever 100 x 10 x 10 mm under gravity (E = 5 MPa, nu = %.2f):\n", tissue.poisson_ratio);
  nlohmann::json cantilever = nlohmann::json::array();
  double cantilever_error = 0.0;
  // The default (smoothed) model on three meshes, and Bullet's one-strain element beside it on
  // two: what a user of Bullet's force would get on the same meshes, at its cost.
  const std::vector<std::pair<host::FemModel, int>> cantilever_runs =
      options.quick ? std::vector<std::pair<host::FemModel, int>>{{kDefaultModel, 2}, {kDefaultModel, 3}, {host::FemModel::kCorotatedLinear, 3}}
                    : std::vector<std::pair<host::FemModel, int>>{
                          {kDefaultModel, 4}, {kDefaultModel, 6}, {kDefaultModel, 8}, {host::FemModel::kCorotatedLinear, 4}, {host::FemModel::kCorotatedLinear, 8}};
  for (const auto& [model, across] : cantilever_runs) {
    CantileverOptions o;
    o.cells_across = across;
    o.material.model = model;
    o.material.youngs_modulus_pa = 5.0e6;
    const auto t0 = std::chrono::steady_clock::now();
    const CantileverResult r = run_cantilever(o);
    const double wall = seconds_since(t0);
    std::printf("  %-18s %d cells across %5d nodes: tip %.4f mm expected %.4f mm error %+.4f, %.1f s\n", host::to_string(model), across, r.nodes_count,
                r.tip_deflection_m * 1e3, r.expected_deflection_m * 1e3, r.relative_error, wall);
    cantilever.push_back({{"model", host::to_string(model)}, {"cells_across", across}, {"nodes", r.nodes_count}, {"tetrahedra", r.tetrahedra_count}, {"tip_deflection_m", r.tip_deflection_m},
                          {"expected_deflection_m", r.expected_deflection_m}, {"relative_error", r.relative_error}, {"max_speed_m_per_s", r.max_speed_m_per_s},
                          {"wall_s", wall}});
    if (model == kDefaultModel) cantilever_error = r.relative_error;  // the default's finest mesh
  }
  out["cantilever"] = cantilever;

  const VesselOptions vessel_defaults;
  std::printf("vessel on the ground: tube R %.0f mm, wall %.0f mm, %.0f mm long, its base line held (E = %.1f MPa, nu = %.2f):\n", vessel_defaults.outer_radius_m * 1e3,
              (vessel_defaults.outer_radius_m - vessel_defaults.inner_radius_m) * 1e3, vessel_defaults.length_m * 1e3, vessel_defaults.material.youngs_modulus_pa * 1e-6,
              vessel_defaults.material.poisson_ratio);
  nlohmann::json vessel = nlohmann::json::array();
  double vessel_error = 0.0, vessel_ovalisation = 0.0;
  std::array<double, 2> vessel_roark{0.0, 0.0};  // Roark's vertical and horizontal change [m]
  using VesselRun = std::pair<host::FemModel, std::array<int, 3>>;
  const std::vector<VesselRun> vessel_runs =
      options.quick ? std::vector<VesselRun>{{kDefaultModel, {1, 16, 6}}, {kDefaultModel, {1, 32, 6}}, {host::FemModel::kCorotatedLinear, {1, 32, 6}}}
                    : std::vector<VesselRun>{{kDefaultModel, {2, 32, 12}},
                                             {kDefaultModel, {2, 64, 12}},
                                             {kDefaultModel, {3, 96, 12}},
                                             {host::FemModel::kCorotatedLinear, {2, 64, 12}}};
  for (const auto& [model, cells] : vessel_runs) {
    VesselOptions o;
    o.material.model = model;
    o.cells_through = cells[0];
    o.cells_around = cells[1];
    o.cells_along = cells[2];
    const auto t0 = std::chrono::steady_clock::now();
    const VesselResult r = run_vessel_on_ground(o);
    const double wall = seconds_since(t0);
    std::printf("  %-18s %d x %d x %d cells %5d nodes: vertical %+.4f mm (Roark %+.4f, %+.3f) horizontal %+.4f mm (Roark %+.4f, %+.3f), ovalisation %.4f, %.1f s\n",
                host::to_string(model), cells[0], cells[1], cells[2], r.nodes_count, r.vertical_change_m * 1e3, r.expected_vertical_change_m * 1e3, r.vertical_relative_error,
                r.horizontal_change_m * 1e3, r.expected_horizontal_change_m * 1e3, r.horizontal_relative_error, r.ovalisation, wall);
    vessel.push_back({{"model", host::to_string(model)}, {"cells_through", cells[0]}, {"cells_around", cells[1]}, {"cells_along", cells[2]}, {"nodes", r.nodes_count}, {"tetrahedra", r.tetrahedra_count},
                      {"vertical_change_m", r.vertical_change_m}, {"expected_vertical_change_m", r.expected_vertical_change_m},
                      {"horizontal_change_m", r.horizontal_change_m}, {"expected_horizontal_change_m", r.expected_horizontal_change_m},
                      {"vertical_relative_error", r.vertical_relative_error}, {"horizontal_relative_error", r.horizontal_relative_error},
                      {"ovalisation", r.ovalisation}, {"max_speed_m_per_s", r.max_speed_m_per_s}, {"wall_s", wall}});
    if (model != kDefaultModel) continue;
    vessel_error = r.vertical_relative_error;  // the default's finest mesh
    vessel_ovalisation = r.ovalisation;
    vessel_roark = {r.expected_vertical_change_m, r.expected_horizontal_change_m};
  }
  const double roark_ovalisation = (vessel_roark[1] - vessel_roark[0]) / (2.0 * vessel_defaults.outer_radius_m);
  std::printf("  Roark's ring (thin, plane strain): ovalisation %.4f\n", roark_ovalisation);
  out["vessel"] = vessel;
  out["vessel_roark_ovalisation"] = roark_ovalisation;

  std::printf("cost of one 1 ms host step (tissue cube of 40 mm on the ground, gravity), median / p95:\n");
  nlohmann::json cost = nlohmann::json::array();
  double anchor_ms = 1e300;
  int anchor_nodes = 0;
  // Every size with the default model; near the anchor size Bullet's own element too, so the
  // smoothing's cost stands beside it in one run.
  std::vector<std::pair<host::FemModel, int>> cost_runs;
  for (const int cells : options.quick ? std::vector<int>{9, 16} : std::vector<int>{9, 12, 16, 20, 26}) {
    cost_runs.emplace_back(kDefaultModel, cells);
    if (cells == 16) cost_runs.emplace_back(host::FemModel::kCorotatedLinear, cells);
  }
  for (const auto& [model, cells] : cost_runs) {
    for (const bool implicit : {false, true}) {
      StepCostOptions o;
      o.material.model = model;
      o.cells_per_edge = cells;
      o.implicit = implicit;
      // Implicit: one Newton iteration whose CG is capped at 10 (the cost of a usable host step,
      // not a converged one); symplectic: mass damping only, so one CG iteration is exact.
      o.cg_max_iterations = implicit ? 10 : 1;
      o.warmup_steps = cells >= 20 ? 5 : 20;
      o.timed_steps = options.quick ? 20 : (cells >= 20 ? 20 : 100);
      const StepCostResult r = time_fem_steps(o);
      const char* name = implicit ? "implicit" : "symplectic";
      std::printf("  %-18s %-10s %2d cells/edge %6d nodes %6d tetrahedra, %2d substeps: %8.3f / %8.3f ms per host step (%.0f Hz at the median)%s\n",
                  host::to_string(model), name, cells, r.nodes_count, r.tetrahedra_count, r.substeps, r.median_ms, r.p95_ms, 1e3 / r.median_ms, r.finite ? "" : "  NOT FINITE");
      cost.push_back({{"model", host::to_string(model)}, {"stepping", name}, {"cells_per_edge", cells}, {"nodes", r.nodes_count}, {"tetrahedra", r.tetrahedra_count}, {"substeps", r.substeps},
                      {"median_ms", r.median_ms}, {"p95_ms", r.p95_ms}, {"highest_rate_hz", 1e3 / r.median_ms}, {"finite", r.finite},
                      {"max_speed_m_per_s", r.max_speed_m_per_s}});
      if (model == kDefaultModel && std::abs(r.nodes_count - kAnchorNodes) <= std::abs(anchor_nodes - kAnchorNodes) && r.finite) {
        if (r.nodes_count != anchor_nodes) anchor_ms = 1e300;
        anchor_nodes = r.nodes_count;
        anchor_ms = std::min(anchor_ms, r.median_ms);  // the cheaper stepping at that size
      }
    }
  }
  out["step_cost"] = cost;

  std::printf("checks:\n");
  checks.push_back(check("cube force / (E A eps) - 1 (worst)", cube_error, kCubeBound, "uniaxial compression at 5 % strain"));
  checks.push_back(check("punch slope / Sneddon - 1 (finest)", punch_error, kPunchBound, "2 a E / (1 - nu^2)"));
  checks.push_back(check("punch slope change, two finest meshes", convergence, kConvergenceBound, "mesh convergence"));
  checks.push_back(check("cantilever tip / Euler-Bernoulli - 1 (finest)", cantilever_error, kCantileverBound, "q L^4 / (8 E I)"));
  checks.push_back(check("vessel ovalisation on the ground (finest)", vessel_ovalisation, kOvalisationBound, "(D_H - D_V) / D after settling"));
  checks.push_back(check("vessel flattening / Roark - 1 (finest)", vessel_error, kVesselRoarkBound, "-0.4674 w R^4 / (E I), ring on its base"));
  const bool cost_pass = anchor_ms <= kStepBoundMs;
  std::printf("  %-44s %9.3f  bound %.3f ms  %s (%d nodes)\n", "ms per step near 4,807 nodes", anchor_ms, kStepBoundMs, cost_pass ? "pass" : "MISS", anchor_nodes);
  checks.push_back({{"name", "ms per step near 4,807 nodes"}, {"value", anchor_ms}, {"bound", kStepBoundMs}, {"pass", cost_pass}, {"nodes", anchor_nodes}});
  out["checks"] = checks;
  return out;
}

}  // namespace fissure::eval
