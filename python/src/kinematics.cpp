// Falcon kinematics (falcon_hw/kinematics.hpp) for analysis scripts: fk, ik, jacobian and the
// workspace test over the Falcon's default geometry, each on one point (shape (3,)) or a batch
// (shape (N, 3)) in one call, so a trajectory costs one Python call. Device frame (libnifalcon's:
// x right, y up, z towards the user), metres, radians. A point the function cannot answer for
// (outside the reachable region, FK not converged) gives NaN in its row rather than an exception.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include "bindings.hpp"
#include "fissure/falcon_hw/falcon_geometry.hpp"
#include "fissure/falcon_hw/kinematics.hpp"

namespace py = pybind11;

namespace fissure::python {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
using Points = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// Rows of a (3,) or (N, 3) array; `single` says which it was.
py::ssize_t rows_of(const Points& a, bool& single, const char* what) {
  if (a.ndim() == 1 && a.shape(0) == 3) {
    single = true;
    return 1;
  }
  if (a.ndim() == 2 && a.shape(1) == 3) {
    single = false;
    return a.shape(0);
  }
  throw std::invalid_argument(std::string(what) + ": expected shape (3,) or (N, 3)");
}

Points shaped(py::ssize_t rows, bool single) {
  return single ? Points(py::array::ShapeContainer{py::ssize_t{3}}) : Points(py::array::ShapeContainer{rows, py::ssize_t{3}});
}

}  // namespace

void bind_kinematics(py::module_& m) {
  const falcon::FalconGeometry geometry{};
  m.attr("WORKSPACE_CENTRE_DEVICE_M") = Eigen::Vector3d(falcon::kWorkspaceCentre_device_m[0], falcon::kWorkspaceCentre_device_m[1],
                                                        falcon::kWorkspaceCentre_device_m[2]);
  m.attr("WORKSPACE_RADIUS_M") = falcon::kWorkspaceRadius_m;

  m.def(
      "ik",
      [geometry](const Points& p) {
        bool single = false;
        const py::ssize_t n = rows_of(p, single, "ik: p_device_m");
        Points out = shaped(n, single);
        const double* in = p.data();
        double* theta = out.mutable_data();
        for (py::ssize_t i = 0; i < n; ++i) {
          Eigen::Vector3d t;
          const bool ok = falcon::inverse_kinematics(geometry, Eigen::Vector3d(in[3 * i], in[3 * i + 1], in[3 * i + 2]), t);
          for (int k = 0; k < 3; ++k) theta[3 * i + k] = ok ? t[k] : kNaN;
        }
        return out;
      },
      py::arg("p_device_m"),
      "Inverse kinematics: motor angles θ1 of the three arms [rad] for end-effector positions [m, device frame].\n"
      "Shape (3,) → (3,), (N, 3) → (N, 3); NaN rows outside the reachable region. Closed form.");
  m.def(
      "fk",
      [geometry](const Points& theta, const std::optional<Eigen::Vector3d>& warm_start, double tolerance_rad, int max_iterations) {
        bool single = false;
        const py::ssize_t n = rows_of(theta, single, "fk: theta_rad");
        Points out = shaped(n, single);
        const falcon::FkOptions options{tolerance_rad, max_iterations};
        Eigen::Vector3d p = warm_start.value_or(Eigen::Vector3d(falcon::kWorkspaceCentre_device_m[0], falcon::kWorkspaceCentre_device_m[1],
                                                               falcon::kWorkspaceCentre_device_m[2]));
        const double* in = theta.data();
        double* pos = out.mutable_data();
        for (py::ssize_t i = 0; i < n; ++i) {
          const falcon::FkResult r = falcon::forward_kinematics(geometry, Eigen::Vector3d(in[3 * i], in[3 * i + 1], in[3 * i + 2]), p, options);
          for (int k = 0; k < 3; ++k) pos[3 * i + k] = r.converged ? p[k] : kNaN;
        }
        return out;
      },
      py::arg("theta_rad"), py::arg("warm_start") = py::none(), py::arg("tolerance_rad") = falcon::kDefaultFkTolerance_rad,
      py::arg("max_iterations") = falcon::kDefaultFkMaxIterations,
      "Forward kinematics (damped Newton on IK, as rt_core runs it): end-effector positions [m, device frame]\n"
      "for motor angles θ1 [rad]. Shape (3,) → (3,), (N, 3) → (N, 3). Each row warm-starts from the previous\n"
      "row's solution (the first from warm_start, default the workspace centre), as the 1 kHz loop does.\n"
      "Rows that do not converge to tolerance_rad within max_iterations are NaN.");
  m.def(
      "jacobian",
      [geometry](const Points& p) {
        bool single = false;
        const py::ssize_t n = rows_of(p, single, "jacobian: p_device_m");
        py::array_t<double> out = single ? py::array_t<double>(py::array::ShapeContainer{py::ssize_t{3}, py::ssize_t{3}})
                                         : py::array_t<double>(py::array::ShapeContainer{n, py::ssize_t{3}, py::ssize_t{3}});
        const double* in = p.data();
        double* j = out.mutable_data();
        for (py::ssize_t i = 0; i < n; ++i) {
          Eigen::Matrix3d dp_dtheta;
          const bool ok = falcon::jacobian(geometry, Eigen::Vector3d(in[3 * i], in[3 * i + 1], in[3 * i + 2]), dp_dtheta);
          for (int r = 0; r < 3; ++r) {
            for (int c = 0; c < 3; ++c) j[9 * i + 3 * r + c] = ok ? dp_dtheta(r, c) : kNaN;
          }
        }
        return out;
      },
      py::arg("p_device_m"),
      "J = ∂p/∂θ1 [m/rad] at end-effector positions [m, device frame] (columns: motors 1..3; torque τ = Jᵀ F).\n"
      "Shape (3,) → (3, 3), (N, 3) → (N, 3, 3); NaN where p is unreachable or J singular.");
  m.def(
      "in_workspace",
      [geometry](const Points& p) -> py::object {
        bool single = false;
        const py::ssize_t n = rows_of(p, single, "in_workspace: p_device_m");
        const double* in = p.data();
        py::array_t<bool> out(py::array::ShapeContainer{n});
        bool* flags = out.mutable_data();
        for (py::ssize_t i = 0; i < n; ++i) flags[i] = falcon::in_workspace(geometry, Eigen::Vector3d(in[3 * i], in[3 * i + 1], in[3 * i + 2]));
        if (single) return py::bool_(flags[0]);
        return out;
      },
      py::arg("p_device_m"),
      "Inside the documented workspace ball (WORKSPACE_RADIUS_M around WORKSPACE_CENTRE_DEVICE_M) and reachable.\n"
      "Shape (3,) → bool, (N, 3) → (N,) bool.");
}

}  // namespace fissure::python
