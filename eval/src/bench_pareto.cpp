// `fissure bench pareto --json FILE [--scene S] [--quick] [--repeats N]`: host run time against
// host force error over two host knobs (the report's Pareto plots (b) and (c)):
//   * tool node spacing (scene field tool.node_spacing_m), coarse → fine; the finest is the
//     reference;
//   * Bullet sub-steps per host step (scene field simulation.substeps_count) 1, 2, 4, 8 at the
//     scene's host step; the most sub-steps is the reference.
// Every run is the scene's HostSimulation alone (no device, no rt loop) on the scene's scripted
// tool trajectory — for spatula-sphere a press ~1 cm into the sphere, a 0.5 s hold and a
// withdrawal — after the same settling, so every run sees exactly the same tool path and only
// the knob differs. Per run: host step wall time (HostStepTimes::total_s, the metrics pass not
// included; median and p99 over all steps and the median over in-contact steps), the host's
// tool force per step compared step by step with the reference run's (RMS and peak |ΔF| as % of
// the reference's peak |F|), crossed nodes (max over the run) and max penetration.
// --repeats reruns each variant: step times are pooled over the repeats, the force trace must
// be identical between repeats (HostSimulation is deterministic; reported as `deterministic`).
#include "fissure/eval/bench_pareto.hpp"
#include "fissure/eval/eval_error.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "fissure/host_sim/host_simulation.hpp"
#include "fissure/host_sim/scene_loader.hpp"
#include "fissure/host_sim/soft_world.hpp"
#include "fissure/session/machine_info.hpp"
#include "fissure/eval/sim_report.hpp"

