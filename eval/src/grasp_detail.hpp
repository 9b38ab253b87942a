#pragma once
// Shared pieces of the grasp experiments (grasp_lift.cpp, grasp_pull.cpp).
#include <fissure/host_sim/host_simulation.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <vector>

class btSoftBody;

namespace fissure::eval::detail {

// A soft node counts as on a jaw within this of its faces: the in-solver contact leaves held
// nodes a skin (1 µm) in front of the face; 0.1 mm also takes the nodes the hold's share ramp
// still counts as pressing.
inline constexpr double kOnJawTolerance_m = 1.0e-4;

struct JawNode {
  int node = -1;
  int part = 0;
  int face = -1;                     // the jaw face it lies on (ToolNodes::planes index)
  Eigen::Vector3d start_tool_m;      // where, in the jaw's frame
};

struct JawForces {
  std::array<double, 2> normal_n{0.0, 0.0};  // |normal force · closing axis| per jaw
  std::array<Eigen::Vector3d, 2> normal_vector_world_n{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  std::array<Eigen::Vector3d, 2> friction_world_n{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};  // friction force on the jaw
};

[[nodiscard]] double vessel_mass_kg(const btSoftBody& soft);
[[nodiscard]] Eigen::Vector3d centre_of_mass_world_m(const btSoftBody& soft);
[[nodiscard]] std::vector<JawNode> nodes_on_jaws(const host::HostSimulation& sim, double tolerance_m);
// How far a node has slid along the jaw face it lay on since start_tool_m (the jaw's frame).
[[nodiscard]] double tangential_slide_m(const host::HostSimulation& sim, const JawNode& node);
[[nodiscard]] JawForces jaw_forces(const host::HostStepResult& r, const Eigen::Vector3d& closing_axis_world);
[[nodiscard]] Eigen::Quaterniond scene_orientation(const host::SceneDescription& scene);
[[nodiscard]] Eigen::Vector3d closing_axis_world(const host::SceneDescription& scene);
// Friction on (in_solver, where it acts) with these ratios.
void set_friction(host::SceneDescription& scene, double static_ratio, double kinetic_ratio);

}  // namespace fissure::eval::detail
