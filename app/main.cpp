// fissure: the single entry point. Subcommands come from the modules' register_* functions.
#include <cstdio>
#include <exception>
#include <string>

#include <CLI/CLI.hpp>

#include "bench_kinematics_command.hpp"
#include "bench_rt_command.hpp"
#include "commands.hpp"
#include "device_kinematics.hpp"
#include "device_usb.hpp"
#include "sim_command.hpp"
#include "bench_collision_command.hpp"
#include "run_command.hpp"
#include "render_command.hpp"
#include "bench_view_command.hpp"
#include "rt_command.hpp"
#include "host_command.hpp"
#include "hil_latency_command.hpp"
#include "bench_proxy_command.hpp"
#include "stress_command.hpp"
#include "bench_all_command.hpp"
#include "fissure/eval/eval_error.hpp"
#include "fissure/session/session_error.hpp"
#include "bench_pareto_command.hpp"
#include "bench_mesh_command.hpp"
#include "bench_grasp_command.hpp"
#include "bench_tissue_command.hpp"

namespace {

// Exit codes: 0 success, 1 a command failed at run time, 2 bad usage (unknown subcommand,
// bad option or value). A usage error is reported in one line, never a help dump.
constexpr int kExitUsage = 2;

// CLI11 reports "fissure foo" as "a subcommand is required"; name the culprit instead.
// Walks the leading non-option words down the subcommand tree and returns the first one
// that is not a subcommand of its parent (empty when all are known).
std::string unknown_subcommand(const CLI::App& root, int argc, char** argv) {
  const CLI::App* app = &root;
  for (int i = 1; i < argc; ++i) {
    const std::string word = argv[i];
    if (word.empty() || word[0] == '-' || app->get_subcommands({}).empty()) return {};
    const CLI::App* next = nullptr;
    for (const CLI::App* sub : app->get_subcommands({})) {
      if (sub->check_name(word)) next = sub;
    }
    if (next == nullptr) return "unknown subcommand '" + word + "' of '" + app->get_display_name() + "'";
    app = next;
  }
  return {};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App root{"Fissure: real-time haptic controller and thin-tool soft-body simulator", "fissure"};
  root.require_subcommand(1);
  root.set_version_flag("--version", "fissure 0.1.0");
  auto* bench = root.add_subcommand("bench", "Benchmarks: run time against error, JSON output");
  bench->require_subcommand(1);
  auto* device = root.add_subcommand("device", "Novint Falcon: kinematics, probe, firmware, homing");
  device->require_subcommand(1);
  fissure::app::CommandTree tree{root, *bench, *device};
  // each module's register_*(tree) goes here as it lands
  fissure::app::register_device_usb(tree);
  fissure::app::register_device_kinematics(tree);
  fissure::app::register_bench_kinematics(tree);
  fissure::app::register_sim(tree);
  fissure::app::register_bench_collision(tree);
  fissure::app::register_run(tree);
  fissure::app::register_rt_command(tree);
  fissure::app::register_host_command(tree);
  fissure::app::register_hil_latency(tree);
  fissure::app::register_bench_proxy(tree);
  fissure::app::register_bench_rt(tree);
  fissure::app::register_render(tree);
  fissure::app::register_bench_view(tree);
  fissure::app::register_stress(tree);
  fissure::app::register_bench_all(tree);
  fissure::app::register_bench_pareto(tree);
  fissure::app::register_bench_mesh(tree);
  fissure::app::register_bench_tissue(tree);
  fissure::app::register_bench_grasp(tree);

  if (const std::string unknown = unknown_subcommand(root, argc, argv); !unknown.empty()) {
    std::fprintf(stderr, "fissure: error: %s (see 'fissure --help')\n", unknown.c_str());
    return kExitUsage;
  }
  try {
    root.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return root.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return root.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return root.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "fissure: error: %s (see 'fissure --help')\n", e.what());
    return kExitUsage;
  } catch (const fissure::app::CommandError& e) {
    std::fprintf(stderr, "fissure: error: %s\n", e.what());
    return e.exit_code();
  } catch (const fissure::eval::EvalError& e) {
    std::fprintf(stderr, "fissure: error: %s\n", e.what());
    return e.bad_argument() ? kExitUsage : 1;
  } catch (const fissure::session::SessionError& e) {
    std::fprintf(stderr, "fissure: error: %s\n", e.what());
    return e.bad_argument() ? kExitUsage : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fissure: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
