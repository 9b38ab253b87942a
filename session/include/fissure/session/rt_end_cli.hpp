#pragma once
// The rt end's command line, one definition for its two programs: `fissure rt` (the
// workstation's fissure) and `fissure-rt` (the RT box's). Header-only so that the session
// library itself needs no CLI11; each program includes it where it registers its options.
#include <string>

#include <CLI/CLI.hpp>

#include "fissure/config/session_tables.hpp"
#include "fissure/session/rt_end.hpp"

namespace fissure::session {

/// What the user typed, before the scene file is read.
struct RtEndArguments {
  std::string transport;
  std::string device = "sim";
  std::string scene;
  double rate_hz = 1000.0;
  double seconds = 0.0;
  std::string rt_policy = "best-effort";
  bool quiet = false;
};

inline void add_rt_end_options(CLI::App& command, RtEndArguments& arguments) {
  command.add_option("--transport", arguments.transport, "can:IFACE or udp:HOST:PORT (HOST:PORT = this box's address)")
      ->required();
  command.add_option("--device", arguments.device, "sim (SimFalcon) or usb (the real Falcon)")->check(CLI::IsMember({"sim", "usb"}));
  command.add_option("--scene", arguments.scene,
                     "scene name or file whose [device_mapping] (and, for sim, [hand]) to use — the host must run the same scene");
  command.add_option("--rate", arguments.rate_hz, "rt tick rate [Hz] (500..10000)")->check(CLI::Range(500.0, 10000.0));
  command.add_option("--seconds", arguments.seconds, "run this long, then ramp out (default: until Ctrl-C)")
      ->check(CLI::NonNegativeNumber);
  command.add_option("--rt-policy", arguments.rt_policy, "best-effort (warn and run without SCHED_FIFO) or enforce (fail)")
      ->check(CLI::IsMember({"best-effort", "enforce"}));
  command.add_flag("--quiet", arguments.quiet, "no status line");
}

/// The rt end's options from the arguments; reads the scene's [device_mapping] and [hand] tables
/// (config::SceneError naming file, line and field when they are wrong).
inline RtEndOptions rt_end_options(const RtEndArguments& arguments, const char* program) {
  RtEndOptions options;
  options.transport = arguments.transport;
  options.usb_device = arguments.device == "usb";
  if (!arguments.scene.empty()) {
    const config::RtSessionConfig scene = config::load_rt_session_config(config::resolve_scene_path(arguments.scene));
    options.device_mapping = scene.device_mapping;
    options.scene_name = scene.scene_name;
    options.hand = scene.hand;
  }
  options.rate_hz = arguments.rate_hz;
  options.seconds = arguments.seconds;
  options.policy = arguments.rt_policy == "enforce" ? rt::RtPolicy::kEnforce : rt::RtPolicy::kBestEffort;
  options.status_line = !arguments.quiet;
  options.program = program;
  return options;
}

}  // namespace fissure::session
