// The in-solver rim constraint in isolation (rim_projection.cpp): a 1 mm blade held edge-first
// through the middle of a coarse slab's triangles, between their nodes, cuts them; the projection
// tents them over the blade's edge, moving their corners along the triangle's normal only, and
// never moves a corner held on a tool face.
#include "../../host_sim/src/thin_body/collision_state.hpp"
#include "soft_scene_fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace fissure::host::thin_body {
namespace {

constexpr double kSlabSide_m = 0.1;
constexpr int kSlabCells = 4;             // 25 mm squares, two triangles each
constexpr double kEdgeDepth_m = 0.0015;   // the blade's edge this far past the slab (within a thickness + reach)
constexpr double kBladeX_m = 0.0125;      // between the node columns at x = 0 and x = 25 mm

CollisionModel slab_model(test_scene::SoftWorld& world, const ToolNodes& tool) {
  world.add_slab(kSlabSide_m, kSlabCells);
  ThinBodyCollisionParams params;
  params.response = ContactResponse::kInSolver;
  return build_collision_model(tool, world.soft(), params, true);
}

struct RimFixture {
  test_scene::SoftWorld world{false};
  ToolNodes tool = test_scene::plate_tool(0.001);
  CollisionModel model = slab_model(world, tool);
  CollisionData data;
  StepFrame frame;
  Eigen::Vector3d slab_normal_world = Eigen::Vector3d::UnitY();

  RimFixture() {
    allocate_collision_data(model, data);
    // The slab's outward side, as the collision sees it.
    const auto& f = model.soft.face_nodes[0];
    const btSoftBody& soft = world.soft();
    const auto at = [&soft](int i) { return Eigen::Vector3d(soft.m_nodes[i].m_x.x(), soft.m_nodes[i].m_x.y(), soft.m_nodes[i].m_x.z()); };
    slab_normal_world = (model.soft.outward_sign * (at(f[1]) - at(f[0])).cross(at(f[2]) - at(f[0]))).normalized();
    // The blade edge-first (thin axis world x), coming from the outward side, its edge 1.5 mm past the slab.
    ToolPose pose;
    pose.orientation_world = test_scene::edge_first_orientation();
    pose.position_world_m = Eigen::Vector3d(kBladeX_m, 0.0, 0.0) + slab_normal_world * (0.02 - kEdgeDepth_m);
    data.step = 1;
    frame = make_step_frame(model, data.step, pose, pose, 1e-3);
    for (int face = 0; face < model.soft.face_count; ++face) data.broad.candidate_faces.push_back(face);
    for (int node = 0; node < model.soft.node_count; ++node) data.broad.candidate_nodes.push_back(node);
  }

  [[nodiscard]] Eigen::Vector3d node_tool(int i) {
    const btVector3& x = world.soft().m_nodes[i].m_x;
    return frame.r_cur.transpose() * (Eigen::Vector3d(x.x(), x.y(), x.z()) - frame.t_cur);
  }

