#pragma once
// What machine a benchmark or session ran on, for every JSON the commands write (benchmarks
// must say where their figures come from): CPU count and model, kernel, arch, compiler, and
// whether assertions were compiled in.
#include <nlohmann/json.hpp>

namespace fissure::session {

[[nodiscard]] nlohmann::json machine_info();

}  // namespace fissure::session
