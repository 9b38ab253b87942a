#include "stress_command.hpp"

#include <sys/utsname.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "stress_cases.hpp"
#include "stress_parallel.hpp"
#include "stress_row_json.hpp"

namespace fissure::app {
namespace {

/// Base seed when --seed is not given: fixed, so CI runs are reproducible.
constexpr std::uint64_t kDefaultStressSeed = 7;

struct StressOptions {
  std::string profile = "ci";
  std::uint64_t seed = kDefaultStressSeed;
  std::string json_path;
  std::vector<std::string> case_names;
  unsigned jobs = 0;  ///< 0: one per core
  bool list = false;
};

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

void print_header() {
  std::printf("%-28s %-20s %9s %-5s %6s %9s %4s %8s %-27s %13s %9s %6s\n", "case", "seed", "ticks", "ok", "|F|max",
              "E max [J]", "xing", "contact%", "faults seen", "inj/onsets", "recovered", "wall");
}

void print_row(const StressRow& r) {
  char recovered[32];
  std::snprintf(recovered, sizeof recovered, "%llu/%llu", static_cast<unsigned long long>(r.recoveries_done),
                static_cast<unsigned long long>(r.recoveries_required));
  char injected[40];
  std::snprintf(injected, sizeof injected, "%llu/%llu", static_cast<unsigned long long>(r.injected_events),
                static_cast<unsigned long long>(r.fault_onsets));
  const double contact_percent = r.ticks > 0 ? 100.0 * static_cast<double>(r.contact_ticks) / static_cast<double>(r.ticks) : 0.0;
  std::printf("%-28s %-20llu %9llu %-5s %6.2f %9.2e %4d %8.1f %-27s %13s %9s %5.1fs\n", r.name.c_str(),
              static_cast<unsigned long long>(r.seed), static_cast<unsigned long long>(r.ticks), r.passed ? "pass" : (r.known_failure ? "KNOWN" : "FAIL"),
              r.force_max_n, r.energy_max_j, r.crossed_nodes_max, contact_percent, fault_bits_text(r.fault_bits_seen).c_str(), injected,
              recovered, r.wall_s);
  if (!r.note.empty()) std::printf("    note: %s\n", r.note.c_str());
  for (const std::string& f : r.failures) std::printf("    FAIL: %s\n", f.c_str());
  std::fflush(stdout);
}

void run(const StressOptions& options) {
  const StressProfile profile = options.profile == "full" ? StressProfile::kFull : StressProfile::kCi;
  std::vector<StressCase> cases = stress_cases();
  if (options.list) {
    for (const StressCase& c : cases) std::printf("%-28s %-13s %s\n", c.name.c_str(), c.group.c_str(), c.scene.c_str());
    return;
  }
  if (!options.case_names.empty()) {
    std::vector<StressCase> chosen;
    for (const std::string& name : options.case_names) {
      bool found = false;
      for (const StressCase& c : cases) {
        if (c.name == name) {
          chosen.push_back(c);
          found = true;
        }
      }
      if (!found) throw CLI::ValidationError("--case", "no stress case named '" + name + "' (see 'fissure stress --list')");
    }
    cases = std::move(chosen);
  }
  std::printf("fissure stress: profile %s, base seed %llu, %zu cases, lockstep; energy bound %.3g J, recovery bound %.2g s\n",
              options.profile.c_str(), static_cast<unsigned long long>(options.seed), cases.size(), kStressEnergyBound_j,
              kStressRecoveryBound_s);
  print_header();
  const auto start = std::chrono::steady_clock::now();
  std::vector<StressRow> rows;
  int failed = 0;
  int known = 0;
  auto count_and_print = [&](const StressRow& row) {
    print_row(row);
    if (!row.passed && !row.known_failure) ++failed;
    if (row.known_failure) ++known;
  };
  const unsigned jobs = options.jobs == 0 ? std::max(1u, std::thread::hardware_concurrency()) : options.jobs;
  if (jobs == 1 || cases.size() == 1) {
    // In this process: what a debugger wants, and the same rows as the forked run.
    for (const StressCase& c : cases) {
      rows.push_back(run_stress_case(c, profile, stress_case_seed(options.seed, c.name)));
      count_and_print(rows.back());
    }
  } else {
    rows = run_stress_cases_forked(cases, profile, options.seed, jobs, count_and_print);
  }
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("%zu cases, %d failed, %d known failures (ci only), %.1f s\n", rows.size(), failed, known, wall_s);
  for (const StressRow& r : rows) {
    if (!r.passed) {
      std::printf("  reproduce %s: fissure stress --profile %s --seed %llu --case %s\n", r.name.c_str(), options.profile.c_str(),
                  static_cast<unsigned long long>(options.seed), r.name.c_str());
    }
  }
  if (!options.json_path.empty()) {
    nlohmann::json out;
    out["profile"] = options.profile;
    out["base_seed"] = options.seed;
    out["energy_bound_j"] = kStressEnergyBound_j;
    out["recovery_bound_s"] = kStressRecoveryBound_s;
    out["wall_s"] = wall_s;
    out["jobs"] = jobs;
    out["failed"] = failed;
    out["known_failures"] = known;
    out["machine"] = machine_json();
    out["cases"] = nlohmann::json::array();
    for (const StressRow& r : rows) out["cases"].push_back(stress_row_to_json(r));
    std::ofstream file(options.json_path);
    if (!file) throw CommandError("cannot write '" + options.json_path + "'");
    file << out.dump(2) << "\n";
  }
  if (failed > 0) throw CommandError(std::to_string(failed) + " of " + std::to_string(rows.size()) + " stress cases failed");
}

}  // namespace

void register_stress(CommandTree& tree) {
  auto options = std::make_shared<StressOptions>();
  CLI::App* cmd = tree.root.add_subcommand(
      "stress", "Numerical stability stress harness (lockstep): adversarial input, extreme parameters, geometry, faulty links");
  cmd->add_option("--profile", options->profile, "ci (short cases, < 5 min in all) or full (>= 1e6 rt ticks per case)")
      ->check(CLI::IsMember({"ci", "full"}));
  cmd->add_option("--seed", options->seed, "base seed (each case derives its own from it and its name)");
  cmd->add_option("--json", options->json_path, "write the report rows as JSON to FILE");
  cmd->add_option("--case", options->case_names, "run only the named case(s) (repeatable)");
  cmd->add_option("--jobs", options->jobs,
                  "cases run side by side, each in its own process (default 0: one per core; 1: all in this process)");
  cmd->add_flag("--list", options->list, "list the cases and exit");
  cmd->callback([options] { run(*options); });
}

}  // namespace fissure::app
