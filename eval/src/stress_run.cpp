#include "fissure/eval/stress_run.hpp"

#include <sys/utsname.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <thread>

#include "fissure/eval/eval_error.hpp"
#include "fissure/eval/stress_parallel.hpp"
#include "fissure/eval/stress_row_json.hpp"

namespace fissure::eval {
namespace {

/// The machine the stress rows come from: core count, CPU model, kernel.
nlohmann::json machine_json() {
  nlohmann::json machine;
  machine["nproc"] = std::thread::hardware_concurrency();
  std::string cpu_model = "unknown";
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; std::getline(cpuinfo, line);) {
    if (line.rfind("model name", 0) == 0) {
      cpu_model = line.substr(line.find(':') + 2);
      break;
    }
  }
  machine["cpu_model"] = cpu_model;
  utsname names{};
  if (uname(&names) == 0) machine["kernel"] = std::string(names.sysname) + " " + names.release;
  return machine;
}

}  // namespace

std::vector<StressCase> stress_cases_named(const std::vector<std::string>& names) {
  const std::vector<StressCase> cases = stress_cases();
  std::vector<StressCase> chosen;
  for (const std::string& name : names) {
    bool found = false;
    for (const StressCase& c : cases) {
      if (c.name == name) {
        chosen.push_back(c);
        found = true;
      }
    }
    if (!found) throw EvalError("no stress case named '" + name + "' (see 'fissure stress --list')", true);
  }
  return chosen;
}

StressRunResult run_stress(const std::vector<StressCase>& cases, const StressRunOptions& options,
                           const std::function<void(const StressRow&)>& on_row) {
  const auto start = std::chrono::steady_clock::now();
  StressRunResult result;
  auto count = [&](const StressRow& row) {
    on_row(row);
    if (!row.passed && !row.known_failure) ++result.failed;
    if (row.known_failure) ++result.known_failures;
  };
  result.jobs = options.jobs == 0 ? std::max(1u, std::thread::hardware_concurrency()) : options.jobs;
  if (result.jobs == 1 || cases.size() == 1) {
    // In this process: what a debugger wants, and the same rows as the forked run.
    for (const StressCase& c : cases) {
      result.rows.push_back(run_stress_case(c, options.profile, stress_case_seed(options.seed, c.name)));
      count(result.rows.back());
    }
  } else {
    result.rows = run_stress_cases_forked(cases, options.profile, options.seed, result.jobs, count);
  }
  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

nlohmann::json stress_report_json(const StressRunResult& result, const StressRunOptions& options, const std::string& profile_name) {
  nlohmann::json out;
  out["profile"] = profile_name;
  out["base_seed"] = options.seed;
  out["energy_bound_j"] = kStressEnergyBound_j;
  out["recovery_bound_s"] = kStressRecoveryBound_s;
  out["wall_s"] = result.wall_s;
  out["jobs"] = result.jobs;
  out["failed"] = result.failed;
  out["known_failures"] = result.known_failures;
  out["machine"] = machine_json();
  out["cases"] = nlohmann::json::array();
  for (const StressRow& r : result.rows) out["cases"].push_back(stress_row_to_json(r));
  return out;
}

}  // namespace fissure::eval
