// The library's exceptions as Python exceptions that keep their text and their parts:
//   config::SceneError   → fissure.SceneError(ValueError), .file .line .field
//   session::SessionError → fissure.SessionError(RuntimeError), .bad_argument
//   eval::EvalError       → fissure.EvalError(RuntimeError), .bad_argument
// Everything else takes pybind11's default mapping (std::invalid_argument → ValueError,
// std::runtime_error and other std::exception → RuntimeError), with what() as the text.
#include <exception>
#include <string>

#include "bindings.hpp"
#include "fissure/config/scene_error.hpp"
#include "fissure/eval/eval_error.hpp"
#include "fissure/session/session_error.hpp"

namespace py = pybind11;

namespace fissure::python {
namespace {

// The Python types live as long as the interpreter (the module holds them too); these handles
// are borrowed for the translator, which runs only while the module is loaded.
py::handle scene_error_type;
py::handle session_error_type;
py::handle eval_error_type;

py::object make_type(py::module_& m, const char* name, PyObject* base, const char* doc) {
  py::object type = py::reinterpret_steal<py::object>(PyErr_NewExceptionWithDoc(
      (std::string("fissure.") + name).c_str(), doc, base, nullptr));
  if (!type) throw py::error_already_set();
  m.attr(name) = type;
  return type;
}

void raise(py::handle type, const py::object& instance) { PyErr_SetObject(type.ptr(), instance.ptr()); }

}  // namespace

void bind_errors(py::module_& m) {
  scene_error_type = make_type(m, "SceneError", PyExc_ValueError,
                               "A configuration file (scene TOML) that cannot be used. str(e) is the loader's one line\n"
                               "'FILE:LINE: field 'FIELD': what is wrong'; the parts are e.file (str), e.line (int,\n"
                               "1-based; 0 when the file is unreadable) and e.field (dotted key path, e.g.\n"
                               "'soft_body.radius_m').")
                         .release();
  session_error_type = make_type(m, "SessionError", PyExc_RuntimeError,
                                 "A session that cannot be set up or run (bad rates, no device, unwritable output).\n"
                                 "e.bad_argument is True when the input names something that cannot be.")
                           .release();
  eval_error_type = make_type(m, "EvalError", PyExc_RuntimeError,
                              "A benchmark or stress run that cannot be set up or finished.\n"
                              "e.bad_argument is True when the input names something that cannot be.")
                        .release();
  py::register_exception_translator([](std::exception_ptr error) {
    try {
      if (error) std::rethrow_exception(error);
    } catch (const config::SceneError& e) {
      py::object instance = scene_error_type(e.what());
      instance.attr("file") = e.file();
      instance.attr("line") = e.line();
      instance.attr("field") = e.field();
      raise(scene_error_type, instance);
    } catch (const session::SessionError& e) {
      py::object instance = session_error_type(e.what());
      instance.attr("bad_argument") = e.bad_argument();
      raise(session_error_type, instance);
    } catch (const eval::EvalError& e) {
      py::object instance = eval_error_type(e.what());
      instance.attr("bad_argument") = e.bad_argument();
      raise(eval_error_type, instance);
    }
  });
}

}  // namespace fissure::python
