// `fissure bench grasp --json FILE [--quick]` (eval/bench_grasp).
#include "bench_grasp_command.hpp"

#include <cstdio>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "fissure/eval/bench_grasp.hpp"
#include "json_file.hpp"

namespace fissure::app {

void register_bench_grasp(CommandTree& tree) {
  struct Arguments {
    std::string json_path;
    eval::BenchGraspOptions bench;
  };
  auto a = std::make_shared<Arguments>();
  CLI::App* cmd = tree.bench.add_subcommand("grasp", "Clamp grasp: lift with the shipped friction and at mu 0.05, release, pull-out force against grip force");
  cmd->add_option("--json", a->json_path, "Write the results JSON here")->required();
  cmd->add_flag("--quick", a->bench.quick, "CI-sized run (three grips, a shorter pull)");
  cmd->callback([a] {
    write_json_file(a->json_path, eval::run_bench_grasp(a->bench));
    std::printf("\nwrote %s\n", a->json_path.c_str());
  });
}

}  // namespace fissure::app
