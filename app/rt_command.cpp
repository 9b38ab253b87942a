// `fissure rt --transport can:IFACE|udp:HOST:PORT [--device sim|usb] [--scene SCENE] [--seconds N]`
// The rt end of a split deployment on this machine (docs/deployment.md); the RT box runs the
// same code as `fissure-rt`. Ctrl-C: the loop ramps the force out and the command exits 0; a
// second Ctrl-C kills.
#include "rt_command.hpp"

#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "fissure/config/session_tables.hpp"
#include "fissure/session/rt_end.hpp"
#include "fissure/session/sigint_flag.hpp"

namespace fissure::app {
using namespace fissure::session;  // the session library: SessionHost, run_session, LinkBridge, …
namespace {

struct RtOptions {
  std::string transport;
  std::string device = "sim";
  std::string scene;
  double rate_hz = 1000.0;
  double seconds = 0.0;
  std::string rt_policy = "best-effort";
  bool quiet = false;
};

void run(const RtOptions& options) {
  session::RtEndOptions end;
  end.transport = options.transport;
  end.usb_device = options.device == "usb";
  if (!options.scene.empty()) {
    try {
      const config::RtSessionConfig scene = config::load_rt_session_config(config::resolve_scene_path(options.scene));
      end.device_mapping = scene.device_mapping;
      end.hand = scene.hand;
    } catch (const std::exception& e) {
      throw CommandError(e.what());
    }
  }
  end.rate_hz = options.rate_hz;
  end.seconds = options.seconds;
  end.policy = options.rt_policy == "enforce" ? rt::RtPolicy::kEnforce : rt::RtPolicy::kBestEffort;
  end.status_line = !options.quiet;
  end.program = "fissure rt";
  end.interrupt = &session::SigintFlag::flag();
  session::run_rt_end(end);
}

}  // namespace

void register_rt_command(CommandTree& tree) {
  auto options = std::make_shared<RtOptions>();
  CLI::App* cmd = tree.root.add_subcommand(
      "rt", "Split deployment, rt box: Falcon + rt_core, proxies from a 'fissure host' over CAN FD or UDP");
  cmd->add_option("--transport", options->transport, "can:IFACE or udp:HOST:PORT (HOST:PORT = this box's address)")
      ->required();
  cmd->add_option("--device", options->device, "sim (SimFalcon) or usb (the real Falcon)")->check(CLI::IsMember({"sim", "usb"}));
  cmd->add_option("--scene", options->scene,
                  "scene whose device mapping (and, for sim, hand script) to use — the host must run the same scene");
  cmd->add_option("--rate", options->rate_hz, "rt tick rate [Hz] (500..10000)")->check(CLI::Range(500.0, 10000.0));
  cmd->add_option("--seconds", options->seconds, "run this long, then ramp out (default: until Ctrl-C)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--rt-policy", options->rt_policy, "best-effort (warn and run without SCHED_FIFO) or enforce (fail)")
      ->check(CLI::IsMember({"best-effort", "enforce"}));
  cmd->add_flag("--quiet", options->quiet, "no status line");
  cmd->callback([options] {
    const session::SigintFlag sigint;
    run(*options);
  });
}

}  // namespace fissure::app
