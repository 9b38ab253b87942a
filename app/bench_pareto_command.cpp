// `fissure bench pareto --json FILE [--scene S] [--quick] [--repeats N]` (eval/bench_pareto).
#include "bench_pareto_command.hpp"

#include <cstdio>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "fissure/eval/bench_pareto.hpp"
#include "json_file.hpp"

namespace fissure::app {

void register_bench_pareto(CommandTree& tree) {
  struct Arguments {
    std::string json_path;
    eval::BenchParetoOptions bench;
  };
  auto a = std::make_shared<Arguments>();
  CLI::App* cmd = tree.bench.add_subcommand(
      "pareto", "Host step time against force error over tool node spacing and sub-steps per host step (scripted trajectory)");
  cmd->add_option("--json", a->json_path, "write the results as JSON to FILE")->required();
  cmd->add_option("--scene", a->bench.scene, "scene name or file with a box tool (default spatula-sphere)");
  cmd->add_flag("--quick", a->bench.quick, "fewer node spacings (reference 0.75 mm instead of 0.5 mm)");
  cmd->add_option("--repeats", a->bench.repeats, "runs per row; step times pooled (default 2)")->check(CLI::Range(1, 20));
  cmd->callback([a] {
    write_json_file(a->json_path, eval::run_bench_pareto(a->bench));
    std::printf("wrote %s\n", a->json_path.c_str());
  });
}

}  // namespace fissure::app
