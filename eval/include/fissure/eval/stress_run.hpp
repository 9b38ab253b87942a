#pragma once
// A `fissure stress` run: the chosen cases, in this process or side by side in child processes
// (stress_parallel.hpp), and the report JSON `fissure stress --json` writes.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fissure/eval/stress_cases.hpp"

namespace fissure::eval {

/// Base seed when none is given: fixed, so CI runs are reproducible.
inline constexpr std::uint64_t kDefaultStressSeed = 7;

struct StressRunOptions {
  StressProfile profile = StressProfile::kCi;
  std::uint64_t seed = kDefaultStressSeed;
  unsigned jobs = 0;  ///< cases side by side; 0: one per core, 1: all in this process
};

struct StressRunResult {
  std::vector<StressRow> rows;  ///< in case order
  int failed = 0;               ///< failed rows that are not known failures
  int known_failures = 0;
  unsigned jobs = 0;            ///< as run (0 resolved to the core count)
  double wall_s = 0.0;
};

/// The cases named in `names`, in that order; throws EvalError(bad_argument) naming the first
/// name that is not a case.
[[nodiscard]] std::vector<StressCase> stress_cases_named(const std::vector<std::string>& names);

/// Runs `cases`; `on_row` is called in case order as each row (and every row before it) is in.
[[nodiscard]] StressRunResult run_stress(const std::vector<StressCase>& cases, const StressRunOptions& options,
                                         const std::function<void(const StressRow&)>& on_row);

/// The report `fissure stress --json` writes; `profile_name` as given on the command line.
[[nodiscard]] nlohmann::json stress_report_json(const StressRunResult& result, const StressRunOptions& options,
                                                const std::string& profile_name);

}  // namespace fissure::eval
