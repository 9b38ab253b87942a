// The benchmarks and the stress harness (eval/): each binding runs the library function the
// `fissure bench ...` / `fissure stress` command runs and returns the JSON that command writes,
// as text; python/fissure/evaluation.py parses it into dicts. They print their tables to the
// process's stdout as they run, as the commands do.
#include <pybind11/stl.h>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bindings.hpp"
#include "conversions.hpp"
#include "fissure/eval/bench_collision.hpp"
#include "fissure/eval/bench_grasp.hpp"
#include "fissure/eval/bench_kinematics.hpp"
#include "fissure/eval/bench_mesh.hpp"
#include "fissure/eval/bench_pareto.hpp"
#include "fissure/eval/bench_proxy.hpp"
#include "fissure/eval/bench_rt.hpp"
#include "fissure/eval/bench_tissue.hpp"
#include "fissure/eval/bench_view.hpp"
#include "fissure/eval/hil_latency.hpp"
#include "fissure/eval/stress_cases.hpp"
#include "fissure/eval/stress_run.hpp"

namespace py = pybind11;

namespace fissure::python {
namespace {

/// Runs `bench` without the GIL (the benchmarks take seconds to minutes) and returns its JSON text.
template <typename Bench>
std::string json_text(Bench&& bench) {
  nlohmann::json result;
  {
    py::gil_scoped_release release;
    result = bench();
  }
  return result.dump();
}

/// A benchmark whose only option is `quick`: `name(quick)` runs it and returns its JSON text.
template <typename Options>
void bind_quick_only(py::module_& m, const char* name, nlohmann::json (*run)(const Options&)) {
  m.def(
      name,
      [run](bool quick) {
        Options o;
        o.quick = quick;
        return json_text([&] { return run(o); });
      },
      py::arg("quick"));
}

}  // namespace

void bind_eval(py::module_& m) {
  m.def(
      "_bench_collision",
      [](bool quick, bool full, const std::vector<std::string>& only, const std::string& contact_response, bool in_solver_friction) {
        eval::BenchCollisionOptions o;
        o.quick = quick;
        o.full = full;
        o.only = only;
        o.contact_response = parse_contact_response(contact_response);
        o.in_solver_tool_friction = in_solver_friction;
        return json_text([&] { return eval::run_bench_collision(o); });
      },
      py::arg("quick"), py::arg("full"), py::arg("only"), py::arg("contact_response"), py::arg("in_solver_friction"));
  bind_quick_only<eval::BenchGraspOptions>(m, "_bench_grasp", &eval::run_bench_grasp);
  bind_quick_only<eval::BenchMeshOptions>(m, "_bench_mesh", &eval::run_bench_mesh);
  bind_quick_only<eval::BenchTissueOptions>(m, "_bench_tissue", &eval::run_bench_tissue);
  m.def(
      "_bench_kinematics",
      [](std::size_t samples, int repeats, std::uint64_t seed) {
        eval::BenchKinematicsOptions o;
        o.samples = samples;
        o.repeats = repeats;
        o.seed = seed;
        return json_text([&] { return eval::run_bench_kinematics(o); });
      },
      py::arg("samples"), py::arg("repeats"), py::arg("seed"));
  m.def(
      "_bench_pareto",
      [](const std::string& scene, bool quick, int repeats) {
        eval::BenchParetoOptions o;
        o.scene = scene;
        o.quick = quick;
        o.repeats = repeats;
        return json_text([&] { return eval::run_bench_pareto(o); });
      },
      py::arg("scene"), py::arg("quick"), py::arg("repeats"));
  m.def(
      "_bench_proxy",
      [](const std::string& scene, double rt_rate_hz, const std::vector<double>& host_rates_hz, double duration_s, double settle_s,
         const std::string& trace_dir) {
        eval::BenchProxyOptions o;
        o.scene = scene;
        o.rt_rate_hz = rt_rate_hz;
        o.host_rates_hz = host_rates_hz;
        o.duration_s = duration_s;
        o.settle_s = settle_s;
        o.trace_dir = trace_dir;
        return json_text([&] { return eval::run_bench_proxy(o); });
      },
      py::arg("scene"), py::arg("rt_rate_hz"), py::arg("host_rates_hz"), py::arg("duration_s"), py::arg("settle_s"), py::arg("trace_dir"));
  m.def(
      "_bench_rt",
      [](double seconds, bool enforce_rt, int priority, bool skip_sched_fifo) {
        eval::BenchRtOptions o;
        o.seconds = seconds;
        o.rt_policy = enforce_rt ? rt::RtPolicy::kEnforce : rt::RtPolicy::kBestEffort;
        o.priority = priority;
        o.skip_sched_fifo = skip_sched_fifo;
        return json_text([&] { return eval::run_bench_rt(o); });
      },
      py::arg("seconds"), py::arg("enforce_rt"), py::arg("priority"), py::arg("skip_sched_fifo"));
  m.def(
      "_bench_view",
      [](const std::string& scene, int repeats, const std::string& out_dir) {
        eval::BenchViewOptions o;
        o.scene = scene;
        o.repeats = repeats;
        o.out_dir = out_dir;
        return json_text([&] { return eval::run_bench_view(o); });
      },
      py::arg("scene"), py::arg("repeats"), py::arg("out_dir"));
  m.def(
      "_hil_latency",
      [](const std::string& device, const std::string& transport, const std::string& scene, double seconds, double rate_hz, double settle_s) {
        eval::HilLatencyOptions o;
        o.device = device;
        o.transport = transport;
        o.scene = scene;
        o.seconds = seconds;
        o.rate_hz = rate_hz;
        o.settle_s = settle_s;
        return json_text([&] { return eval::run_hil_latency(o); });
      },
      py::arg("device"), py::arg("transport"), py::arg("scene"), py::arg("seconds"), py::arg("rate_hz"), py::arg("settle_s"));
  m.def(
      "stress_case_names",
      [] {
        std::vector<std::string> names;
        for (const eval::StressCase& c : eval::stress_cases()) names.push_back(c.name);
        return names;
      },
      "Names of every stress case, in report order (fissure.stress(cases=[...]) takes them).");
  m.def(
      "_stress",
      [](const std::optional<std::vector<std::string>>& case_names, const std::string& profile, std::uint64_t seed, unsigned jobs) {
        if (profile != "ci" && profile != "full") throw std::invalid_argument("stress profile '" + profile + "': expected ci or full");
        eval::StressRunOptions o;
        o.profile = profile == "full" ? eval::StressProfile::kFull : eval::StressProfile::kCi;
        o.seed = seed;
        o.jobs = jobs;
        const std::vector<eval::StressCase> cases = case_names ? eval::stress_cases_named(*case_names) : eval::stress_cases();
        return json_text([&] {
          const eval::StressRunResult result = eval::run_stress(cases, o, [](const eval::StressRow&) {});
          return eval::stress_report_json(result, o, profile);
        });
      },
      py::arg("cases"), py::arg("profile"), py::arg("seed"), py::arg("jobs"));
}

}  // namespace fissure::python
