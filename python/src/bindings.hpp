#pragma once
// The fissure Python module (_fissure), one file per area it binds; module.cpp calls each.
#include <pybind11/pybind11.h>

namespace fissure::python {

void bind_errors(pybind11::module_& m);      // errors.cpp: SceneError, SessionError, EvalError
void bind_scene(pybind11::module_& m);       // scene.cpp: Scene, ToolPose, plunge tools
void bind_host(pybind11::module_& m);        // host_simulation.cpp: HostSimulation, StepResult
void bind_session(pybind11::module_& m);     // session.cpp: run_session
void bind_eval(pybind11::module_& m);        // eval.cpp: benchmarks, stress harness
void bind_kinematics(pybind11::module_& m);  // kinematics.cpp: Falcon fk / ik / jacobian

}  // namespace fissure::python
