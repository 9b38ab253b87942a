// `fissure hil latency [--device usb|sim] [--transport inproc|udp:HOST:PORT|can:IFACE] [--seconds N]
//                      [--scene SCENE] --json FILE` (eval/hil_latency): the JSON and its table.
#include "hil_latency_command.hpp"

#include <cstdio>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "fissure/eval/hil_latency.hpp"
#include "json_file.hpp"

namespace fissure::app {
namespace {

void print_table(const nlohmann::json& out) {
  std::printf("hil latency: %s over %s, %.1f s, %llu ticks (%llu overruns), %llu host steps, SCHED_FIFO %s\n",
              out["device"].get<std::string>().c_str(), out["transport"].get<std::string>().c_str(), out["seconds"].get<double>(),
              out["ticks"].get<unsigned long long>(), out["overruns"].get<unsigned long long>(), out["host_steps"].get<unsigned long long>(),
              out["rt_sched_fifo"].get<bool>() ? "yes" : "no");
  std::printf("  %-22s %10s %10s %10s %8s\n", "measure", "median", "p99", "max", "count");
  for (const char* key : {"device_round_trip_us", "rt_tick_us", "host_step_us", "proxy_age_ms", "end_to_end_ms"}) {
    const nlohmann::json& d = out[key];
    std::printf("  %-22s %10.3f %10.3f %10.3f %8llu\n", key, d["median"].get<double>(), d["p99"].get<double>(), d["max"].get<double>(),
                d["count"].get<unsigned long long>());
  }
}

}  // namespace

void register_hil_latency(CommandTree& tree) {
  struct Arguments {
    std::string json_path;
    eval::HilLatencyOptions hil;
  };
  auto a = std::make_shared<Arguments>();
  CLI::App* hil = tree.root.add_subcommand("hil", "Hardware-in-the-loop measurements");
  hil->require_subcommand(1);
  CLI::App* cmd =
      hil->add_subcommand("latency", "Latency distributions: device round trip, rt tick, host step, proxy age, end to end (JSON + table)");
  cmd->add_option("--device", a->hil.device, "sim (SimFalcon with the scene's hand) or usb (the real Falcon)")
      ->check(CLI::IsMember({"sim", "usb"}));
  cmd->add_option("--transport", a->hil.transport, "inproc, udp:HOST:PORT or can:IFACE (both ends run in this process over the carrier)");
  cmd->add_option("--scene", a->hil.scene, "scene the host simulates (default spatula-sphere)");
  cmd->add_option("--seconds", a->hil.seconds, "measurement length [s] (default 10)")->check(CLI::PositiveNumber);
  cmd->add_option("--rate", a->hil.rate_hz, "rt tick rate [Hz] (500..10000)")->check(CLI::Range(500.0, 10000.0));
  cmd->add_option("--settle", a->hil.settle_s, "seconds the soft body settles first")->check(CLI::NonNegativeNumber);
  cmd->add_option("--json", a->json_path, "output JSON file")->required();
  cmd->callback([a] {
    if (a->json_path.empty()) throw CLI::ValidationError("--json", "an output file is required");
    const nlohmann::json out = eval::run_hil_latency(a->hil);
    write_json_file(a->json_path, out);
    print_table(out);
    std::printf("  wrote %s\n", a->json_path.c_str());
    if (!eval::hil_latency_measured(out)) throw CommandError("no proxy reached rt_core: the end-to-end latency could not be measured");
  });
}

}  // namespace fissure::app
