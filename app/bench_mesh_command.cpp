// `fissure bench mesh --json FILE [--quick]` (eval/bench_mesh).
#include "bench_mesh_command.hpp"

#include <cstdio>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "fissure/eval/bench_mesh.hpp"
#include "json_file.hpp"

namespace fissure::app {

void register_bench_mesh(CommandTree& tree) {
  struct Arguments {
    std::string json_path;
    eval::BenchMeshOptions bench;
  };
  auto a = std::make_shared<Arguments>();
  CLI::App* cmd = tree.bench.add_subcommand("mesh", "Mesh import: load time of convex tool meshes (OBJ, STL) and soft-body meshes against their size");
  cmd->add_option("--json", a->json_path, "Write the results JSON here")->required();
  cmd->add_flag("--quick", a->bench.quick, "CI-sized run (no 362k-triangle rows)");
  cmd->callback([a] {
    write_json_file(a->json_path, eval::run_bench_mesh(a->bench));
    std::printf("\nwrote %s\n", a->json_path.c_str());
  });
}

}  // namespace fissure::app
