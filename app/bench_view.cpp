// `fissure bench view [--scene S] [--repeats N] [--json FILE]`: host step time with nothing
// drawn, with snapshots captured and published into an exchange nobody reads (the bare cost of
// the hand-off), with the frame writer thread running (every 10 steps and every step, never
// waited for), and with the --view window when a display exists — every row paced at the scene's
// real host rate, as in a session. The host step never waits for a view; what is left is
// competition for the CPU (2 cores here; llvmpipe renders on the CPU).
#include "bench_view.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "render_command.hpp"
#include "sim_report.hpp"

namespace fissure::app {
namespace {

struct BenchViewOptions {
  std::string scene = "spatula-sphere";
  int repeats = 3;
  std::string json_path;
  std::string frames_dir = "out/bench-view-frames";
};

struct Config {
  std::string name;
  bool publish_only = false;
  int frame_every = 0;  // 0: no frames
  bool view = false;
};

void run_bench(const BenchViewOptions& o) {
  std::vector<Config> configs = {{"none", false, 0, false},
                                 {"publish (no reader)", true, 0, false},
                                 {"frames every 10 steps", false, 10, false},
                                 {"frames every step", false, 1, false}};
  const char* display = std::getenv("DISPLAY");
  if (display != nullptr && *display != '\0') configs.push_back({"view window", false, 0, true});
  nlohmann::json rows = nlohmann::json::array();
  std::printf("bench view: scene %s, scripted trajectory, %d repeats per row\n", o.scene.c_str(), o.repeats);
  std::printf("%-22s %12s %10s %14s %12s %9s %9s %9s %11s\n", "configuration", "step med us", "p99 us", "publish med us", "p99 us",
              "frames", "dropped", "frame ms", "view frames");
  for (const Config& c : configs) {
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
        ro.frames_dir = o.frames_dir;
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
  if (!o.json_path.empty()) {
    nlohmann::json j;
    j["benchmark"] = "view";
    j["scene"] = o.scene;
    j["repeats"] = o.repeats;
    j["rows"] = rows;
    j["machine"] = sim_machine_info();
    std::ofstream f(o.json_path);
    if (!f) throw CommandError("cannot write the JSON '" + o.json_path + "'");
    f << j.dump(2) << '\n';
    std::printf("wrote %s\n", o.json_path.c_str());
  }
}

}  // namespace

void register_bench_view(CommandTree& tree) {
  auto o = std::make_shared<BenchViewOptions>();
  CLI::App* cmd = tree.bench.add_subcommand("view", "Host step time with and without the frame writer / window / snapshot publishing");
  cmd->add_option("--scene", o->scene, "Scene name or file");
  cmd->add_option("--repeats", o->repeats, "Runs per configuration")->check(CLI::Range(1, 50));
  cmd->add_option("--frames-dir", o->frames_dir, "Where the frame rows write their PNGs");
  cmd->add_option("--json", o->json_path, "Write the results JSON here");
  cmd->callback([o] { run_bench(*o); });
}

}  // namespace fissure::app
