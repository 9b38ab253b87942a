// `fissure run SCENE [--lockstep] [--device sim|usb] [--duration S] [--out DIR] ...`
// Ctrl-C (SIGINT) asks the rt loop to ramp the force out (rt_core/safety.hpp, 0.2 s), then the
// session ends normally and still writes its trace, summary and plot. A second Ctrl-C kills.
#include "run_command.hpp"

#include <atomic>
#include <csignal>
#include <filesystem>
#include <memory>
#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>

#include "fissure/host_sim/scene_loader.hpp"
#include "session_runner.hpp"

#include "sigint_flag.hpp"

namespace fissure::app {
namespace {

struct RunOptions {
  std::string scene;
  std::string device = "sim";
  bool lockstep = false;
  double duration_s = 0.0;
  double rt_rate_hz = 1000.0;
  double host_rate_hz = 0.0;
  double settle_s = 1.0;
  std::string out_dir;
  bool no_plot = false;
  bool no_passivity_controller = false;
  bool quiet = false;
};

void run(const RunOptions& options) {
  host::SceneDescription scene;
  try {
    scene = host::load_scene(host::resolve_scene_path(options.scene));
  } catch (const std::exception& e) {
    throw CommandError(e.what());
  }
  SessionOptions session;
  session.scene = scene;
  session.device = options.device == "usb" ? SessionDevice::kUsb : SessionDevice::kSim;
  session.lockstep = options.lockstep;
  session.duration_s = options.duration_s;
  session.rt_rate_hz = options.rt_rate_hz;
  session.host_rate_hz = options.host_rate_hz;
  session.settle_s = options.settle_s;
  session.out_dir = options.out_dir.empty() ? std::filesystem::path("out") / ("run-" + scene.name) : std::filesystem::path(options.out_dir);
  session.plot = !options.no_plot;
  session.passivity_controller = !options.no_passivity_controller;
  session.status_line = !options.quiet;
  SessionOutcome outcome;
  {
    const SigintFlag sigint;
    session.interrupt = &SigintFlag::flag();
    outcome = run_session(session);
  }
  const nlohmann::json& s = outcome.summary;
  std::printf("%s %s session of '%s': %.2f s, %llu ticks (%.0f Hz), host %llu steps\n",
              s["mode"].get<std::string>().c_str(), s["device"].get<std::string>().c_str(), scene.name.c_str(),
              s["duration_s"].get<double>(), s["ticks"].get<unsigned long long>(), s["tick_rate_hz"].get<double>(),
              s["host_steps"].get<unsigned long long>());
  std::printf("  crossed nodes max %d | faults %llu | overruns %llu | force max %.2f N (limit %.1f) | energy %.4g J\n",
              s["crossed_nodes_max"].get<int>(), s["faults"].get<unsigned long long>(),
              s["overruns"].get<unsigned long long>(), s["force_max_n"].get<double>(), s["force_limit_n"].get<double>(),
              s["energy_j"].get<double>());
  std::printf("  proxy age median %.2f ms, p99 %.2f ms | host step median %.3f ms, p99 %.3f ms%s\n",
              s["proxy_age_ms"]["median"].get<double>(), s["proxy_age_ms"]["p99"].get<double>(),
              s["host_step_ms"]["median"].get<double>(), s["host_step_ms"]["p99"].get<double>(),
              SigintFlag::raised() ? " | stopped by Ctrl-C" : "");
  std::printf("  wrote %s, %s%s%s\n", outcome.trace_path.c_str(), outcome.summary_path.c_str(),
              outcome.plot_path.empty() ? "" : ", ", outcome.plot_path.c_str());
}

}  // namespace

void register_run(CommandTree& tree) {
  auto options = std::make_shared<RunOptions>();
  CLI::App* cmd = tree.root.add_subcommand(
      "run", "Run a scene end to end: Falcon (simulated or USB) + rt_core + host simulation in one process");
  cmd->add_option("scene", options->scene, "scene name (scenes/NAME.toml) or path to a scene file")->required();
  cmd->add_option("--device", options->device, "sim (SimFalcon with the scene's hand script) or usb (the real Falcon)")
      ->check(CLI::IsMember({"sim", "usb"}));
  cmd->add_flag("--lockstep", options->lockstep, "simulated time: deterministic, as fast as the CPU allows");
  cmd->add_option("--duration", options->duration_s, "seconds (default: the hand script's length; usb: until Ctrl-C)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--rate", options->rt_rate_hz, "rt tick rate [Hz] (500..10000)")->check(CLI::Range(500.0, 10000.0));
  cmd->add_option("--host-rate", options->host_rate_hz, "host step rate [Hz] (default: the scene's time step)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--settle", options->settle_s, "seconds the soft body settles before the session")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--out", options->out_dir, "output directory (default out/run-SCENE)");
  cmd->add_flag("--no-plot", options->no_plot, "skip the PNG plot");
  cmd->add_flag("--no-passivity-controller", options->no_passivity_controller,
                "diagnosis: rt_core's passivity controller off (the energy observer still runs)");
  cmd->add_flag("--quiet", options->quiet, "no status line");
  cmd->callback([options] { run(*options); });
}

}  // namespace fissure::app
