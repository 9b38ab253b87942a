// Stage 3 of the thin-body collision in isolation: the infeasible-pair exclusion with its
// cross-check for one-way pairs (paper: "a cross-check is necessary at each step"), and the
// side-memory rule (the node in contact longest led).
#include "../../host_sim/src/thin_body/collision_state.hpp"
#include "soft_scene_fixture.hpp"

#include <gtest/gtest.h>

#include <algorithm>

namespace fissure::host::thin_body {
namespace {

class PairExclusion : public ::testing::Test {
 protected:
  void SetUp() override { world_.add_slab(0.1, 4); }

  CollisionModel model_for(const ToolNodes& tool, bool paired) {
    return build_collision_model(tool, world_.soft(), ThinBodyCollisionParams{}, paired);
  }

  // Puts node in contact with soft face `face` as the sweep would have.
  static void touch(CollisionData& data, int node, int face, int age, double facing, double tau) {
    const auto n = static_cast<std::size_t>(node);
    data.sweep.node_face[n] = face;
    data.sweep.node_age[n] = age;
    data.sweep.node_facing[n] = facing;
    data.sweep.node_tau[n] = tau;
    data.sweep.contact_nodes.push_back(node);
    std::sort(data.sweep.contact_nodes.begin(), data.sweep.contact_nodes.end());
  }

  test_scene::SoftWorld world_{false};
};

TEST_F(PairExclusion, MutualPairKeepsTheFaceThatMeetsTheSurfaceHeadOn) {
  const ToolNodes tool = test_scene::plate_tool(0.004);
  const CollisionModel model = model_for(tool, true);
  CollisionData data;
  allocate_collision_data(model, data);
  data.step = 1;
  const int bottom = 90;  // second face of the 9×9 grid (−y normals)
  const int top = tool.pair_of()[bottom];
  ASSERT_LT(tool.normals_tool()[bottom].y(), 0.0);
  touch(data, bottom, 3, 1, -1.0, 0.2);  // head on
  touch(data, top, 3, 1, +1.0, 0.6);     // the triangle is behind it
  EXPECT_EQ(exclude_infeasible_pairs(model, data), 0);
  ASSERT_EQ(data.exclusion.vector.size(), 1u);
  EXPECT_EQ(data.exclusion.vector[0], top);
  EXPECT_EQ(data.sweep.node_face[static_cast<std::size_t>(top)], -1) << "excluded: no contact this step";
  EXPECT_EQ(data.sweep.node_age[static_cast<std::size_t>(top)], 0) << "and no side memory for the next";
  ASSERT_EQ(data.exclusion.contacted_faces.size(), 1u);
  EXPECT_EQ(data.exclusion.face_plane[3], tool.plane_of_node()[bottom]);
  EXPECT_EQ(data.exclusion.face_lead_node[3], bottom);
}

TEST_F(PairExclusion, SideMemoryWinsTheNodeThatWasInContactFirstLed) {
  const ToolNodes tool = test_scene::plate_tool(0.004);
  const CollisionModel model = model_for(tool, true);
  CollisionData data;
  allocate_collision_data(model, data);
  const int bottom = 100;
  const int top = tool.pair_of()[bottom];
  touch(data, bottom, 5, 1, -1.0, 0.0);  // just arrived, head on
  touch(data, top, 7, 12, -0.2, 1.0);    // in contact for 12 steps already
  exclude_infeasible_pairs(model, data);
  ASSERT_EQ(data.exclusion.vector.size(), 1u);
  EXPECT_EQ(data.exclusion.vector[0], bottom);
}

TEST_F(PairExclusion, OneWayPairIsCrossCheckedFromTheNodeItPointsAt) {
  RoundedSpatulaParams params;
  const ToolNodes tool = ToolNodes::from_convex_mesh(make_rounded_spatula_mesh(params, 1.0));  // unlimited: one-way pairs
  // Find i → j with j → k ≠ i.
  int i = -1;
  for (int node = 0; node < tool.node_count() && i < 0; ++node) {
    const int pair = tool.pair_of()[static_cast<std::size_t>(node)];
    if (pair >= 0 && tool.pair_of()[static_cast<std::size_t>(pair)] != node) i = node;
  }
  ASSERT_GE(i, 0);
  const int j = tool.pair_of()[static_cast<std::size_t>(i)];
  const int k = tool.pair_of()[static_cast<std::size_t>(j)];
  const CollisionModel model = model_for(tool, true);
  CollisionData data;
  allocate_collision_data(model, data);
  // i leads; j trails, and j's own pair k is not in contact — only the cross-check through
  // "nodes that paired with j" can catch j.
  touch(data, i, 2, 1, -0.9, 0.1);
  touch(data, j, 2, 1, 0.8, 0.3);
  ASSERT_TRUE(k < 0 || data.sweep.node_face[static_cast<std::size_t>(k)] < 0);
  EXPECT_EQ(exclude_infeasible_pairs(model, data), 0);
  ASSERT_EQ(data.exclusion.vector.size(), 1u);
  EXPECT_EQ(data.exclusion.vector[0], j);
  EXPECT_EQ(data.exclusion.face_lead_node[2], i);

  // The other way round (j leads) the exclusion falls on i, found from i's own pair.
  CollisionData reversed;
  allocate_collision_data(model, reversed);
  touch(reversed, i, 2, 1, 0.8, 0.3);
  touch(reversed, j, 2, 1, -0.9, 0.1);
  exclude_infeasible_pairs(model, reversed);
  ASSERT_EQ(reversed.exclusion.vector.size(), 1u);
  EXPECT_EQ(reversed.exclusion.vector[0], i);
}

TEST_F(PairExclusion, RayOnlyKeepsBothFacesAndCountsThem) {
  const ToolNodes tool = test_scene::plate_tool(0.004);
  const CollisionModel model = model_for(tool, false);
  CollisionData data;
  allocate_collision_data(model, data);
  const int bottom = 90;
  touch(data, bottom, 3, 1, -1.0, 0.2);
  touch(data, tool.pair_of()[bottom], 3, 1, 1.0, 0.6);
  EXPECT_EQ(exclude_infeasible_pairs(model, data), 1) << "one pair with both faces pushing";
  EXPECT_TRUE(data.exclusion.vector.empty());
}

TEST_F(PairExclusion, UnpairedToolExcludesNothing) {
  const ToolNodes tool = ToolNodes::from_convex_mesh(make_rounded_spatula_mesh(RoundedSpatulaParams{}, 0.0));
  ASSERT_FALSE(tool.is_thin());
  const CollisionModel model = model_for(tool, true);
  CollisionData data;
  allocate_collision_data(model, data);
  touch(data, 0, 1, 1, 1.0, 0.5);
  touch(data, 1, 1, 1, -1.0, 0.5);
  exclude_infeasible_pairs(model, data);
  EXPECT_TRUE(data.exclusion.vector.empty());
  EXPECT_EQ(data.exclusion.contacted_faces.size(), 1u);
}

}  // namespace
}  // namespace fissure::host::thin_body
