#pragma once
// `fissure bench rt`: rt_core's tick time, its SCHED_FIFO wake-up latency against cyclictest,
// and the Z-width against Colgate–Schenkel's bound (bench_rt.cpp). Prints its tables as it runs.
#include <string>

#include <nlohmann/json.hpp>

#include "fissure/rt_core/rt_thread.hpp"

namespace fissure::eval {

struct BenchRtOptions {
  double seconds = 30.0;                  ///< SCHED_FIFO run length per rate [s]
  rt::RtPolicy rt_policy = rt::RtPolicy::kEnforce;  ///< kEnforce: fail when SCHED_FIFO cannot be had
  int priority = rt::kDefaultRtPriority;  ///< SCHED_FIFO priority of both loops
  bool skip_sched_fifo = false;           ///< part 2 left out: tick time and Z-width only
};

/// Throws EvalError when the real-time set-up is refused under kEnforce or a config does not build.
[[nodiscard]] nlohmann::json run_bench_rt(const BenchRtOptions& options);

}  // namespace fissure::eval
