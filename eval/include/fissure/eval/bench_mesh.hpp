#pragma once
// `fissure bench mesh`: load time of imported meshes against their size (issue 24, "loading
// linear in mesh size"). Each row is one mesh written to a temporary file and loaded the way a
// scene loads it, every stage timed separately (bench_mesh.cpp says which).
#include <nlohmann/json.hpp>

namespace fissure::eval {

struct BenchMeshOptions {
  bool quick = false;  ///< CI-sized: the ~1k and ~41k triangle tools only (no 362k rows)
};

/// Runs the benchmark and prints its table; the JSON the report reads.
[[nodiscard]] nlohmann::json run_bench_mesh(const BenchMeshOptions& options);

}  // namespace fissure::eval
