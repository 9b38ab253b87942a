#pragma once
// `fissure bench view`: what seeing the scene costs a real-time session — `fissure run` in
// real time without a view, with --frames and (with a display) with --view (bench_view.cpp).
#include <string>

#include <nlohmann/json.hpp>

namespace fissure::eval {

struct BenchViewOptions {
  std::string scene = "spatula-sphere";
  int repeats = 3;                         ///< runs per row; the table gives their median
  std::string out_dir = "out/bench-view";  ///< where the runs write traces, summaries, frames
};

/// The session rows (JSON "rows" with the benchmark's header fields); prints the table as it
/// runs. Throws EvalError when the scene does not load.
[[nodiscard]] nlohmann::json run_bench_view(const BenchViewOptions& options);

}  // namespace fissure::eval
