// `fissure bench kinematics --json FILE [--samples N] [--repeats N] [--seed S]` (eval/bench_kinematics).
#include "bench_kinematics_command.hpp"

#include <cstddef>
#include <cstdio>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "fissure/eval/bench_kinematics.hpp"
#include "json_file.hpp"

namespace fissure::app {

void register_bench_kinematics(CommandTree& tree) {
  struct Arguments {
    std::string json_path;
    eval::BenchKinematicsOptions bench;
  };
  auto a = std::make_shared<Arguments>();
  auto* command = tree.bench.add_subcommand(
      "kinematics", "Falcon FK/IK/Jacobian: run time against error over FK tolerances, vs libnifalcon's scheme");
  command->add_option("--json", a->json_path, "write the results as JSON to FILE")->required();
  command->add_option("--samples", a->bench.samples, "hand-trajectory samples at 1 kHz (default 20000)")
      ->check(CLI::Range(std::size_t{128}, std::size_t{10'000'000}));
  command->add_option("--repeats", a->bench.repeats, "timed passes over the samples (default 5)")->check(CLI::Range(1, 100));
  command->add_option("--seed", a->bench.seed, "trajectory seed (default 2024)");
  command->callback([a] {
    if (a->bench.samples < 2 * eval::kKinematicsBatchSize) throw CLI::ValidationError("--samples", "need at least 128 samples");
    write_json_file(a->json_path, eval::run_bench_kinematics(a->bench));
    std::printf("wrote %s\n", a->json_path.c_str());
  });
}

}  // namespace fissure::app
