#pragma once
// The rt end of a split deployment (docs/deployment.md): the device (SimFalcon with the scene's
// hand, or the USB Falcon) and rt_core's RtLoop on a real-time thread, joined to a host over
// CAN FD or UDP by a LinkBridge pumped on a service thread, so the tick never touches the
// carrier. The calling thread drains telemetry and prints the status line. Host death needs
// nothing here: no proxy reaches rt_core, whose staleness stage fades the force to zero
// (stale 0.1 s + fade 0.05 s); the rt end only reports it. Bullet-free: `fissure rt` on a
// workstation and `fissure-rt` on the RT box run this same code.
#include <atomic>
#include <cstdint>
#include <optional>
#include <string>

#include "fissure/rt_core/rt_thread.hpp"
#include "fissure/shared/session_config.hpp"

namespace fissure::session {

struct RtEndOptions {
  std::string transport;                ///< can:IFACE or udp:HOST:PORT (this box's address)
  bool usb_device = false;              ///< the USB Falcon; false: SimFalcon
  DeviceMapping device_mapping{};       ///< the scene's (the host must run the same scene)
  /// The scene's name; with it the handshake refuses a host running another scene or mapping
  /// (wire::session_fingerprint). Empty (no --scene): not checked, and said so.
  std::string scene_name;
  std::optional<HandScript> hand;       ///< SimFalcon's scripted hand (none: the grip is left free)
  double rate_hz = 1000.0;              ///< rt tick rate [Hz]
  double seconds = 0.0;                 ///< run this long, then ramp out; 0 = until interrupted
  rt::RtPolicy policy = rt::RtPolicy::kBestEffort;
  bool status_line = true;
  const char* program = "fissure rt";   ///< names the program in messages
  /// Set from a signal handler: ramp out and stop (checked every 10 ms).
  const std::atomic<bool>* interrupt = nullptr;
};

struct RtEndOutcome {
  double seconds = 0.0;
  std::uint64_t ticks = 0;
  std::uint64_t overruns = 0;
  bool link_established = false;
  double link_established_at_s = -1.0;  ///< session time of the handshake (-1: never)
  /// Session time the host's proxies stopped (last fresh proxy) when it was still silent at the
  /// end; -1 when it was live at the end or never connected.
  double host_lost_at_s = -1.0;
  std::uint64_t host_losses = 0;        ///< times the host went silent after being live
  /// Session time the host said goodbye (it stopped cleanly); -1 when it did not.
  double host_closed_at_s = -1.0;
  std::uint64_t proxies_used = 0;
  double force_max_n = 0.0;
  std::uint64_t frames_discarded = 0;
  std::uint64_t messages_discarded = 0;
  std::uint64_t host_restarts = 0;
  std::uint64_t device_fault_ticks = 0; ///< ticks with a device-side fault (rt_core/faults.hpp)
  std::uint64_t proxy_stale_ticks = 0;  ///< ticks without a fresh proxy: expected once the host stops
  std::uint64_t proxies_rejected = 0;   ///< proxies rt_core refused as invalid
  bool interrupted = false;
};

/// Runs the rt end and prints its one-line summary on stdout (the link: never established,
/// established at t, closed cleanly by the host at t, host silent from t). Throws SessionError
/// when the set-up fails (device, carrier, rt config, an enforced real-time policy refused),
/// the host was refused by the handshake (another protocol version, scene or mapping), no host
/// ever connected, or the link was lost (the host went silent without closing) at the end.
RtEndOutcome run_rt_end(const RtEndOptions& options);

}  // namespace fissure::session
