// `fissure host SCENE --transport can:IFACE|udp:HOST:PORT [--seconds N]`
// The host PC of a split deployment (docs/deployment.md; session/host_end.hpp). Ctrl-C: stop
// stepping and exit 0 — rt_core's proxy goes stale and fades the force out on its own.
#include "host_command.hpp"

#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "fissure/host_sim/scene_loader.hpp"
#include "fissure/session/scene_plausibility.hpp"
#include "fissure/session/host_end.hpp"
#include "fissure/session/session_runner.hpp"
#include "fissure/session/sigint_flag.hpp"

namespace fissure::app {
namespace {

struct HostOptions {
  std::string scene;
  std::string transport;
  double seconds = 0.0;
  double host_rate_hz = 0.0;
  double settle_s = 1.0;
  double connect_timeout_s = 10.0;
  bool quiet = false;
};

void run(const HostOptions& options) {
  host::SceneDescription loaded;
  try {
    loaded = session::load_plausible_scene(options.scene);
  } catch (const std::exception& e) {
    throw CommandError(e.what());
  }
  session::HostEndOptions end;
  end.scene = session::scene_at_host_rate(loaded, options.host_rate_hz);
  end.transport = options.transport;
  end.seconds = options.seconds;
  end.settle_s = options.settle_s;
  end.connect_timeout_s = options.connect_timeout_s;
  end.status_line = !options.quiet;
  end.interrupt = &session::SigintFlag::flag();
  session::run_host_end(end);
}

}  // namespace

void register_host_command(CommandTree& tree) {
  auto options = std::make_shared<HostOptions>();
  CLI::App* cmd = tree.root.add_subcommand(
      "host", "Split deployment, host PC: the scene's simulation + proxy builder, feeding a 'fissure rt' over CAN FD or UDP");
  cmd->add_option("scene", options->scene, "scene name (scenes/NAME.toml) or path to a scene file")->required();
  cmd->add_option("--transport", options->transport, "can:IFACE or udp:HOST:PORT (HOST:PORT = the rt box's address)")
      ->required();
  cmd->add_option("--seconds", options->seconds, "run this long (default: until Ctrl-C)")->check(CLI::NonNegativeNumber);
  cmd->add_option("--host-rate", options->host_rate_hz, "host step rate [Hz] (default: the scene's time step)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--settle", options->settle_s, "seconds the soft body settles before connecting")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--connect-timeout", options->connect_timeout_s, "fail if rt_core has not answered within this [s]")
      ->check(CLI::PositiveNumber);
  cmd->add_flag("--quiet", options->quiet, "no status line");
  cmd->callback([options] {
    const session::SigintFlag sigint;
    run(*options);
  });
}

}  // namespace fissure::app
