// Stage 4 of the paired collision (host_sim/src/thin_body/enforced_displacement.cpp): what a
// HELD soft node does while the tool holds still — the mechanism behind issue 5's "paired → hold
// jitter ≤ 1 %".
//  * The tool face is frictionless: a held node dragged along it slides freely, only its normal
//    position is enforced (Coulomb friction measures worse: ThinBodyCollisionParams).
//  * A node lifted off the face moves freely and, pushed back, is held where it lands.
#include "soft_scene_fixture.hpp"

#include <fissure/host_sim/thin_body_collision.hpp>

#include <gtest/gtest.h>

#include <cmath>

namespace fissure::host {
namespace {

using test_scene::kStep_s;

Eigen::Vector3d to_eigen(const btVector3& v) { return {v.x(), v.y(), v.z()}; }

// A 40 mm plate pressed 2 mm into a frozen flat slab (10 mm cells), then held; the slab node at
// the centre is under the plate's bottom face, held on it.
struct HeldSlab {
  test_scene::SoftWorld world{false};
  ToolNodes tool;
  std::unique_ptr<ThinBodyCollision> collision;
  CollisionStepResult result;
  ToolPose pose;
  int centre = -1;

  HeldSlab() : tool(test_scene::plate_tool(0.004)) {
    world.add_slab(0.1, 10);
    world.soft().m_cfg.kDF = 0.2f;  // the scenes' soft friction: Bullet's, not applied by the paired response
    collision = make_paired_collision(tool, world.soft(), ThinBodyCollisionParams{});
    for (int i = 0; i < world.soft().m_nodes.size(); ++i)
      if (to_eigen(world.soft().m_nodes[i].m_x).norm() < 1e-6) centre = i;
    ToolPose previous;
    previous.position_world_m = Eigen::Vector3d(0, 0.0021, 0);  // bottom face 0.1 mm above the slab
    for (int s = 1; s <= 10; ++s) {
      pose = previous;
      pose.position_world_m.y() = 0.002 - 0.002 * s / 10.0;  // to 2 mm deep
      world.step_without_dynamics();
      collision->step(previous, pose, kStep_s, world.soft(), result);
      previous = pose;
    }
  }

