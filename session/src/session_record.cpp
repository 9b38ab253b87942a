#include "fissure/session/session_record.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include <Eigen/Core>

#include "fissure/session/session_error.hpp"
#include "fissure/rt_core/faults.hpp"
#include "fissure/session/shell_quote.hpp"

namespace fissure::session {
namespace {

double norm(const Vec3& v) { return as_eigen(v).norm(); }

bool finite(const Vec3& v) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); }

/// The first non-finite quantity of a telemetry sample, by the trace column's name; null when all are finite.
const char* non_finite_quantity(const rt::TelemetrySample& s) {
  if (!finite(s.tool_position_world_m)) return "tool position (tool_*_world_m)";
  if (!std::isfinite(s.jaw_closing_m)) return "jaw closing (jaw_closing_m)";
  if (!finite(s.force_device_n)) return "commanded device force (force_*_device_n)";
  if (!finite(s.contact_force_device_n)) return "contact force (contact_force_n)";
  if (!finite(s.friction_force_device_n)) return "friction force (friction_n)";
  if (!std::isfinite(s.max_penetration_m)) return "rt penetration depth (penetration_m)";
  if (!std::isfinite(s.energy_j)) return "passivity energy (energy_j)";
  if (!std::isfinite(s.fade_gain) || !std::isfinite(s.ramp_gain)) return "force gains (fade_gain, ramp_gain)";
  return nullptr;
}

const char* non_finite_quantity(const HostStatus& h) {
  if (!std::isfinite(h.force_n)) return "host contact force (host_force_n)";
  if (!std::isfinite(h.max_penetration_m)) return "host penetration depth (host_penetration_m)";
  if (!std::isfinite(h.soft_volume_ratio)) return "soft body volume (soft_volume_ratio)";
  return nullptr;
}

}  // namespace

void SampleReservoir::add(double value) {
  max_ = count_ == 0 ? value : std::max(max_, value);
  ++count_;
  if (values_.size() < kCapacity) {
    values_.push_back(value);
    return;
  }
  // splitmix64: a fixed, portable sequence (std::uniform_int_distribution is not portable).
  rng_state_ += 0x9E3779B97F4A7C15ull;
  std::uint64_t z = rng_state_;
  z = (z ^ (z >> 30u)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27u)) * 0x94D049BB133111EBull;
  z ^= z >> 31u;
  const std::uint64_t slot = z % count_;
  if (slot < kCapacity) values_[slot] = value;
}

SessionRecorder::SessionRecorder(const std::filesystem::path& trace_path) : trace_path_(trace_path) {
  trace_ = std::fopen(trace_path_.c_str(), "w");
  if (trace_ == nullptr) throw SessionError("cannot write '" + trace_path_.string() + "'");
  std::fprintf(trace_,
               "time_s,tick,tool_x_world_m,tool_y_world_m,tool_z_world_m,jaw_closing_m,"
               "force_x_device_n,force_y_device_n,force_z_device_n,force_n,contact_force_n,"
               "penetration_m,patches_in_contact,proxy_age_ms,proxy_sequence,energy_j,fade_gain,ramp_gain,"
               "fault_bits,overruns,host_time_s,host_force_n,host_contacts,host_crossed_nodes,host_penetration_m,host_jaw_gap_m,"
               "host_jaw_a_normal_n,host_jaw_a_friction_n,host_jaw_b_normal_n,host_jaw_b_friction_n,friction_n,parts_sliding\n");
}

void SessionRecorder::note_non_finite(const char* quantity, double time_s, std::uint64_t tick) {
  if (!figures_.first_non_finite.empty()) return;
  char text[192];
  std::snprintf(text, sizeof text, "%s (tick %llu, t = %.4f s)", quantity, static_cast<unsigned long long>(tick), time_s);
  figures_.first_non_finite = text;
}

SessionRecorder::~SessionRecorder() { close_trace(); }

void SessionRecorder::close_trace() {
  if (trace_ != nullptr) std::fclose(trace_);
  trace_ = nullptr;
}

void SessionRecorder::add_host_step(const HostStatus& host) {
  last_host_ = host;
  ++figures_.host_steps;
  figures_.crossed_nodes_max = std::max(figures_.crossed_nodes_max, host.crossed_nodes);
  figures_.tool_reseats = host.tool_reseats;
  figures_.soft_volume_ratio_min = std::min(figures_.soft_volume_ratio_min, host.soft_volume_ratio);
  figures_.host_penetration_max_m = std::max(figures_.host_penetration_max_m, host.max_penetration_m);
  figures_.host_force_max_n = std::max(figures_.host_force_max_n, host.force_n);
  figures_.host_step_ms.add(host.step_cpu_s * 1e3);
  if (const char* quantity = non_finite_quantity(host)) note_non_finite(quantity, static_cast<double>(host.host_time_ns) * 1e-9, last_.tick);
}

