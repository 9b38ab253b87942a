// `fissure bench all --out DIR [--quick] [--docs DOCS_DIR] [--only NAME]... [--report-only] [--stress-full]`
// (eval/bench_all: every benchmark as a child process, then the report).
#include "bench_all_command.hpp"

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "fissure/eval/bench_all.hpp"

namespace fissure::app {

void register_bench_all(CommandTree& tree) {
  auto options = std::make_shared<eval::BenchAllOptions>();
  CLI::App* cmd = tree.bench.add_subcommand(
      "all", "Run every benchmark (+ stress --profile ci), write their JSON, PNG plots and report.md into --out");
  cmd->add_option("--out", options->out_dir, "directory for the JSON, logs, plots and report.md")->required();
  cmd->add_flag("--quick", options->quick, "short runs of every benchmark (for development, not for the committed report)");
  cmd->add_option("--docs", options->docs_dir,
                  "also write DOCS/benchmarks.md with its plots in DOCS/images/bench/ (the committed report: --docs docs)");
  cmd->add_option("--only", options->only, "run only the named benchmark(s); the others' earlier results in --out are kept");
  cmd->add_flag("--report-only", options->report_only, "run nothing: remake the plots and report from the JSON already in --out");
  cmd->add_flag("--stress-full", options->stress_full,
                "also run the full stress profile (>= 1e6 rt ticks per case, one process per core; ~10 min on 2 cores)");
  cmd->callback([options] {
    const std::vector<std::string> names = eval::bench_all_names();
    for (const std::string& name : options->only) {
      if (std::find(names.begin(), names.end(), name) == names.end()) {
        std::string known;
        for (const std::string& n : names) known += (known.empty() ? "" : ", ") + n;
        throw CLI::ValidationError("--only", "no benchmark named '" + name + "' (" + known + ")");
      }
    }
    std::string invocation = "fissure bench all --out " + options->out_dir;
    if (options->quick) invocation += " --quick";
    if (!options->docs_dir.empty()) invocation += " --docs " + options->docs_dir;
    for (const std::string& o : options->only) invocation += " --only " + o;
    if (options->stress_full) invocation += " --stress-full";
    eval::run_bench_all(*options, invocation);
  });
}

}  // namespace fissure::app
