#pragma once
// `fissure hil latency`: the latency distributions of a real-time session — device round trip,
// rt tick, host step, proxy age and end to end — in process or over a real carrier with both
// ends in this process (hil_latency.cpp says how each is measured).
#include <string>

#include <nlohmann/json.hpp>

namespace fissure::eval {

struct HilLatencyOptions {
  std::string device = "sim";           ///< sim (SimFalcon with the scene's hand) or usb
  std::string transport = "inproc";     ///< inproc, udp:HOST:PORT or can:IFACE
  std::string scene = "spatula-sphere";
  double seconds = 10.0;                ///< measurement length [s]
  double rate_hz = 1000.0;              ///< rt tick rate [Hz]
  double settle_s = 1.0;                ///< soft body settling first [s]
};

/// The distributions as the JSON `fissure hil latency --json` writes. Throws EvalError (bad
/// transport spec: bad_argument; scene; link or host failure) or SessionError (set-up).
[[nodiscard]] nlohmann::json run_hil_latency(const HilLatencyOptions& options);

/// Whether the run measured an end-to-end latency at all (at least one proxy reached rt_core).
[[nodiscard]] bool hil_latency_measured(const nlohmann::json& result);

}  // namespace fissure::eval
