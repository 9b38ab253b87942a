#pragma once
// What a `fissure run` session leaves behind: a per-tick CSV trace (rt telemetry + the newest
// host status), the summary figures docs/session.md explains (crossed_nodes_max, faults, overruns,
// force_max_n, proxy_age_ms {median, p99}, energy_j) and a status line. Runs on the session's
// main thread (not the rt thread): it may allocate and write files.
#include <array>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fissure/rt_core/telemetry.hpp"
#include "fissure/session/session_host.hpp"

namespace fissure::session {

/// Samples of one figure for its quantiles, in bounded memory: every value while there are at most
/// kCapacity (exact quantiles — every test and benchmark session), then a uniform reservoir
/// sample (Vitter's algorithm R, fixed seed, so a lockstep run is still reproducible). A session
/// of any length, e.g. a USB run left going all day, costs at most kCapacity doubles per figure.
class SampleReservoir {
 public:
  /// 8 MiB of doubles: 17 min of ticks at 1 kHz kept exactly.
  static constexpr std::size_t kCapacity = std::size_t{1} << 20;
  void add(double value);
  [[nodiscard]] std::uint64_t count() const noexcept { return count_; }
  [[nodiscard]] bool exact() const noexcept { return count_ <= kCapacity; }
  [[nodiscard]] double max() const noexcept { return max_; }
  [[nodiscard]] const std::vector<double>& values() const noexcept { return values_; }

 private:
  std::vector<double> values_;
  std::uint64_t count_ = 0;
  double max_ = 0.0;
  std::uint64_t rng_state_ = 0x9E3779B97F4A7C15ull;
};

struct SessionFigures {
  std::uint64_t ticks = 0;
  std::uint64_t overruns = 0;
  std::uint64_t fault_ticks = 0;           ///< ticks with any RtFaultBits fault bit set
  std::uint32_t fault_bits_seen = 0;       ///< OR of every fault bit seen
  /// Ticks with each flag bit (fault_bits 16..20: not faults, rt_core/faults.hpp), by bit − 16.
  std::array<std::uint64_t, 5> flag_ticks{};
  std::uint64_t telemetry_samples = 0;
  TimeNs first_tick_time_ns = 0;           ///< loop clock time of the first / last sample
  TimeNs last_tick_time_ns = 0;
  double force_max_n = 0.0;                ///< max |commanded device force|
  double contact_force_max_n = 0.0;        ///< max |proxy force| before passivity/safety
  double rt_penetration_max_m = 0.0;       ///< deepest proxy penetration rt_core evaluated
  double energy_j = 0.0;                   ///< passivity observer at the last sample (> 0: active)
  double energy_max_j = 0.0;               ///< its maximum over the session
  int crossed_nodes_max = 0;
  std::uint64_t tool_reseats = 0;          ///< host re-seated its tool (device position epoch changed)
  double soft_volume_ratio_min = 1.0;      ///< lowest signed soft volume / settled (< 0: turned inside out)
  double host_penetration_max_m = 0.0;     ///< deepest soft node inside the tool (host)
  double host_force_max_n = 0.0;
  std::uint64_t host_steps = 0;
  SampleReservoir proxy_age_ms;            ///< per tick with a proxy
  SampleReservoir host_step_ms;            ///< per host step
  /// Loop-clock time between consecutive telemetry samples [us]: the rt tick period as it
  /// happened (its jitter is what competition for the CPU, e.g. the view, would show up in).
  SampleReservoir tick_interval_us;
  /// The first non-finite quantity seen ("" while all are finite), e.g. "rt tool position
  /// (tick 1234, t = 1.234 s)": a run that produced one has no valid outputs.
  std::string first_non_finite;
};

class SessionRecorder {
 public:
  /// Opens `trace_path` for writing (its directory must exist: OutputStaging makes it). Throws
  /// SessionError naming the file when it cannot.
  explicit SessionRecorder(const std::filesystem::path& trace_path);
  ~SessionRecorder();
  SessionRecorder(const SessionRecorder&) = delete;
  SessionRecorder& operator=(const SessionRecorder&) = delete;

  void add_host_step(const HostStatus& host);
  void add_tick(const rt::TelemetrySample& sample, const HostStatus& host);
  void close_trace();

  [[nodiscard]] const SessionFigures& figures() const noexcept { return figures_; }
  /// The newest telemetry sample added (zeros before the first).
  [[nodiscard]] const rt::TelemetrySample& last_tick() const noexcept { return last_; }
  [[nodiscard]] const std::filesystem::path& trace_path() const noexcept { return trace_path_; }

  /// One status line (no newline): time, tick rate, force, proxy age, overruns, crossed nodes.
  [[nodiscard]] std::string status_line(double time_s, double tick_rate_hz, double host_rate_hz) const;

 private:
  void note_non_finite(const char* quantity, double time_s, std::uint64_t tick);

  std::filesystem::path trace_path_;
  std::FILE* trace_ = nullptr;
  SessionFigures figures_;
  rt::TelemetrySample last_{};
  HostStatus last_host_{};
};

/// Median and p99 (nearest rank) of `values` (sorted in place); {0, 0} when empty.
struct Quantiles {
  double median = 0.0;
  double p99 = 0.0;
  double max = 0.0;
};
Quantiles quantiles(std::vector<double>& values);
/// The same over a reservoir (its max is exact even when its quantiles are sampled).
Quantiles quantiles(const SampleReservoir& samples);

/// Finds tools/plot_session.py (FISSURE_TOOLS_DIR, ./tools, or up from the executable) and runs
/// it with Debian's /usr/bin/python3 on the trace; returns the PNG path, or "" and `error`.
std::filesystem::path plot_session(const std::filesystem::path& trace, const std::filesystem::path& png,
                                   const std::string& title, std::string& error);

}  // namespace fissure::session
