// `fissure bench proxy [--json FILE] [--scene S] [--rt-rate HZ] [--host-rates HZ...] …` (eval/bench_proxy).
#include "bench_proxy_command.hpp"

#include <cstdio>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "fissure/eval/bench_proxy.hpp"
#include "json_file.hpp"

namespace fissure::app {

void register_bench_proxy(CommandTree& tree) {
  struct Arguments {
    std::string json_path;
    eval::BenchProxyOptions bench;
  };
  auto a = std::make_shared<Arguments>();
  CLI::App* cmd = tree.bench.add_subcommand(
      "proxy", "Rendered force vs an every-tick-proxy oracle on the same trajectory, over host rates");
  cmd->add_option("--json", a->json_path, "write the table as JSON here");
  cmd->add_option("--scene", a->bench.scene, "scene name or file (default spatula-sphere)");
  cmd->add_option("--rt-rate", a->bench.rt_rate_hz, "rt tick rate [Hz]; the oracle's host runs at this rate")
      ->check(CLI::Range(500.0, 10000.0));
  cmd->add_option("--host-rates", a->bench.host_rates_hz, "host rates to compare [Hz]")->expected(1, 16);
  cmd->add_option("--duration", a->bench.duration_s, "seconds (default: the hand script's length)")->check(CLI::NonNegativeNumber);
  cmd->add_option("--settle", a->bench.settle_s, "soft body settling before each run [s]")->check(CLI::NonNegativeNumber);
  cmd->add_option("--trace-dir", a->bench.trace_dir,
                  "write proxy_trace_<host_hz>hz.csv per row here (per-tick force decomposition, for diagnosis)");
  cmd->callback([a] {
    const nlohmann::json result = eval::run_bench_proxy(a->bench);
    if (a->json_path.empty()) return;
    write_json_file(a->json_path, result);
    std::printf("wrote %s\n", a->json_path.c_str());
  });
}

}  // namespace fissure::app