namespace fissure::eval {
using namespace fissure::session;  // the session library: SessionHost, run_session, LinkBridge, …
namespace {

/// Node spacings [m] swept, coarse → fine; the last is the reference. The spatula is 30 × 60 mm
/// and ships at 3 mm: 30 mm leaves nodes on its rim only, 0.5 mm puts ~15 000 nodes on its two
/// faces, far finer than the 128-face sphere's triangles (edges ≈ 2 cm).
const std::vector<double> kNodeSpacings_m{0.03, 0.02, 0.015, 0.012, 0.01, 0.008, 0.006, 0.004, 0.003, 0.002, 0.0015, 0.001, 0.0005};
const std::vector<double> kQuickNodeSpacings_m{0.02, 0.012, 0.006, 0.003, 0.0015, 0.00075};
/// Share of the first hold averaged at its start and at its end for the hold drift.
constexpr double kHoldWindowShare = 0.2;
/// Sub-steps per host step; the last is the reference.
const std::vector<int> kSubsteps{1, 2, 4, 8};
/// Soft body settling before each run [s] — the same 1 s `fissure run` and `bench proxy` use (a
/// shorter settle leaves gravity sag in the Hunt-Crossley rest state).
constexpr double kSettle_s = 1.0;


struct Trace {
  std::vector<Eigen::Vector3d> force_world_n;  ///< host force on the tool, per step
  std::vector<double> time_s;                  ///< simulated time at the end of each step
  std::vector<double> step_s;                  ///< pooled over repeats
  std::vector<double> step_in_contact_s;       ///< pooled over repeats
  int crossed_nodes_max = 0;
  double max_penetration_m = 0.0;
  int tool_nodes = 0;
  bool deterministic = true;                   ///< every repeat gave the same force trace
  double wall_s = 0.0;
};

/// One run of `scene` over its scripted trajectory; appends to `trace` (forces only on repeat 0).
void run_once(const host::SceneDescription& scene, int repeat, Trace& trace) {
  host::HostSimulation sim(scene);
  sim.settle(kSettle_s);
  const double dt = scene.simulation.time_step_s;
  const long steps = std::max(1L, std::lround(host::trajectory_duration_s(scene) / dt));
  if (repeat == 0) {
    trace.force_world_n.reserve(static_cast<std::size_t>(steps));
    const host::ToolNodes* nodes = sim.tool_nodes(0);
    trace.tool_nodes = nodes != nullptr ? nodes->node_count() : 0;
  }
  for (long i = 0; i < steps; ++i) {
    const host::TrajectorySample target = sim.scripted_target();
    const host::HostStepResult& r = sim.step(host::to_tool_pose(target.pose), target.jaw_gap_m);
    trace.step_s.push_back(r.times.total_s);
    if (r.contact_count > 0) trace.step_in_contact_s.push_back(r.times.total_s);
    trace.crossed_nodes_max = std::max(trace.crossed_nodes_max, r.crossing.crossed_nodes);
    trace.max_penetration_m = std::max(trace.max_penetration_m, r.crossing.max_penetration_m);
    const auto k = static_cast<std::size_t>(i);
    if (repeat == 0) {
      trace.force_world_n.push_back(r.force_on_tool_world_n);
      trace.time_s.push_back(r.time_s);
    } else if (k >= trace.force_world_n.size() || trace.force_world_n[k] != r.force_on_tool_world_n) {
      trace.deterministic = false;
    }
  }
}

Trace run_variant(const host::SceneDescription& scene, int repeats) {
  Trace trace;
  const auto start = std::chrono::steady_clock::now();
  for (int repeat = 0; repeat < repeats; ++repeat) run_once(scene, repeat, trace);
  trace.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return trace;
}

struct ForceError {
  double rms_pct = 0.0;
  double peak_pct = 0.0;
  double reference_peak_n = 0.0;
};

ForceError force_error(const Trace& run, const Trace& reference) {
  ForceError e;
  for (const Eigen::Vector3d& f : reference.force_world_n) e.reference_peak_n = std::max(e.reference_peak_n, f.norm());
  const std::size_t n = std::min(run.force_world_n.size(), reference.force_world_n.size());
  double sum_sq = 0.0;
  double peak = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double d = (run.force_world_n[i] - reference.force_world_n[i]).norm();
    sum_sq += d * d;
    peak = std::max(peak, d);
  }
  if (n > 0 && e.reference_peak_n > 0.0) {
    e.rms_pct = 100.0 * std::sqrt(sum_sq / static_cast<double>(n)) / e.reference_peak_n;
    e.peak_pct = 100.0 * peak / e.reference_peak_n;
  }
  return e;
}

/// The scripted trajectory's first hold [start, end) in s; {0, 0} when it has none (box tools:
/// legs at constant speed, as host::sample_trajectory moves them).
std::pair<double, double> first_hold_window_s(const host::SceneDescription& scene) {
  double t_s = 0.0;
  Vec3 from = scene.trajectory.start.position_world_m;
  for (const host::TrajectoryWaypoint& wp : scene.trajectory.waypoints) {
    double distance_sq = 0.0;
    for (int i = 0; i < 3; ++i) distance_sq += (wp.position_world_m[i] - from[i]) * (wp.position_world_m[i] - from[i]);
    t_s += std::sqrt(distance_sq) / wp.speed_m_per_s;
    if (wp.hold_s > 0.0) return {t_s, t_s + wp.hold_s};
    from = wp.position_world_m;
  }
  return {0.0, 0.0};
}

/// Mean |F| over the first and the last kHoldWindowShare of the hold: a force that should be
/// constant while the tool is held still (the drift shows what the error is made of).
struct HoldForce {
  double start_n = 0.0;
  double end_n = 0.0;
  double drift_pct = 0.0;
};

HoldForce hold_force(const Trace& t, std::pair<double, double> hold_s) {
  HoldForce h;
  const double share_s = kHoldWindowShare * (hold_s.second - hold_s.first);
  double start_sum = 0.0, end_sum = 0.0;
  int start_count = 0, end_count = 0;
  for (std::size_t i = 0; i < t.time_s.size(); ++i) {
    if (t.time_s[i] >= hold_s.first && t.time_s[i] < hold_s.first + share_s) {
      start_sum += t.force_world_n[i].norm();
      ++start_count;
    } else if (t.time_s[i] >= hold_s.second - share_s && t.time_s[i] < hold_s.second) {
      end_sum += t.force_world_n[i].norm();
      ++end_count;
    }
  }
  if (start_count > 0) h.start_n = start_sum / start_count;
  if (end_count > 0) h.end_n = end_sum / end_count;
  if (h.start_n > 0.0) h.drift_pct = 100.0 * (h.end_n - h.start_n) / h.start_n;
  return h;
}

struct Variant {
  double value = 0.0;  ///< the knob's value (node spacing [m] or sub-steps)
  host::SceneDescription scene;
};

/// Runs a sweep (the last variant is the reference), prints its table, returns its JSON rows.
nlohmann::json run_sweep(const std::string& knob, const std::vector<Variant>& variants, int repeats) {
  const std::pair<double, double> hold_s = first_hold_window_s(variants.back().scene);
  SimProgress progress("bench pareto: " + knob, static_cast<long>(variants.size()));
  long done = 0;
  std::vector<Trace> traces(variants.size());
  // The reference first, so every row can be scored as soon as it is run.
  traces.back() = run_variant(variants.back().scene, repeats);
  progress.update(++done, knob + " reference");
  for (std::size_t i = 0; i + 1 < variants.size(); ++i) {
    traces[i] = run_variant(variants[i].scene, repeats);
    progress.update(++done, knob);
  }
  progress.finish("");
  std::printf("\n%s sweep (reference: the %s row)\n", knob.c_str(), knob == "node_spacing_m" ? "finest" : "most sub-steps");
  std::printf("%14s %10s %12s %10s %14s %13s %14s %8s %10s %9s %9s %6s\n", knob.c_str(), "tool nodes", "step med us", "p99 us",
              "contact med us", "rms err %pk", "peak err %pk", "crossed", "pen mm", "hold F N", "drift %", "det");
  nlohmann::json rows = nlohmann::json::array();
  for (std::size_t i = 0; i < variants.size(); ++i) {
    const Trace& t = traces[i];
    const ForceError e = force_error(t, traces.back());
    const double median_us = sim_quantile(t.step_s, 0.5) * 1e6;
    const double p99_us = sim_quantile(t.step_s, 0.99) * 1e6;
    const double contact_median_us = sim_quantile(t.step_in_contact_s, 0.5) * 1e6;
    const HoldForce hold = hold_force(t, hold_s);
    std::printf("%14.4g %10d %12.1f %10.1f %14.1f %13.3f %14.3f %8d %10.4f %9.3f %+9.1f %6s\n", variants[i].value, t.tool_nodes, median_us,
                p99_us, contact_median_us, e.rms_pct, e.peak_pct, t.crossed_nodes_max, t.max_penetration_m * 1e3, hold.start_n,
                hold.drift_pct, t.deterministic ? "yes" : "NO");
    rows.push_back({{knob, variants[i].value},
                    {"reference", i + 1 == variants.size()},
                    {"tool_nodes", t.tool_nodes},
                    {"host_step_us", {{"median", median_us}, {"p99", p99_us}, {"samples", t.step_s.size()}}},
                    {"host_step_in_contact_us", {{"median", contact_median_us}, {"samples", t.step_in_contact_s.size()}}},
                    {"rms_error_pct", e.rms_pct},
                    {"peak_error_pct", e.peak_pct},
                    {"reference_peak_force_n", e.reference_peak_n},
                    {"crossed_nodes_max", t.crossed_nodes_max},
                    {"max_penetration_m", t.max_penetration_m},
                    {"hold_force_start_n", hold.start_n},
                    {"hold_force_end_n", hold.end_n},
                    {"hold_drift_pct", hold.drift_pct},
                    {"deterministic", t.deterministic},
                    {"wall_s", t.wall_s}});
  }
  return rows;
}

nlohmann::json run_pareto(const BenchParetoOptions& options) {
  host::SceneDescription base;
  try {
    base = host::load_scene(host::resolve_scene_path(options.scene));
  } catch (const std::exception& e) {
    throw EvalError(e.what());
  }
  if (base.tool.kind == host::ToolKind::kConvexMesh) {
    throw EvalError("bench pareto: scene '" + base.name + "' has a convex mesh tool: tool.node_spacing_m has no effect (one node per triangle)");
  }
  const auto start = std::chrono::steady_clock::now();
  const std::vector<double>& spacings = options.quick ? kQuickNodeSpacings_m : kNodeSpacings_m;
  std::vector<Variant> spacing_variants;
  for (const double spacing_m : spacings) {
    Variant v{spacing_m, base};
    v.scene.tool.node_spacing_m = spacing_m;
    spacing_variants.push_back(std::move(v));
  }
  std::vector<Variant> substep_variants;
  for (const int substeps : kSubsteps) {
    Variant v{static_cast<double>(substeps), base};
    v.scene.simulation.substeps_count = substeps;
    substep_variants.push_back(std::move(v));
  }
  const double duration_s = host::trajectory_duration_s(base);
  std::printf("bench pareto: scene %s, scripted trajectory %.2f s at host step %.3g ms after %.1f s settling, %d repeat(s) per row\n",
              base.name.c_str(), duration_s, base.simulation.time_step_s * 1e3, kSettle_s, options.repeats);
  std::printf("force error = |F - F_reference| per host step, RMS and peak over the trajectory, %% of the reference's peak |F|\n");
  nlohmann::json out;
  out["benchmark"] = "pareto";
  out["scene"] = base.name;
  out["quick"] = options.quick;
  out["repeats"] = options.repeats;
  out["trajectory_s"] = duration_s;
  out["settle_s"] = kSettle_s;
  out["host_step_s"] = base.simulation.time_step_s;
  out["scene_node_spacing_m"] = base.tool.node_spacing_m;
  out["scene_substeps_count"] = base.simulation.substeps_count;
  out["method"] = {
      {"runs", "HostSimulation alone on the scene's scripted tool trajectory (same path every run), collision method from the scene"},
      {"timing", "HostStepTimes::total_s per host step (metrics pass excluded), pooled over repeats; median, p99, median over in-contact steps"},
      {"error", "per host step |F_tool - F_tool_reference| (world frame, last sub-step's force); RMS and peak over the trajectory as % of "
                "the reference run's peak |F|"},
      {"node_spacing_sweep", "tool.node_spacing_m varied, substeps as in the scene; reference = finest spacing"},
      {"hold", "mean |F| over the first and the last 20 % of the trajectory's first hold (tool still); drift = end / start - 1"},
      {"substeps_sweep", "simulation.substeps_count varied at the scene's host step, node spacing as in the scene; reference = most sub-steps"}};
  out["node_spacing"] = run_sweep("node_spacing_m", spacing_variants, options.repeats);
  out["substeps"] = run_sweep("substeps", substep_variants, options.repeats);
  out["wall_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  out["machine"] = machine_info();
  std::printf("\nbench pareto: %.1f s wall\n", out["wall_s"].get<double>());
  return out;
}

}  // namespace

nlohmann::json run_bench_pareto(const BenchParetoOptions& options) { return run_pareto(options); }

}  // namespace fissure::eval
