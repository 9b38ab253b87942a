// The proxy builder's model for a scene (host_sim/proxy_model.hpp): the scene's law, the planes of
// each jaw's tool, and rt_core's part for each host jaw.
#include "fissure/host_sim/proxy_model.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstddef>

#include "fissure/host_sim/scene_loader.hpp"
#include "fissure/host_sim/soft_world.hpp"

namespace fissure::host {
namespace {

void expect_scene_law(const ProxyBuilderModel& model, const SceneDescription& scene) {
  EXPECT_EQ(model.hunt_crossley.k, scene.hunt_crossley.k);
  EXPECT_EQ(model.hunt_crossley.lambda, scene.hunt_crossley.lambda);
  EXPECT_EQ(model.hunt_crossley.n, scene.hunt_crossley.n);
  EXPECT_EQ(model.hunt_crossley.per_unit_area, scene.hunt_crossley.per_unit_area);
}

TEST(ProxyModel, ASpatulaHasOneJawOnTheToolWithItsToolsPlanes) {
  const SceneDescription scene = load_scene(resolve_scene_path("spatula-sphere"));
  const HostSimulation sim(scene, SceneCollisionMethod::kPaired);
  const std::optional<ProxyBuilderModel> model = proxy_model_for(scene, sim);
  ASSERT_TRUE(model.has_value());
  expect_scene_law(*model, scene);
  EXPECT_EQ(model->jaw_count, 1);
  EXPECT_EQ(model->plane_count[0], static_cast<int>(sim.tool_nodes(0)->planes().size()));
  EXPECT_GT(model->plane_count[0], 0);
  EXPECT_EQ(model->part_of_jaw[0], ToolPart::kTool);
}

// rt_core's jaw A is the one on the −e_c side of the tool (shared/device_mapping.hpp): checked
// here against where host_sim actually places each jaw at the scene's start pose.
TEST(ProxyModel, AClampsJawsMapToRtJawsByTheSideOfTheClosingAxisTheySitOn) {
  for (const char* name : {"clamp-sphere", "clamp-vessel"}) {
    const SceneDescription scene = load_scene(resolve_scene_path(name));
    const HostSimulation sim(scene, SceneCollisionMethod::kPaired);
    const std::optional<ProxyBuilderModel> model = proxy_model_for(scene, sim);
    ASSERT_TRUE(model.has_value()) << name;
    expect_scene_law(*model, scene);
    ASSERT_EQ(model->jaw_count, 2) << name;
    const ToolPose start = to_tool_pose(scene.trajectory.start);
    std::array<ToolPose, kMaxToolParts> parts{};
    tool_part_poses(scene, start, scene.tool.clamp.jaw_gap_open_m, parts);
    const int c = scene.device_mapping.closing_axis_world;
    for (std::size_t jaw = 0; jaw < 2; ++jaw) {
      const double side_m = parts[jaw].position_world_m[c] - start.position_world_m[c];
      ASSERT_NE(side_m, 0.0) << name << " jaw " << jaw;
      EXPECT_EQ(model->part_of_jaw[jaw], side_m < 0.0 ? ToolPart::kJawA : ToolPart::kJawB) << name << " jaw " << jaw;
      EXPECT_EQ(model->plane_count[jaw], static_cast<int>(sim.tool_nodes(static_cast<int>(jaw))->planes().size())) << name;
    }
    EXPECT_NE(model->part_of_jaw[0], model->part_of_jaw[1]) << name;
  }
}

TEST(ProxyModel, TheBulletMethodHasNoToolNodesToBuildFrom) {
  const SceneDescription scene = load_scene(resolve_scene_path("spatula-sphere"));
  const HostSimulation sim(scene, SceneCollisionMethod::kBullet);
  EXPECT_FALSE(proxy_model_for(scene, sim).has_value());
}

}  // namespace
}  // namespace fissure::host
