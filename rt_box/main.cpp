// fissure-rt: the RT box of a split deployment (docs/deployment.md). The Falcon and rt_core run
// here; the scene, its simulation and the contact proxy come from `fissure host` on the host PC
// over CAN FD or UDP. The RT box reads only the scene file's [device_mapping] and [hand] tables,
// so it needs neither Bullet nor the meshes.
//   fissure-rt --transport udp:0.0.0.0:47000 --scene spatula-sphere [--device sim|usb] [--seconds N]
// Exit codes: 0 done (or Ctrl-C, after the force ramped out), 1 a failure at run time, 2 bad usage.
// Ctrl-C: the loop ramps the force out and the program exits 0; a second Ctrl-C kills.
#include <cstdio>
#include <exception>
#include <string>

#include <CLI/CLI.hpp>

#include "fissure/session/rt_end_cli.hpp"
#include "fissure/session/session_error.hpp"
#include "fissure/session/sigint_flag.hpp"

namespace {

constexpr int kExitFailure = 1;
constexpr int kExitUsage = 2;

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"fissure-rt: the RT box of a split deployment — Falcon + rt_core, contact proxies from 'fissure host'",
               "fissure-rt"};
  app.set_version_flag("--version", "fissure-rt 0.1.0");
  fissure::session::RtEndArguments arguments;
  fissure::session::add_rt_end_options(app, arguments);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "fissure-rt: error: %s (see 'fissure-rt --help')\n", e.what());
    return kExitUsage;
  }
  try {
    fissure::session::RtEndOptions options = fissure::session::rt_end_options(arguments, "fissure-rt");
    const fissure::session::SigintFlag sigint;
    options.interrupt = &fissure::session::SigintFlag::flag();
    fissure::session::run_rt_end(options);
  } catch (const fissure::session::SessionError& e) {
    std::fprintf(stderr, "fissure-rt: error: %s\n", e.what());
    return e.bad_argument() ? kExitUsage : kExitFailure;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fissure-rt: error: %s\n", e.what());
    return kExitFailure;
  }
  return 0;
}
