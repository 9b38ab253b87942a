#pragma once
// `fissure bench pareto`: host step time against host force error over the tool's node spacing
// and the Bullet sub-steps per host step (bench_pareto.cpp). Prints its tables as it runs.
#include <string>

#include <nlohmann/json.hpp>

namespace fissure::eval {

struct BenchParetoOptions {
  std::string scene = "spatula-sphere";  ///< scene name or file with a box tool
  bool quick = false;                    ///< fewer node spacings (reference 0.75 mm, not 0.5 mm)
  int repeats = 2;                       ///< runs per row; step times pooled
};

/// Throws EvalError when the scene does not load or has a convex mesh tool.
[[nodiscard]] nlohmann::json run_bench_pareto(const BenchParetoOptions& options);

}  // namespace fissure::eval
