// `fissure rt --transport can:IFACE|udp:HOST:PORT [--device sim|usb] [--scene SCENE] [--seconds N]`
// The rt end of a split deployment on this machine (docs/deployment.md); the RT box runs the
// same code as `fissure-rt`. Ctrl-C: the loop ramps the force out and the command exits 0; a
// second Ctrl-C lets that finish, a third quits at once.
#include "rt_command.hpp"

#include <memory>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "fissure/session/rt_end_cli.hpp"
#include "fissure/session/sigint_flag.hpp"

namespace fissure::app {

void register_rt_command(CommandTree& tree) {
  auto arguments = std::make_shared<session::RtEndArguments>();
  CLI::App* cmd = tree.root.add_subcommand(
      "rt", "Split deployment, rt box: Falcon + rt_core, proxies from a 'fissure host' over CAN FD or UDP");
  session::add_rt_end_options(*cmd, *arguments);
  cmd->callback([arguments] {
    session::RtEndOptions options;
    try {
      options = session::rt_end_options(*arguments, "fissure rt");
    } catch (const config::SceneError& e) {
      throw CommandError(e.what());
    }
    const session::SigintFlag sigint;
    options.interrupt = &session::SigintFlag::flag();
    session::run_rt_end(options);
  });
}

}  // namespace fissure::app
