#pragma once
// `fissure bench proxy`: the contact force rt_core renders at several host refresh rates
// against an every-tick-proxy oracle on the same device trajectory (bench_proxy.cpp).
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace fissure::eval {

struct BenchProxyOptions {
  std::string scene = "spatula-sphere";
  double rt_rate_hz = 2000.0;  ///< the oracle's host runs at this rate
  std::vector<double> host_rates_hz{1000.0, 500.0, 250.0, 100.0, 50.0};
  double duration_s = 0.0;     ///< 0: the hand script's length
  double settle_s = 1.0;       ///< soft body settling before each run
  std::string trace_dir;       ///< non-empty: a per-tick force decomposition CSV per row here
};

/// Runs the benchmark; prints its table as it runs. Throws EvalError (scene, host rate that
/// does not divide the rt rate, unwritable trace) or SessionError (rt config).
[[nodiscard]] nlohmann::json run_bench_proxy(const BenchProxyOptions& options);

}  // namespace fissure::eval
