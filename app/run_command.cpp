// `fissure run SCENE [--lockstep] [--device sim|usb] [--duration S] [--out DIR] ...`
// Ctrl-C (SIGINT) asks the rt loop to ramp the force out (rt_core/safety.hpp, 0.2 s), then the
// session ends normally and still writes its trace, summary and plot; a second Ctrl-C lets that
// finish, a third quits at once. Outputs reach their names only when complete
// (session/output_staging.hpp).
#include "run_command.hpp"

#include <atomic>
#include <csignal>
#include <filesystem>
#include <memory>
#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "fissure/host_sim/scene_loader.hpp"
#include "fissure/session/scene_plausibility.hpp"
#include "fissure/session/session_runner.hpp"

#include "fissure/session/sigint_flag.hpp"

namespace fissure::app {
using namespace fissure::session;  // the session library: SessionHost, run_session, LinkBridge, …
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
  bool view = false;
  std::string frames_dir;
  int frame_every = 10;
  int width_px = 960;
  int height_px = 720;
  std::string method;
  std::string record_path;
  std::string replay_path;
};

void run(const RunOptions& options) {
  host::SceneDescription scene;
  try {
    scene = load_plausible_scene(options.scene);
  } catch (const std::exception& e) {
    throw CommandError(e.what());
  }
  if (!options.method.empty()) scene.simulation.collision_method = *host::parse_collision_method(options.method);
  SessionOptions session;
  session.scene = scene;
  session.record_path = options.record_path;
  session.replay_path = options.replay_path;
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
  session.view = options.view;
  session.frames_dir = options.frames_dir;
  session.frame_every = options.frame_every;
  session.frame_width_px = options.width_px;
  session.frame_height_px = options.height_px;
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
  std::printf("  tool re-seats %llu (device position discontinuities) | soft volume min %.2f of settled%s\n",
              s["tool_reseats"].get<unsigned long long>(), s["soft_volume_ratio_min"].get<double>(),
              s["soft_everted"].get<bool>() ? " — SOFT BODY TURNED INSIDE OUT" : "");
  std::printf("  proxy age median %.2f ms, p99 %.2f ms | host step median %.3f ms, p99 %.3f ms%s\n",
              s["proxy_age_ms"]["median"].get<double>(), s["proxy_age_ms"]["p99"].get<double>(),
              s["host_step_ms"]["median"].get<double>(), s["host_step_ms"]["p99"].get<double>(),
              SigintFlag::raised() ? " | stopped by Ctrl-C" : "");
  if (s.contains("view")) {
    const nlohmann::json& v = s["view"];
    if (v["window"]["open"].get<bool>()) {
      std::printf("  view: %llu frames drawn\n", v["window"]["frames_drawn"].get<unsigned long long>());
    }
    if (v.contains("frames")) {
      const nlohmann::json& fr = v["frames"];
      std::printf("  frames: %llu written to %s (every %d host steps, %llu dropped), %.1f ms per frame median; capture+publish median %.1f us\n",
                  fr["written"].get<unsigned long long>(), fr["dir"].get<std::string>().c_str(), fr["every_host_steps"].get<int>(),
                  fr["dropped"].get<unsigned long long>(), fr["frame_ms"]["median"].get<double>(),
                  v["capture_publish_us"]["median"].get<double>());
    }
  }
  if (s.contains("replay")) {
    const nlohmann::json& r = s["replay"];
    std::printf("  replayed %s (recorded from %s on '%s'): %llu records, %llu exchanges, %llu commands differing from the recorded ones\n",
                r["file"].get<std::string>().c_str(), r["recorded_device"].get<std::string>().c_str(),
                r["recorded_scene"].get<std::string>().c_str(), r["records"].get<unsigned long long>(),
                r["exchanges"].get<unsigned long long>(), r["commands_differing"].get<unsigned long long>());
  }
  if (s.contains("recording")) {
    std::printf("  recorded %llu device exchanges to %s\n", s["recording"]["exchanges"].get<unsigned long long>(),
                s["recording"]["file"].get<std::string>().c_str());
  }
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
  cmd->add_option("--method", options->method, "collision method: paired | ray | bullet (default: the scene's)")
      ->check(CLI::IsMember({"paired", "ray", "bullet"}));
  cmd->add_option("--record", options->record_path,
                  "keep every device exchange (encoder counts, buttons, timestamps as Falcon packets) in FILE, for --replay");
  cmd->add_option("--replay", options->replay_path,
                  "the device answers from a recording made with --record (any --rate, --method, --host-rate; --lockstep reproduces it)");
  cmd->add_flag("--lockstep", options->lockstep, "simulated time: deterministic, as fast as the CPU allows");
  cmd->add_option("--duration", options->duration_s, "seconds, at most 86400 (default: the hand script's length; usb: until Ctrl-C)")
      ->check(CLI::Validator([](std::string& text) { return check_seconds_at_most(text, 86400.0, "one day per session"); }, "0..86400"));
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
  cmd->add_flag("--view", options->view,
                "live 3-D window (GLFW, own thread, never blocks the host or rt); without a display it says so and runs on");
  cmd->add_option("--frames", options->frames_dir,
                  "write PNG frames here (headless OpenGL, own thread; real time drops frames it has no time for, lockstep writes each)");
  cmd->add_option("--frame-every", options->frame_every, "host steps between frames")->check(CLI::PositiveNumber);
  cmd->add_option("--width", options->width_px, "frame / window width [px]")->check(CLI::Range(64, 4096));
  cmd->add_option("--height", options->height_px, "frame / window height [px]")->check(CLI::Range(64, 4096));
  cmd->callback([options] { run(*options); });
}

}  // namespace fissure::app
