#pragma once
// `fissure bench tissue`: issue 24's validation table — Bullet's deformable-world FEM against
// its analytic anchors (tissue_validation.hpp) at several mesh resolutions, and the cost of a
// host step against node count. Prints the table; returns the JSON (with each check's bound and
// verdict).
#include <nlohmann/json.hpp>

namespace fissure::eval {

struct BenchTissueOptions {
  bool quick = false;  ///< CI-sized: the coarse and middle resolutions only, fewer timed steps
};

[[nodiscard]] nlohmann::json run_bench_tissue(const BenchTissueOptions& options);

}  // namespace fissure::eval
