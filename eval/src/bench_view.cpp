// `fissure bench view [--scene S] [--repeats N] [--render-rows] [--json FILE]`: what seeing the
// scene costs a real-time session: rt and host timings with and without --view.
//
// Session rows (the default): `fissure run SCENE` in real time — SimFalcon + the rt thread
// (SCHED_FIFO when allowed) + the host thread, exactly as the command runs it — without any
// view, with --frames (every 10 host steps, never waited for), and, when a display exists
// (e.g. under xvfb-run), with the --view window and with both. Each row is run --repeats times
// in this one invocation; the table gives the median over the runs of each run's host step
// median / p99, rt tick interval median / p99, rt wake-up latency median / p99, and the sums
// of overruns and late host steps. The view never blocks either thread: what is left is
// competition for the CPU (2 cores here; llvmpipe renders on the CPU).
// The host-only rows of --render-rows time `fissure render`'s own loop and are measured by the
// command (app/bench_view_command.cpp).
#include "fissure/eval/bench_view.hpp"
#include "fissure/eval/eval_error.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fissure/host_sim/scene_loader.hpp"
#include "fissure/session/session_runner.hpp"
#include "fissure/eval/sim_report.hpp"

namespace fissure::eval {
using namespace fissure::session;  // the session library: SessionHost, run_session, LinkBridge, …
namespace {

struct SessionRow {
  std::string name;
  bool view = false;
  int frame_every = 0;  // 0: no frames
};

double median_of(std::vector<double> v) { return sim_quantile(std::move(v), 0.5); }

nlohmann::json run_session_rows(const BenchViewOptions& o, const host::SceneDescription& scene) {
  std::vector<SessionRow> rows = {{"no view", false, 0}, {"--frames every 10", false, 10}};
  const char* display = std::getenv("DISPLAY");
  const bool have_display = display != nullptr && *display != '\0';
  if (have_display) {
    rows.push_back({"--view", true, 0});
    rows.push_back({"--view --frames every 10", true, 10});
  }
  std::printf("bench view: `fissure run %s` in real time, %d runs per row (median over runs)%s\n", o.scene.c_str(), o.repeats,
              have_display ? "" : "; no DISPLAY: --view rows skipped (run under xvfb-run for them)");
  std::printf("%-26s %9s %9s %10s %10s %9s %9s %9s %9s %8s %9s %9s\n", "configuration", "host med", "host p99", "tick med",
              "tick p99", "wake med", "wake p99", "overruns", "host late", "frames", "dropped", "view fps");
  std::printf("%-26s %9s %9s %10s %10s %9s %9s %9s %9s %8s %9s %9s\n", "", "[us]", "[us]", "[us]", "[us]", "[us]", "[us]", "[sum]",
              "[sum]", "[sum]", "[sum]", "[med]");
  nlohmann::json out = nlohmann::json::array();
  for (const SessionRow& row : rows) {
    std::vector<double> host_med, host_p99, tick_med, tick_p99, wake_med, wake_p99, view_fps, publish_med;
    std::uint64_t overruns = 0, late = 0, written = 0, dropped = 0, ticks = 0;
    nlohmann::json runs = nlohmann::json::array();
    for (int r = 0; r < o.repeats; ++r) {
      SessionOptions so;
      so.scene = scene;
      so.status_line = false;
      so.plot = false;
      const std::string tag = (row.view ? std::string("view") : std::string("noview")) + "-f" + std::to_string(row.frame_every) + "-" +
                              std::to_string(r);
      so.out_dir = std::filesystem::path(o.out_dir) / tag;
      so.view = row.view;
      if (row.frame_every > 0) {
        so.frames_dir = so.out_dir / "frames";
        so.frame_every = row.frame_every;
      }
      const SessionOutcome outcome = run_session(so);
      const nlohmann::json& s = outcome.summary;
      host_med.push_back(s["host_step_ms"]["median"].get<double>() * 1e3);
      host_p99.push_back(s["host_step_ms"]["p99"].get<double>() * 1e3);
      tick_med.push_back(s["tick_interval_us"]["median"].get<double>());
      tick_p99.push_back(s["tick_interval_us"]["p99"].get<double>());
      wake_med.push_back(s["wakeup_latency_us"]["median"].get<double>());
      wake_p99.push_back(s["wakeup_latency_us"]["p99"].get<double>());
      overruns += s["overruns"].get<std::uint64_t>();
      late += s["host_late_steps"].get<std::uint64_t>();
      ticks += s["ticks"].get<std::uint64_t>();
      if (s.contains("view")) {
        const nlohmann::json& v = s["view"];
        if (v.contains("frames")) {
          written += v["frames"]["written"].get<std::uint64_t>();
          dropped += v["frames"]["dropped"].get<std::uint64_t>();
        }
        if (v["window"]["open"].get<bool>()) view_fps.push_back(v["window"]["frames_drawn"].get<double>() / s["wall_s"].get<double>());
        publish_med.push_back(v["capture_publish_us"]["median"].get<double>());
      }
      runs.push_back({{"summary", outcome.summary_path.string()},
                      {"host_step_ms", s["host_step_ms"]},
                      {"tick_interval_us", s["tick_interval_us"]},
                      {"wakeup_latency_us", s["wakeup_latency_us"]},
                      {"overruns", s["overruns"]},
                      {"ticks", s["ticks"]},
                      {"rt_setup", s["rt_setup"]}});
    }
    std::printf("%-26s %9.1f %9.1f %10.1f %10.1f %9.1f %9.1f %9llu %9llu %8llu %9llu %9s\n", row.name.c_str(), median_of(host_med),
                median_of(host_p99), median_of(tick_med), median_of(tick_p99), median_of(wake_med), median_of(wake_p99),
                static_cast<unsigned long long>(overruns), static_cast<unsigned long long>(late), static_cast<unsigned long long>(written),
                static_cast<unsigned long long>(dropped), view_fps.empty() ? "-" : std::to_string(static_cast<int>(median_of(view_fps))).c_str());
    out.push_back({{"configuration", row.name},
                   {"view", row.view},
                   {"frame_every_host_steps", row.frame_every},
                   {"runs", o.repeats},
                   {"host_step_us", {{"median", median_of(host_med)}, {"p99", median_of(host_p99)}}},
                   {"rt_tick_interval_us", {{"median", median_of(tick_med)}, {"p99", median_of(tick_p99)}}},
                   {"rt_wakeup_latency_us", {{"median", median_of(wake_med)}, {"p99", median_of(wake_p99)}}},
                   {"overruns", overruns},
                   {"host_late_steps", late},
                   {"ticks", ticks},
                   {"frames_written", written},
                   {"frames_dropped", dropped},
                   {"view_fps_median", view_fps.empty() ? nlohmann::json(nullptr) : nlohmann::json(median_of(view_fps))},
                   {"capture_publish_us_median", publish_med.empty() ? nlohmann::json(nullptr) : nlohmann::json(median_of(publish_med))},
                   {"per_run", runs}});
  }
  return out;
}

}  // namespace

nlohmann::json run_bench_view(const BenchViewOptions& o) {
  host::SceneDescription scene;
  try {
    scene = host::load_scene(host::resolve_scene_path(o.scene));
  } catch (const std::exception& e) {
    throw EvalError(e.what());
  }
  nlohmann::json j;
  j["benchmark"] = "view";
  j["scene"] = o.scene;
  j["repeats"] = o.repeats;
  j["command"] = "fissure run " + o.scene + " (real time, SimFalcon) per row";
  j["rows"] = run_session_rows(o, scene);
  return j;
}

}  // namespace fissure::eval
