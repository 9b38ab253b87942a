// `fissure bench tissue --json FILE [--quick]` (eval/bench_tissue).
#include "bench_tissue_command.hpp"

#include <cstdio>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "fissure/eval/bench_tissue.hpp"
#include "json_file.hpp"

namespace fissure::app {

void register_bench_tissue(CommandTree& tree) {
  struct Arguments {
    std::string json_path;
    eval::BenchTissueOptions bench;
  };
  auto a = std::make_shared<Arguments>();
  CLI::App* cmd = tree.bench.add_subcommand("tissue", "Tissue FEM: Bullet's deformable-world FEM against analytic anchors (cube, Sneddon punch, cantilever) and step cost against node count");
  cmd->add_option("--json", a->json_path, "Write the results JSON here")->required();
  cmd->add_flag("--quick", a->bench.quick, "CI-sized run (coarse and middle meshes only)");
  cmd->callback([a] {
    write_json_file(a->json_path, eval::run_bench_tissue(a->bench));
    std::printf("\nwrote %s\n", a->json_path.c_str());
  });
}

}  // namespace fissure::app
