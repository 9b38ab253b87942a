// PYBIND11_MODULE(_fissure): the compiled half of the `fissure` package; python/fissure/
// __init__.py re-exports it and adds what is plain Python (parsing the session trace, the
// benchmarks' JSON).
#include "bindings.hpp"

PYBIND11_MODULE(_fissure, m) {
  m.doc() = "Fissure's host simulation, sessions, benchmarks and Falcon kinematics (compiled part; import `fissure`)";
  fissure::python::bind_errors(m);
  fissure::python::bind_scene(m);
  fissure::python::bind_host(m);
  fissure::python::bind_session(m);
  fissure::python::bind_eval(m);
  fissure::python::bind_kinematics(m);
}
