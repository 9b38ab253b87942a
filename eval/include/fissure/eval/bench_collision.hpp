#pragma once
// `fissure bench collision`: the thin-body collision methods measured (bench_collision.cpp
// says what each of the four parts measures). Prints its tables as it runs.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fissure/host_sim/scene_description.hpp"

namespace fissure::eval {

struct BenchCollisionOptions {
  bool quick = false;              ///< CI-sized: fewer speeds and meshes, shorter holds
  bool full = false;               ///< more timing samples per cost-vs-mesh row; the same cells
  std::vector<std::string> only;   ///< parts to run (empty: all): sweep, cells, indentation, scaling
  /// Where the paired / ray response acts in every scene the bench runs (the solver A/B of part 4
  /// stays after_step: it compares Bullet's stock solver, which cannot host the in-solver one).
  host::ContactResponse contact_response = host::ContactResponse::kAfterStep;
  /// In-solver plunge and levering cells: the tool's faces have friction 0.5 / 0.4 (true) or none.
  bool in_solver_tool_friction = true;
  /// The sweep and levering cells' ball: the paper's shell (kShell) or the same surface filled
  /// with tetrahedra, an FEM body (kFem: host::volumetric_plunge_scene, with contact_response and
  /// the in-solver friction; the sweep and levering only — Bullet's method and the clamp cell's
  /// ball are shells).
  host::SoftBodyModel soft_model = host::SoftBodyModel::kShell;
  [[nodiscard]] bool runs(const char* part) const;
};

/// Runs the benchmark; the JSON the report reads. Throws EvalError when the scene does not load.
[[nodiscard]] nlohmann::json run_bench_collision(const BenchCollisionOptions& options);

}  // namespace fissure::eval
