#pragma once
// `fissure bench all`: every benchmark as a child process of this executable, their JSON and
// logs in one directory, then tools/report/make_report.py's plots and report (bench_all.cpp).
#include <string>
#include <vector>

namespace fissure::eval {

struct BenchAllOptions {
  std::string out_dir;             ///< the JSON, logs, plots and report.md
  std::string docs_dir;            ///< non-empty: also DOCS/benchmarks.md with DOCS/images/bench/
  bool quick = false;              ///< short runs of every benchmark
  bool report_only = false;        ///< run nothing: remake the report from the JSON in out_dir
  bool stress_full = false;        ///< also the full stress profile (opt-in child)
  std::vector<std::string> only;   ///< run only these children (names from bench_all_names())
};

/// The children's names, in run order (what --only accepts).
[[nodiscard]] std::vector<std::string> bench_all_names();

/// Runs the selected children and the report; `invocation` is recorded in bench_all.json.
/// Throws EvalError when the report cannot be made or any child failed (after the report).
void run_bench_all(const BenchAllOptions& options, const std::string& invocation);

}  // namespace fissure::eval
