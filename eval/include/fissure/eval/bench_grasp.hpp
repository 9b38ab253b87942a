#pragma once
// `fissure bench grasp`: issue 23's grasp table — lift with the shipped friction (the vessel rises
// with the jaws, no node slides along a jaw during the hold, the opened jaws let go), the same lift
// at a slippery μ (it slips out), and the pull-out force of an end-anchored vessel against the
// grip force over five grips (Coulomb: slope 2μ). Prints the table; returns the JSON with each
// target's bound and verdict.
#include <nlohmann/json.hpp>

namespace fissure::eval {

struct BenchGraspOptions {
  bool quick = false;  ///< CI-sized: three grips instead of five, a shorter pull
};

[[nodiscard]] nlohmann::json run_bench_grasp(const BenchGraspOptions& options);

}  // namespace fissure::eval
