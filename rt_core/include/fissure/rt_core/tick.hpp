#pragma once
// The tick: (device sample, period) → command, one pass through the pipeline, one file per
// stage. noexcept, no heap, no lock, no blocking call except the device exchange:
//   read device (ping-pong: sends last tick's command, gets this tick's encoders)
//   → encoder → angles (jump check) → FK (warm) → velocity (Butterworth, velocity_filter.hpp)
//   → latest proxy (wait-free try_fetch + validate) → Hunt-Crossley per patch at the CURRENT
//   position (device → world mapping) → blend on swap → staleness fade → passivity
//   observer/controller → safety → Jᵀ → motor command (written with the next exchange)
//   → DeviceState out (LatestValueExchange) → telemetry (SPSC ring).
// Ping-pong latency: the Falcon answers each command with one reading, so the command this
// tick computes goes out with the next tick's exchange (as in libnifalcon's I/O loop).
#include <cstdint>

#include <Eigen/Core>

#include "fissure/falcon_hw/haptic_device.hpp"
#include "fissure/rt_core/proxy_intake.hpp"
#include "fissure/rt_core/rt_config.hpp"
#include "fissure/rt_core/rt_data.hpp"
#include "fissure/rt_core/telemetry.hpp"
#include "fissure/shared/exchanges.hpp"
#include "fissure/shared/latest_value_exchange.hpp"
#include "fissure/shared/messages.hpp"

namespace fissure::rt {

/// What the tick talks to. All wait-free except device.try_exchange (bounded I/O).
struct TickIo {
  falcon::HapticDevice& device;
  ProxyExchange& proxy_in;            ///< host → rt (consumer side)
  DeviceStateExchange& state_out;     ///< rt → host (producer side)
  TelemetryRing& telemetry;           ///< rt → logger (producer side)
};

/// Timing facts the loop owner knows and the tick reports.
struct TickTiming {
  TimeNs now_ns = 0;
  TimeNs wakeup_latency_ns = 0;
  std::uint64_t overruns = 0;
  bool stop_requested = false;  ///< ramp out (the loop keeps ticking until stopped)
};

struct TickResult {
  std::uint32_t fault_bits = 0;            ///< RtFaultBits active this tick (+ flags)
  Eigen::Vector3d force_device_n = Eigen::Vector3d::Zero();
  bool stopped = false;                    ///< ramp-out finished: the command is zero for good
};

TickResult tick(const RtModel& model, RtData& data, TickIo& io, const TickTiming& timing) noexcept;

}  // namespace fissure::rt
