#pragma once
// Pipeline stage: one telemetry sample per tick into a wait-free SPSC ring (the last stage).
// The consumer (status line, CSV trace, benchmark) pops at its own pace; when it falls
// behind the ring is full, the sample is dropped and counted — the tick never waits.
#include <array>
#include <cstdint>

#include "fissure/shared/messages.hpp"
#include "fissure/shared/spsc_ring.hpp"
#include "fissure/shared/time.hpp"

namespace fissure::rt {

struct TelemetrySample {
  std::uint64_t tick = 0;                 ///< tick index since the loop started
  TimeNs time_ns = 0;                     ///< tick time on the loop's clock
  TimeNs wakeup_latency_ns = 0;           ///< now − deadline at wake-up (0 in lockstep)
  std::uint64_t overruns = 0;             ///< missed periods so far
  Vec3 position_device_m{};               ///< FK position (last good one during a device fault)
  Vec3 velocity_device_m_per_s{};         ///< filtered velocity
  Vec3 tool_position_world_m{};           ///< after the device → world mapping
  Vec3 contact_force_device_n{};          ///< proxy force after blend and fade, before passivity/safety
  Vec3 force_device_n{};                  ///< force commanded (after safety) — goes out next exchange
  Vec3 friction_force_device_n{};         ///< friction share of the proxy force at this position, faded (no blend)
  std::array<std::int16_t, 3> motor_counts{};
  std::uint16_t patches_in_contact = 0;
  double jaw_closing_m = 0.0;
  double max_penetration_m = 0.0;         ///< deepest patch penetration (< 0: none)
  double energy_j = 0.0;                  ///< passivity observer: Σ F·Δp since start (> 0: active)
  double passivity_damping_n_s_per_m = 0.0;
  double fade_gain = 0.0;                 ///< staleness fade (1 fresh, 0 faded out)
  double ramp_gain = 0.0;                 ///< safety ramp-in/out gain
  TimeNs proxy_age_ns = 0;                ///< age of the proxy in use (0: none yet)
  std::uint64_t proxy_sequence = 0;       ///< sequence of the proxy in use
  std::uint64_t proxies_rejected = 0;     ///< invalid proxies so far
  std::uint32_t fault_bits = 0;           ///< RtFaultBits: faults active this tick + flags
  std::uint32_t buttons = 0;
  std::uint8_t io_status = 0;             ///< falcon::IoStatus of this tick's exchange
  std::int8_t fk_iterations = 0;
  std::uint8_t parts_sliding = 0;         ///< tool parts whose friction cone slides this tick
};
static_assert(std::is_trivially_copyable_v<TelemetrySample>);

/// 8192 samples: ~8 s at 1 kHz, ~0.8 s at 10 kHz — a 10 Hz status line or CSV writer keeps up.
inline constexpr std::size_t kTelemetryCapacity = 8192;
using TelemetryRing = SpscRing<TelemetrySample, kTelemetryCapacity>;

}  // namespace fissure::rt
