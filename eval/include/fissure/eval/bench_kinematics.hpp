#pragma once
// `fissure bench kinematics`: Falcon FK/IK/Jacobian run time against error over FK tolerances,
// against libnifalcon's scheme (bench_kinematics.cpp). Prints its table as it runs.
#include <cstddef>
#include <cstdint>

#include <nlohmann/json.hpp>

namespace fissure::eval {

/// Solves timed between two clock reads; the trajectory needs at least two batches.
inline constexpr std::size_t kKinematicsBatchSize = 64;

struct BenchKinematicsOptions {
  std::size_t samples = 20000;  ///< hand-trajectory samples at 1 kHz (≥ 2 × kKinematicsBatchSize)
  int repeats = 5;              ///< timed passes over the samples
  std::uint64_t seed = 2024;    ///< trajectory seed
};

/// Runs the benchmark; throws EvalError on too few samples or an internal inconsistency.
[[nodiscard]] nlohmann::json run_bench_kinematics(const BenchKinematicsOptions& options);

}  // namespace fissure::eval