void SessionRecorder::add_tick(const rt::TelemetrySample& s, const HostStatus& host) {
  if (figures_.telemetry_samples > 0) figures_.tick_interval_us.add(static_cast<double>(s.time_ns - last_.time_ns) * 1e-3);
  last_ = s;
  if (figures_.telemetry_samples++ == 0) figures_.first_tick_time_ns = s.time_ns;
  figures_.last_tick_time_ns = s.time_ns;
  figures_.ticks = s.tick + 1;
  figures_.overruns = s.overruns;
  const std::uint32_t faults = s.fault_bits & rt::kAnyFault;
  if (faults != 0) ++figures_.fault_ticks;
  figures_.fault_bits_seen |= faults;
  for (std::size_t flag = 0; flag < figures_.flag_ticks.size(); ++flag) {
    if ((s.fault_bits & (rt::kFlagForceClamped << flag)) != 0u) ++figures_.flag_ticks[flag];
  }
  const double force = norm(s.force_device_n);
  const double contact_force = norm(s.contact_force_device_n);
  figures_.force_max_n = std::max(figures_.force_max_n, force);
  figures_.contact_force_max_n = std::max(figures_.contact_force_max_n, contact_force);
  figures_.rt_penetration_max_m = std::max(figures_.rt_penetration_max_m, s.max_penetration_m);
  figures_.energy_j = s.energy_j;
  figures_.energy_max_j = std::max(figures_.energy_max_j, s.energy_j);
  const double age_ms = static_cast<double>(s.proxy_age_ns) * 1e-6;
  if (s.proxy_sequence != 0) figures_.proxy_age_ms.add(age_ms);
  if (const char* quantity = non_finite_quantity(s)) {
    note_non_finite(quantity, static_cast<double>(s.time_ns - figures_.first_tick_time_ns) * 1e-9, s.tick);
  }
  if (trace_ != nullptr) {
    std::fprintf(trace_,
                 "%.6f,%llu,%.7g,%.7g,%.7g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%u,%.4f,%llu,%.6g,%.4g,%.4g,%u,%llu,%.6f,%.6g,%d,%d,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%u\n",
                 static_cast<double>(s.time_ns - figures_.first_tick_time_ns) * 1e-9, static_cast<unsigned long long>(s.tick), s.tool_position_world_m[0],
                 s.tool_position_world_m[1], s.tool_position_world_m[2], s.jaw_closing_m, s.force_device_n[0],
                 s.force_device_n[1], s.force_device_n[2], force, contact_force, std::max(0.0, s.max_penetration_m),
                 static_cast<unsigned>(s.patches_in_contact), age_ms, static_cast<unsigned long long>(s.proxy_sequence),
                 s.energy_j, s.fade_gain, s.ramp_gain, s.fault_bits, static_cast<unsigned long long>(s.overruns),
                 static_cast<double>(host.host_time_ns) * 1e-9, host.force_n, host.contacts, host.crossed_nodes,
                 host.max_penetration_m, host.jaw_gap_m, host.part_normal_n[0], host.part_friction_n[0], host.part_normal_n[1],
                 host.part_friction_n[1], norm(s.friction_force_device_n), static_cast<unsigned>(s.parts_sliding));
  }
}

std::string SessionRecorder::status_line(double time_s, double tick_rate_hz, double host_rate_hz) const {
  char line[256];
  std::snprintf(line, sizeof line,
                "t %6.2f s | rt %6.0f Hz | host %5.0f Hz | F %5.2f N | proxy age %5.1f ms | overruns %llu | crossed %d | faults %s",
                time_s, tick_rate_hz, host_rate_hz, norm(last_.force_device_n),
                static_cast<double>(last_.proxy_age_ns) * 1e-6, static_cast<unsigned long long>(last_.overruns),
                last_host_.crossed_nodes, rt::fault_name(last_.fault_bits & rt::kAnyFault));
  return line;
}

Quantiles quantiles(std::vector<double>& values) {
  Quantiles q;
  if (values.empty()) return q;
  std::sort(values.begin(), values.end());
  const auto rank = [&](double p) {
    const auto i = static_cast<std::size_t>(std::ceil(p * static_cast<double>(values.size()))) ;
    return values[std::min(values.size() - 1, i == 0 ? 0 : i - 1)];
  };
  q.median = rank(0.5);
  q.p99 = rank(0.99);
  q.max = values.back();
  return q;
}

Quantiles quantiles(const SampleReservoir& samples) {
  std::vector<double> values = samples.values();
  Quantiles q = quantiles(values);
  q.max = samples.max();
  return q;
}

std::filesystem::path plot_session(const std::filesystem::path& trace, const std::filesystem::path& png,
                                   const std::string& title, std::string& error) {
  namespace fs = std::filesystem;
  std::vector<fs::path> candidates;
  if (const char* env = std::getenv("FISSURE_TOOLS_DIR")) candidates.emplace_back(env);
  candidates.emplace_back(fs::current_path() / "tools");
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    for (fs::path dir = exe.parent_path(); !dir.empty() && dir != dir.root_path(); dir = dir.parent_path()) {
      candidates.push_back(dir / "tools");
    }
  }
  fs::path script;
  for (const fs::path& dir : candidates) {
    if (fs::is_regular_file(dir / "plot_session.py", ec)) {
      script = dir / "plot_session.py";
      break;
    }
  }
  if (script.empty()) {
    error = "tools/plot_session.py not found (set FISSURE_TOOLS_DIR)";
    return {};
  }
  // Debian's python3 + python3-matplotlib (toolchain/setup.sh), not whatever python is first on PATH.
  const std::string command = "/usr/bin/python3 " + shell_quote(script.string()) + " " + shell_quote(trace.string()) +
                              " " + shell_quote(png.string()) + " --title " + shell_quote(title);
  const int status = std::system(command.c_str());
  if (status != 0) {
    error = "plot failed (" + command + " exited with status " + std::to_string(status) + ")";
    return {};
  }
  return png;
}

}  // namespace fissure::session
