// `fissure bench view [--scene S] [--repeats N] [--render-rows] [--out DIR] [--json FILE]`: the
// session rows come from eval/bench_view; --render-rows adds the host-only rows, which time
// `fissure render`'s own loop (run_render, a command of this program) paced at the host rate:
// nothing drawn, snapshots published into an exchange nobody reads, frames every 10 steps and
// every step, the window.
#include "bench_view_command.hpp"

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "fissure/eval/bench_view.hpp"
#include "fissure/eval/sim_report.hpp"
#include "fissure/session/machine_info.hpp"
#include "json_file.hpp"
#include "render_command.hpp"

namespace fissure::app {
namespace {

using eval::sim_quantile;

struct RenderRow {
  std::string name;
  bool publish_only = false;
  int frame_every = 0;  // 0: no frames
  bool view = false;
};

nlohmann::json run_render_rows(const eval::BenchViewOptions& o) {
  std::vector<RenderRow> configs = {{"none", false, 0, false},
                                    {"publish (no reader)", true, 0, false},
                                    {"frames every 10 steps", false, 10, false},
                                    {"frames every step", false, 1, false}};
  const char* display = std::getenv("DISPLAY");
  if (display != nullptr && *display != '\0') configs.push_back({"view window", false, 0, true});
  nlohmann::json rows = nlohmann::json::array();
  std::printf("\nhost only (fissure render's loop on the scripted trajectory, paced at the host rate), %d repeats per row\n", o.repeats);
  std::printf("%-22s %12s %10s %14s %12s %9s %9s %9s %11s\n", "configuration", "step med us", "p99 us", "publish med us", "p99 us",
              "frames", "dropped", "frame ms", "view frames");
  for (const RenderRow& c : configs) {
    std::vector<double> step_s, publish_s, frame_s;
    std::uint64_t written = 0, dropped = 0, view_frames = 0;
    for (int r = 0; r < o.repeats; ++r) {
      RenderOptions ro;
      ro.scene = o.scene;
      ro.quiet = true;
      ro.publish_only = c.publish_only;
      ro.view = c.view;
      ro.realtime = true;  // every row at the host's real rate (1 kHz), as in a session
      ro.hold_view_at_end = false;
      if (c.frame_every > 0) {
        ro.frames_dir = (std::filesystem::path(o.out_dir) / "render-frames").string();
        ro.frame_every = c.frame_every;
        ro.wait_for_frames = false;
      }
      RenderOutcome out = run_render(ro);
      step_s.insert(step_s.end(), out.step_s.begin(), out.step_s.end());
      publish_s.insert(publish_s.end(), out.publish_s.begin(), out.publish_s.end());
      frame_s.insert(frame_s.end(), out.frame_s.begin(), out.frame_s.end());
      written += out.frames_written;
      dropped += out.frames_dropped;
      view_frames += out.view_frames;
    }
    const double med = sim_quantile(step_s, 0.5) * 1e6, p99 = sim_quantile(step_s, 0.99) * 1e6;
    const double pub_med = sim_quantile(publish_s, 0.5) * 1e6, pub_p99 = sim_quantile(publish_s, 0.99) * 1e6;
    std::printf("%-22s %12.1f %10.1f %14.2f %12.2f %9llu %9llu %9.1f %11llu\n", c.name.c_str(), med, p99, pub_med, pub_p99,
                static_cast<unsigned long long>(written), static_cast<unsigned long long>(dropped), sim_quantile(frame_s, 0.5) * 1e3,
                static_cast<unsigned long long>(view_frames));
    rows.push_back({{"configuration", c.name},
                    {"host_step_us", {{"median", med}, {"p99", p99}, {"samples", step_s.size()}}},
                    {"capture_publish_us", {{"median", pub_med}, {"p99", pub_p99}, {"samples", publish_s.size()}}},
                    {"frames_written", written},
                    {"frames_dropped", dropped},
                    {"frame_ms_median", sim_quantile(frame_s, 0.5) * 1e3},
                    {"view_frames_drawn", view_frames}});
  }
  return rows;
}

}  // namespace

void register_bench_view(CommandTree& tree) {
  struct Arguments {
    std::string json_path;
    bool render_rows = false;
    eval::BenchViewOptions bench;
  };
  auto a = std::make_shared<Arguments>();
  CLI::App* cmd = tree.bench.add_subcommand(
      "view", "Real-time session (fissure run) host step and rt tick timings with and without --frames / --view");
  cmd->add_option("--scene", a->bench.scene, "Scene name or file");
  cmd->add_option("--repeats", a->bench.repeats, "Runs per configuration (the table gives the median over them)")->check(CLI::Range(1, 50));
  cmd->add_flag("--render-rows", a->render_rows, "Also the host-only rows (fissure render's loop: publish cost, frames every step)");
  cmd->add_option("--out", a->bench.out_dir, "Where the runs write their traces, summaries and frames");
  cmd->add_option("--json", a->json_path, "Write the results JSON here");
  cmd->callback([a] {
    nlohmann::json j = eval::run_bench_view(a->bench);
    if (a->render_rows) j["host_only_rows"] = run_render_rows(a->bench);
    if (a->json_path.empty()) return;
    j["machine"] = session::machine_info();
    write_json_file(a->json_path, j);
    std::printf("wrote %s\n", a->json_path.c_str());
  });
}

}  // namespace fissure::app
