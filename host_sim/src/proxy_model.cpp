#include "fissure/host_sim/proxy_model.hpp"

#include <cstddef>

#include <Eigen/Geometry>

#include "fissure/host_sim/soft_world.hpp"

namespace fissure::host {

std::optional<ProxyBuilderModel> proxy_model_for(const SceneDescription& scene, const HostSimulation& sim) {
  ProxyBuilderModel model;
  model.hunt_crossley = scene.hunt_crossley;
  model.friction_static_ratio = scene.tool.friction_static_ratio;
  model.friction_kinetic_ratio = scene.tool.friction_kinetic_ratio;
  const bool clamp = scene.tool.kind == ToolKind::kClamp;
  model.jaw_count = clamp ? 2 : 1;
  // rt_core's clamp convention (shared/device_mapping.hpp): jaw A is the one on the −e_c side.
  // host_sim's jaw 0 sits at tool-local +y (host_simulation.hpp); the tool keeps its start
  // orientation throughout a session.
  const Eigen::Vector3d local_y_world = to_tool_pose(scene.trajectory.start).orientation_world * Eigen::Vector3d::UnitY();
  for (int jaw = 0; jaw < model.jaw_count; ++jaw) {
    const ToolNodes* nodes = sim.tool_nodes(jaw);
    if (nodes == nullptr) return std::nullopt;
    const auto j = static_cast<std::size_t>(jaw);
    model.plane_count[j] = static_cast<int>(nodes->planes().size());
    if (clamp) {
      const double side = (jaw == 0 ? 1.0 : -1.0) * local_y_world[scene.device_mapping.closing_axis_world];
      model.part_of_jaw[j] = side < 0.0 ? ToolPart::kJawA : ToolPart::kJawB;
    } else {
      model.part_of_jaw[j] = ToolPart::kTool;
    }
  }
  return model;
}

}  // namespace fissure::host
