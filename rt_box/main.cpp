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

#include "fissure/config/scene_error.hpp"
#include "fissure/config/session_tables.hpp"
#include "fissure/session/rt_end.hpp"
#include "fissure/session/session_error.hpp"
#include "fissure/session/sigint_flag.hpp"

namespace {

constexpr int kExitFailure = 1;
constexpr int kExitUsage = 2;

struct Options {
  std::string transport;
  std::string device = "sim";
  std::string scene;
  double rate_hz = 1000.0;
  double seconds = 0.0;
  std::string rt_policy = "best-effort";
  bool quiet = false;
};

void run(const Options& options) {
  using namespace fissure;
  session::RtEndOptions end;
  end.transport = options.transport;
  end.usb_device = options.device == "usb";
  if (!options.scene.empty()) {
    const config::RtSessionConfig scene = config::load_rt_session_config(config::resolve_scene_path(options.scene));
    end.device_mapping = scene.device_mapping;
    end.hand = scene.hand;
  }
  end.rate_hz = options.rate_hz;
  end.seconds = options.seconds;
  end.policy = options.rt_policy == "enforce" ? rt::RtPolicy::kEnforce : rt::RtPolicy::kBestEffort;
  end.status_line = !options.quiet;
  end.program = "fissure-rt";
  const session::SigintFlag sigint;
  end.interrupt = &session::SigintFlag::flag();
  session::run_rt_end(end);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"fissure-rt: the RT box of a split deployment — Falcon + rt_core, contact proxies from 'fissure host'",
               "fissure-rt"};
  app.set_version_flag("--version", "fissure-rt 0.1.0");
  Options options;
  app.add_option("--transport", options.transport, "can:IFACE or udp:HOST:PORT (HOST:PORT = this box's address)")->required();
  app.add_option("--device", options.device, "sim (SimFalcon) or usb (the real Falcon)")->check(CLI::IsMember({"sim", "usb"}));
  app.add_option("--scene", options.scene,
                 "scene name or file whose [device_mapping] (and, for sim, [hand]) to use — the host must run the same scene");
  app.add_option("--rate", options.rate_hz, "rt tick rate [Hz] (500..10000)")->check(CLI::Range(500.0, 10000.0));
  app.add_option("--seconds", options.seconds, "run this long, then ramp out (default: until Ctrl-C)")->check(CLI::NonNegativeNumber);
  app.add_option("--rt-policy", options.rt_policy, "best-effort (warn and run without SCHED_FIFO) or enforce (fail)")
      ->check(CLI::IsMember({"best-effort", "enforce"}));
  app.add_flag("--quiet", options.quiet, "no status line");
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
    run(options);
  } catch (const fissure::session::SessionError& e) {
    std::fprintf(stderr, "fissure-rt: error: %s\n", e.what());
    return e.bad_argument() ? kExitUsage : kExitFailure;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fissure-rt: error: %s\n", e.what());
    return kExitFailure;
  }
  return 0;
}
