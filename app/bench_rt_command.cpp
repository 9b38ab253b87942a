// `fissure bench rt --json FILE [--seconds N] [--rt-policy enforce|best_effort] [--priority P]
// [--skip-sched-fifo]` (eval/bench_rt).
#include "bench_rt_command.hpp"

#include <cstdio>
#include <fstream>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "fissure/eval/bench_rt.hpp"
#include "json_file.hpp"

namespace fissure::app {

void register_bench_rt(CommandTree& tree) {
  struct Arguments {
    std::string json_path;
    std::string rt_policy = "enforce";
    eval::BenchRtOptions bench;
  };
  auto a = std::make_shared<Arguments>();
  auto* command = tree.bench.add_subcommand(
      "rt", "rt_core: tick time (1/8 patches), SCHED_FIFO wake-up latency vs cyclictest, Z-width vs Colgate–Schenkel");
  command->add_option("--json", a->json_path, "write the results as JSON to FILE")->required();
  command->add_option("--seconds", a->bench.seconds, "SCHED_FIFO run length per rate (default 30)")->check(CLI::Range(1.0, 3600.0));
  command->add_option("--rt-policy", a->rt_policy, "enforce: fail if SCHED_FIFO/mlockall cannot be had (default); best_effort: warn and run")
      ->check(CLI::IsMember({"enforce", "best_effort"}));
  command->add_option("--priority", a->bench.priority, "SCHED_FIFO priority for both loops (default 80)")->check(CLI::Range(1, 99));
  command->add_flag("--skip-sched-fifo", a->bench.skip_sched_fifo, "skip part 2 (no real-time run, no cyclictest): tick time and Z-width only");
  command->callback([a] {
    // Fail before a minute of measuring, not after, when the output cannot be written.
    if (!std::ofstream(a->json_path)) throw CommandError("cannot write '" + a->json_path + "'");
    a->bench.rt_policy = a->rt_policy == "enforce" ? rt::RtPolicy::kEnforce : rt::RtPolicy::kBestEffort;
    write_json_file(a->json_path, eval::run_bench_rt(a->bench));
    std::printf("\nwrote %s\n", a->json_path.c_str());
  });
}

}  // namespace fissure::app
