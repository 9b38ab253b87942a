// `fissure bench collision --json FILE [--quick | --full] [--only PART]...` (eval/bench_collision).
#include "bench_collision_command.hpp"

#include <cstdio>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "fissure/eval/bench_collision.hpp"
#include "json_file.hpp"

namespace fissure::app {

void register_bench_collision(CommandTree& tree) {
  struct Arguments {
    std::string json_path;
    std::string contact_response = "after_step";
    std::string in_solver_friction = "on";
    std::string soft_model = "shell";
    eval::BenchCollisionOptions bench;
  };
  auto a = std::make_shared<Arguments>();
  CLI::App* cmd = tree.bench.add_subcommand("collision", "Thin-body collision: tunnelling sweep (two meshes), levering and clamp-release cells, force-indentation, convergence, cost vs mesh");
  cmd->add_option("--json", a->json_path, "Write the results JSON here")->required();
  cmd->add_flag("--quick", a->bench.quick, "CI-sized run (fewer speeds and meshes, shorter holds)");
  cmd->add_flag("--full", a->bench.full, "More timing samples per cost-vs-mesh row (300 instead of 100); same cells");
  cmd->add_option("--only", a->bench.only, "Run only these parts (default: all; the report needs all)")
      ->check(CLI::IsMember({"sweep", "cells", "indentation", "scaling"}));
  cmd->add_option("--contact-response", a->contact_response,
                  "Where the paired / ray response acts in every scene: after_step (after Bullet's step) or in_solver (inside its position iterations)")
      ->check(CLI::IsMember({host::to_string(host::ContactResponse::kAfterStep), host::to_string(host::ContactResponse::kInSolver)}))
      ->capture_default_str();
  cmd->add_option("--in-solver-friction", a->in_solver_friction,
                  "In-solver plunge and levering cells: the tool's faces have friction 0.5 / 0.4 (on) or none (off)")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  cmd->add_option("--soft-model", a->soft_model,
                  "Sweep and levering cells' ball: shell (the paper's edge-link shell) or fem (the same surface filled with tetrahedra, "
                  "an FEM body on a bed, with --contact-response; with --only sweep --only cells)")
      ->check(CLI::IsMember({"shell", "fem"}))
      ->capture_default_str();
  cmd->callback([a] {
    a->bench.soft_model = a->soft_model == "fem" ? host::SoftBodyModel::kFem : host::SoftBodyModel::kShell;
    a->bench.in_solver_tool_friction = a->in_solver_friction == "on";
    a->bench.contact_response = *host::parse_contact_response(a->contact_response);  // IsMember checked the name
    write_json_file(a->json_path, eval::run_bench_collision(a->bench));
    std::printf("\nwrote %s\n", a->json_path.c_str());
  });
}

}  // namespace fissure::app