  // The soft solver's stand-in: moves the node by `drag` during the step, the tool held still.
  Eigen::Vector3d hold_step_with_drag(const Eigen::Vector3d& drag_world_m) {
    world.step_without_dynamics();
    btSoftBody::Node& node = world.soft().m_nodes[centre];
    node.m_x += btVector3(static_cast<btScalar>(drag_world_m.x()), static_cast<btScalar>(drag_world_m.y()),
                          static_cast<btScalar>(drag_world_m.z()));
    collision->step(pose, pose, kStep_s, world.soft(), result);
    return to_eigen(world.soft().m_nodes[centre].m_x);
  }
};

TEST(EnforcedDisplacement, HeldNodeDraggedAlongTheFaceSlidesFreely) {
  HeldSlab slab;
  ASSERT_GE(slab.centre, 0);
  const Eigen::Vector3d held = to_eigen(slab.world.soft().m_nodes[slab.centre].m_x);
  ASSERT_NEAR(held.y(), -0.002, 1e-5) << "the centre node is held on the plate's bottom face";
  // (The bottom face's outward normal is −y: +y pushes the node into the plate.) Pushed 1 mm into
  // the face and dragged 0.1 mm, then 0.5 mm along it: back on the face, where the drag took it.
  const Eigen::Vector3d after_small = slab.hold_step_with_drag(Eigen::Vector3d(1e-4, 1e-3, 0));
  EXPECT_NEAR(after_small.x(), held.x() + 1e-4, 1e-6) << "no friction: the tangential drag stays";
  EXPECT_NEAR(after_small.y(), held.y(), 1e-6) << "back on the face";
  const Eigen::Vector3d after_large = slab.hold_step_with_drag(Eigen::Vector3d(5e-4, 1e-3, 0));
  EXPECT_NEAR(after_large.x(), held.x() + 6e-4, 2e-6);
  EXPECT_NEAR(after_large.y(), held.y(), 1e-6);
  EXPECT_GT(slab.result.contacted_triangles, 0);
}

TEST(EnforcedDisplacement, HeldNodeLiftedOffMovesFreelyAndIsHeldAgainWhereItLands) {
  HeldSlab slab;
  ASSERT_GE(slab.centre, 0);
  const Eigen::Vector3d held = to_eigen(slab.world.soft().m_nodes[slab.centre].m_x);
  // Lifted 0.5 mm off the face (and moved 0.3 mm sideways): not put back, still colliding.
  const Eigen::Vector3d lifted = slab.hold_step_with_drag(Eigen::Vector3d(3e-4, -5e-4, 0));
  EXPECT_NEAR(lifted.y(), held.y() - 5e-4, 1e-6);
  EXPECT_NEAR(lifted.x(), held.x() + 3e-4, 1e-6);
  EXPECT_GT(slab.result.contacted_triangles, 0);
  // Pushed back into the face: held again where it landed, not snapped back to the old point.
  const Eigen::Vector3d landed = slab.hold_step_with_drag(Eigen::Vector3d(0, 1e-3, 0));
  EXPECT_NEAR(landed.x(), held.x() + 3e-4, 1e-6);
  EXPECT_NEAR(landed.y(), held.y(), 1e-6);
}

// The rim wrap (a coarse triangle straddling an edge-first blade is pulled in front of the edge)
// moves a vertex beside the blade onto the leading rim plane. A vertex beyond the tool's back —
// past the far side face, as the vessel's wall lies beside a clamp jaw's opposite edge — is not
// beside the blade: its straight move onto the leading rim runs over a large face (so it clears
// the interior) and across the whole tool. It stays where it is.
TEST(EnforcedDisplacement, RimWrapNeverCarriesAVertexAcrossTheWholeTool) {
  // A plate 40 mm along x, 4 mm thick, moving 1 mm per step along +x: its +x side face leads into
  // one triangle that meets it head-on (outward normal 55° off −x, towards −y) and leans back
  // over the plate's +y face to a top vertex at height top_y.
  struct Outcome {
    Eigen::Vector3d top_start_m;
    Eigen::Vector3d top_end_m;
    double rim_x_m = 0.0;
  };
  const auto plunge = [](double top_y_m) {
    test_scene::SoftWorld world{false};
    const ToolNodes tool = test_scene::plate_tool(0.004);
    constexpr double kTan55 = 1.4281480067421144;
    const auto x_at = [&](double y) { return 0.024 - kTan55 * y; };
    const std::vector<Eigen::Vector3d> vertices = {{x_at(-0.01), -0.01, 0.03}, {x_at(-0.01), -0.01, -0.03}, {x_at(top_y_m), top_y_m, 0.0}};
    world.add_triangles(vertices, {1, 0, 2});
    std::unique_ptr<ThinBodyCollision> collision = make_paired_collision(tool, world.soft(), ThinBodyCollisionParams{});
    CollisionStepResult result;
    ToolPose previous;
    previous.position_world_m = Eigen::Vector3d(0.0035, 0.0, 0.0);  // rim 0.5 mm before the triangle at y = 0
    ToolPose pose = previous;
    pose.position_world_m.x() += 0.001;
    world.step_without_dynamics();
    collision->step(previous, pose, test_scene::kStep_s, world.soft(), result);
    return Outcome{vertices[2], to_eigen(world.soft().m_nodes[2].m_x), pose.position_world_m.x() + 0.02};
  };
  const double skin_m = ThinBodyCollisionParams{}.skin_m;
  // Top vertex 15 mm up: beside the plate (2 mm behind its middle), wrapped onto the leading rim.
  const Outcome beside = plunge(0.015);
  EXPECT_NEAR(beside.top_end_m.x(), beside.rim_x_m + skin_m, 1e-6) << "a vertex beside the plate is wrapped in front of its rim";
  EXPECT_NEAR(beside.top_end_m.y(), beside.top_start_m.y(), 1e-6);
  // Top vertex 40 mm up: 38 mm behind the plate's middle, 18 mm beyond its back face.
  const Outcome beyond = plunge(0.04);
  EXPECT_LT(beyond.top_start_m.x() - (beyond.rim_x_m - 0.04), 0.0) << "the premise: beyond the back face";
  EXPECT_NEAR(beyond.top_end_m.x(), beyond.top_start_m.x(), 1e-6) << "a vertex beyond the back is not carried across the plate";
  EXPECT_NEAR(beyond.top_end_m.y(), beyond.top_start_m.y(), 1e-6);
}

}  // namespace
}  // namespace fissure::host
