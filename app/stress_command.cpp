#include "stress_command.hpp"

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "fissure/eval/eval_error.hpp"
#include "fissure/eval/stress_cases.hpp"
#include "fissure/eval/stress_run.hpp"
#include "json_file.hpp"

namespace fissure::app {
namespace {

using eval::StressCase;
using eval::StressRow;

struct StressArguments {
  std::string profile = "ci";
  std::uint64_t seed = eval::kDefaultStressSeed;
  std::string json_path;
  std::vector<std::string> case_names;
  unsigned jobs = 0;  ///< 0: one per core
  bool list = false;
};

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
              r.force_max_n, r.energy_max_j, r.crossed_nodes_max, contact_percent, eval::fault_bits_text(r.fault_bits_seen).c_str(), injected,
              recovered, r.wall_s);
  if (!r.note.empty()) std::printf("    note: %s\n", r.note.c_str());
  for (const std::string& f : r.failures) std::printf("    FAIL: %s\n", f.c_str());
  std::fflush(stdout);
}

void run(const StressArguments& arguments) {
  eval::StressRunOptions options;
  options.profile = arguments.profile == "full" ? eval::StressProfile::kFull : eval::StressProfile::kCi;
  options.seed = arguments.seed;
  options.jobs = arguments.jobs;
  std::vector<StressCase> cases = eval::stress_cases();
  if (arguments.list) {
    for (const StressCase& c : cases) std::printf("%-28s %-13s %s\n", c.name.c_str(), c.group.c_str(), c.scene.c_str());
    return;
  }
  if (!arguments.case_names.empty()) {
    try {
      cases = eval::stress_cases_named(arguments.case_names);
    } catch (const eval::EvalError& e) {
      throw CLI::ValidationError("--case", e.what());
    }
  }
  std::printf("fissure stress: profile %s, base seed %llu, %zu cases, lockstep; energy bound %.3g J, recovery bound %.2g s\n",
              arguments.profile.c_str(), static_cast<unsigned long long>(arguments.seed), cases.size(), eval::kStressEnergyBound_j,
              eval::kStressRecoveryBound_s);
  print_header();
  const eval::StressRunResult result = eval::run_stress(cases, options, print_row);
  std::printf("%zu cases, %d failed, %d known failures (ci only), %.1f s\n", result.rows.size(), result.failed, result.known_failures,
              result.wall_s);
  for (const StressRow& r : result.rows) {
    if (!r.passed) {
      std::printf("  reproduce %s: fissure stress --profile %s --seed %llu --case %s\n", r.name.c_str(), arguments.profile.c_str(),
                  static_cast<unsigned long long>(arguments.seed), r.name.c_str());
    }
  }
  if (!arguments.json_path.empty()) write_json_file(arguments.json_path, eval::stress_report_json(result, options, arguments.profile));
  if (result.failed > 0) {
    throw CommandError(std::to_string(result.failed) + " of " + std::to_string(result.rows.size()) + " stress cases failed");
  }
}

}  // namespace

void register_stress(CommandTree& tree) {
  auto arguments = std::make_shared<StressArguments>();
  CLI::App* cmd = tree.root.add_subcommand(
      "stress", "Numerical stability stress harness (lockstep): adversarial input, extreme parameters, geometry, faulty links");
  cmd->add_option("--profile", arguments->profile, "ci (short cases, < 5 min in all) or full (>= 1e6 rt ticks per case)")
      ->check(CLI::IsMember({"ci", "full"}));
  cmd->add_option("--seed", arguments->seed, "base seed (each case derives its own from it and its name)");
  cmd->add_option("--json", arguments->json_path, "write the report rows as JSON to FILE");
  cmd->add_option("--case", arguments->case_names, "run only the named case(s) (repeatable)");
  cmd->add_option("--jobs", arguments->jobs,
                  "cases run side by side, each in its own process (default 0: one per core; 1: all in this process)");
  cmd->add_flag("--list", arguments->list, "list the cases and exit");
  cmd->callback([arguments] { run(*arguments); });
}

}  // namespace fissure::app
