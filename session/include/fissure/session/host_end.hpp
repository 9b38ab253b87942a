#pragma once
// The host end of a split deployment (docs/deployment.md): the scene's HostSimulation and proxy
// builder (SessionHost, the same object an in-process session steps) on the host schedule,
// joined to an rt end (fissure rt / fissure-rt) by a LinkBridge pumped before and after each
// step. rt_core death: no DeviceState for kRtSilentAfter_ns (50 ms) → the scene is paused (no
// step, no proxy) until rt_core is heard again; a restarted rt_core re-handshakes with a new
// session id. Stopping: rt_core's proxy goes stale and fades the force out on its own.
#include <atomic>
#include <cstdint>
#include <string>

#include "fissure/host_sim/scene_description.hpp"

namespace fissure::session {

struct HostEndOptions {
  host::SceneDescription scene;         ///< as run (see scene_at_host_rate)
  std::string transport;                ///< can:IFACE or udp:HOST:PORT (the rt box's address)
  double seconds = 0.0;                 ///< 0 = until interrupted
  double settle_s = 1.0;                ///< soft body settling before connecting [s]
  double connect_timeout_s = 10.0;      ///< fail when rt_core has not answered within this [s]
  bool status_line = true;
  /// Set from a signal handler: stop stepping and return.
  const std::atomic<bool>* interrupt = nullptr;
};

struct HostEndOutcome {
  double seconds = 0.0;
  std::uint64_t steps = 0;
  std::uint64_t late_steps = 0;
  std::uint64_t pauses = 0;
  double paused_s = 0.0;
  int crossed_nodes_max = 0;
  double host_force_max_n = 0.0;
  bool rt_closed = false;  ///< rt_core said goodbye (it stopped cleanly)
  bool rt_lost = false;    ///< rt_core silent at the end without a goodbye (crash, kill, cut link)
  double rt_lost_at_s = -1.0;  ///< when rt_core went silent for good [s from the host's start] (rt_lost only)
  bool interrupted = false;
};

/// Runs the host end and prints its one-line summary on stdout. Throws SessionError when the
/// set-up fails, rt_core never answers, the handshake refuses the peer, or a step fails.
HostEndOutcome run_host_end(const HostEndOptions& options);

}  // namespace fissure::session
