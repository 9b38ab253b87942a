#pragma once
// One stress report row ⇄ JSON: the `fissure stress --json` row format, and the wire format
// between a case's child process and the parent when cases run in parallel (stress_parallel.hpp).
#include <nlohmann/json.hpp>

#include "fissure/eval/stress_cases.hpp"

namespace fissure::eval {

nlohmann::json stress_row_to_json(const StressRow& row);

/// Inverse of stress_row_to_json; throws nlohmann::json::exception naming the missing field.
StressRow stress_row_from_json(const nlohmann::json& json);

}  // namespace fissure::eval
