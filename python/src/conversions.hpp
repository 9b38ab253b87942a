#pragma once
// Conversions the binding files share: NumPy arrays that own a buffer moved out of a C++
// vector (no copy: a capsule frees it with the array), Eigen point lists as (N, 3) arrays,
// collision-method names.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <array>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "fissure/host_sim/scene_description.hpp"
#include "fissure/host_sim/thin_tool.hpp"

namespace fissure::python {

/// A 1-D or N-D array owning `values` (moved onto the heap; the capsule deletes it).
template <typename T>
pybind11::array_t<T> to_array(std::vector<T> values, std::vector<pybind11::ssize_t> shape = {}) {
  auto* owned = new std::vector<T>(std::move(values));
  pybind11::capsule free_when_done(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  if (shape.empty()) shape = {static_cast<pybind11::ssize_t>(owned->size())};
  return pybind11::array_t<T>(shape, owned->data(), free_when_done);
}

/// (N, 3) float64 copy of a point list (one copy: Eigen::Vector3d is three packed doubles).
inline pybind11::array_t<double> to_array(const std::vector<Eigen::Vector3d>& points) {
  pybind11::array_t<double> out({static_cast<pybind11::ssize_t>(points.size()), pybind11::ssize_t{3}});
  double* dst = out.mutable_data();
  for (const Eigen::Vector3d& p : points) {
    *dst++ = p.x();
    *dst++ = p.y();
    *dst++ = p.z();
  }
  return out;
}

inline host::SceneCollisionMethod parse_method(const std::string& name) {
  if (const auto method = host::parse_collision_method(name)) return *method;
  throw std::invalid_argument("collision method '" + name + "': expected paired, ray or bullet");
}

inline host::ContactResponse parse_contact_response(const std::string& name) {
  if (const auto response = host::parse_contact_response(name)) return *response;
  throw std::invalid_argument("contact response '" + name + "': expected after_step or in_solver");
}

/// A ToolPose, a position [x, y, z] (keeps orientation_from's orientation) or [x, y, z, qw, qx, qy, qz].
host::ToolPose tool_pose_from(const pybind11::handle& pose, const host::ToolPose& orientation_from);

}  // namespace fissure::python
