// fissure._run_session: one `fissure run` session (session::run_session) from Python. It writes
// what the command line writes (trace.csv, summary.json, optionally session.png) into out_dir;
// python/fissure/session.py reads the trace into arrays and the summary into a dict.
#include <pybind11/stl.h>

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>

#include "bindings.hpp"
#include "conversions.hpp"
#include "fissure/host_sim/scene_description.hpp"
#include "fissure/session/session_runner.hpp"

namespace py = pybind11;

namespace fissure::python {

void bind_session(py::module_& m) {
  m.def(
      "_run_session",
      [](const host::SceneDescription& scene, const std::string& out_dir, bool lockstep, const std::string& device, double host_rate_hz,
         double rt_rate_hz, const std::optional<std::string>& method, double duration_s, double settle_s, bool plot,
         bool passivity_controller, bool status_line, const std::string& record_path, const std::string& replay_path) {
        session::SessionOptions options;
        options.scene = scene;
        if (method) options.scene.simulation.collision_method = parse_method(*method);
        if (device != "sim" && device != "usb") throw std::invalid_argument("device '" + device + "': expected sim or usb");
        options.device = device == "usb" ? session::SessionDevice::kUsb : session::SessionDevice::kSim;
        options.lockstep = lockstep;
        options.host_rate_hz = host_rate_hz;
        options.rt_rate_hz = rt_rate_hz;
        options.duration_s = duration_s;
        options.settle_s = settle_s;
        options.out_dir = out_dir;
        options.plot = plot;
        options.passivity_controller = passivity_controller;
        options.status_line = status_line;
        options.record_path = record_path;  // empty: no recording
        options.replay_path = replay_path;  // empty: SimFalcon or the USB Falcon
        session::SessionOutcome outcome;
        {
          py::gil_scoped_release release;
          outcome = session::run_session(options);
        }
        py::dict d;
        d["summary_json"] = outcome.summary.dump();
        d["trace_path"] = outcome.trace_path.string();
        d["summary_path"] = outcome.summary_path.string();
        d["plot_path"] = outcome.plot_path.string();
        return d;
      },
      py::arg("scene"), py::arg("out_dir"), py::arg("lockstep"), py::arg("device"), py::arg("host_rate_hz"), py::arg("rt_rate_hz"),
      py::arg("method"), py::arg("duration_s"), py::arg("settle_s"), py::arg("plot"), py::arg("passivity_controller"),
      py::arg("status_line"), py::arg("record_path"), py::arg("replay_path"), "Internal: use fissure.run_session.");
}

}  // namespace fissure::python