  // Triangles the tool cuts (in front of and behind the plane inside the prism).
  [[nodiscard]] int cut_triangles() {
    int cut = 0;
    for (int face = 0; face < model.soft.face_count; ++face) {
      const auto& f = model.soft.face_nodes[static_cast<std::size_t>(face)];
      const std::array<Eigen::Vector3d, 3> x{node_tool(f[0]), node_tool(f[1]), node_tool(f[2])};
      const Eigen::Vector3d normal = (model.soft.outward_sign * (x[1] - x[0]).cross(x[2] - x[0])).normalized();
      const TriangleToolExtent e = triangle_tool_extent(model.tool, x, normal, 0.05);
      if (e.meets && e.lowest_m < -kInsideTolerance_m && e.highest_m > kInsideTolerance_m) ++cut;
    }
    return cut;
  }
};

TEST(RimProjection, TheExtentOfABladeThroughATriangleIsExact) {
  RimFixture fx;
  // Every node is outside the blade: the node projection has nothing to do here.
  for (int i = 0; i < fx.model.soft.node_count; ++i) EXPECT_GT(fx.tool.signed_distance_m(fx.node_tool(i)), 0.0) << i;
  int cut = 0;
  for (int face = 0; face < fx.model.soft.face_count; ++face) {
    const auto& f = fx.model.soft.face_nodes[static_cast<std::size_t>(face)];
    const std::array<Eigen::Vector3d, 3> x{fx.node_tool(f[0]), fx.node_tool(f[1]), fx.node_tool(f[2])};
    const Eigen::Vector3d normal = (fx.model.soft.outward_sign * (x[1] - x[0]).cross(x[2] - x[0])).normalized();
    const TriangleToolExtent e = triangle_tool_extent(fx.model.tool, x, normal, 0.05);
    if (!(e.meets && e.lowest_m < 0.0)) continue;
    ++cut;
    // The lowest point is the blade's edge, 1.5 mm behind the flat slab; the highest its back, 38.5 mm in front.
    EXPECT_NEAR(e.lowest_m, -kEdgeDepth_m, 1e-9) << face;
    EXPECT_NEAR(e.highest_m, 0.04 - kEdgeDepth_m, 1e-9) << face;
  }
  EXPECT_GT(cut, 0) << "the blade passes between the nodes through some triangles";
  EXPECT_EQ(cut, fx.cut_triangles());
}

TEST(RimProjection, CutTrianglesAreTentedOverTheEdgeAlongTheirNormal) {
  RimFixture fx;
  ASSERT_GT(fx.cut_triangles(), 0);
  std::vector<Eigen::Vector3d> before;
  for (int i = 0; i < fx.model.soft.node_count; ++i) before.push_back(fx.node_tool(i));
  // The first pass moves corners into the body, along the flat slab's normal but for what a
  // triangle handled after a moved neighbour sees of its tilt (one pass is Gauss–Seidel).
  EXPECT_GT(project_rim_contacts(fx.model, fx.frame, fx.world.soft(), fx.data), 0);
  const Eigen::Vector3d normal_tool = fx.frame.r_cur.transpose() * fx.slab_normal_world;
  int moved_corners = 0;
  for (int i = 0; i < fx.model.soft.node_count; ++i) {
    const Eigen::Vector3d moved = fx.node_tool(i) - before[static_cast<std::size_t>(i)];
    EXPECT_LE(normal_tool.dot(moved), 1e-9) << i;
    EXPECT_LE((moved - normal_tool.dot(moved) * normal_tool).norm(), 0.1 * std::abs(normal_tool.dot(moved)) + 1e-12) << i << ": moved sideways";
    moved_corners += moved.norm() > 0.0 ? 1 : 0;
  }
  EXPECT_GT(moved_corners, 0);
  // Later passes follow the tilted triangles' own normals until none is cut.
  int passes = 1;
  while (fx.cut_triangles() > 0 && passes < 20) {
    (void)project_rim_contacts(fx.model, fx.frame, fx.world.soft(), fx.data);
    ++passes;
  }
  EXPECT_EQ(fx.cut_triangles(), 0) << "after " << passes << " passes";
  EXPECT_LE(passes, 10);
  for (int i = 0; i < fx.model.soft.node_count; ++i)
    EXPECT_GT(fx.tool.signed_distance_m(fx.node_tool(i)), 0.0) << i << ": a corner was pushed into the blade";
}

// (Here every cut triangle keeps a free corner that can carry the move; one whose deepest point
// lies next to its held corners moves them too, rim_projection.cpp.)
TEST(RimProjection, ACornerHeldOnAToolFaceIsNotMoved) {
  RimFixture fx;
  // Hold every corner of the cut triangles that lies on the blade's +x side.
  std::vector<int> held;
  for (int i = 0; i < fx.model.soft.node_count; ++i) {
    if (fx.world.soft().m_nodes[i].m_x.x() > kBladeX_m) {
      fx.data.displacement.hold_stamp[static_cast<std::size_t>(i)] = fx.data.step;
      fx.data.displacement.hold_plane[static_cast<std::size_t>(i)] = 0;
      held.push_back(i);
    }
  }
  ASSERT_FALSE(held.empty());
  std::vector<Eigen::Vector3d> before;
  for (int i : held) before.push_back(fx.node_tool(i));
  for (int pass = 0; pass < 4; ++pass) (void)project_rim_contacts(fx.model, fx.frame, fx.world.soft(), fx.data);
  for (std::size_t k = 0; k < held.size(); ++k) EXPECT_EQ(fx.node_tool(held[k]), before[k]) << held[k];
}

}  // namespace
}  // namespace fissure::host::thin_body
