// The Bullet world of a scene and its soft bodies (soft_world.cpp, soft_body_builder.cpp).
#include "fissure/host_sim/soft_world.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>

#include "fissure/host_sim/scene_loader.hpp"
#include "fissure/host_sim/soft_body_builder.hpp"

namespace fissure::host {
namespace {

// Signed volume of a closed triangle surface (positive when outward-wound), and whether
// every edge is shared by exactly two oppositely oriented triangles.
double signed_volume(const SurfaceMesh& m) {
  double v = 0.0;
  for (const auto& t : m.triangles) {
    const Eigen::Vector3d a(m.vertices_m[t[0]].data()), b(m.vertices_m[t[1]].data()), c(m.vertices_m[t[2]].data());
    v += a.dot(b.cross(c)) / 6.0;
  }
  return v;
}
bool closed_and_consistent(const SurfaceMesh& m) {
  std::map<std::pair<int, int>, int> edges;
  for (const auto& t : m.triangles) {
    for (int e = 0; e < 3; ++e) ++edges[{t[e], t[(e + 1) % 3]}];
  }
  for (const auto& [e, n] : edges) {
    if (n != 1 || edges.count({e.second, e.first}) == 0) return false;
  }
  return true;
}

TEST(SoftBodyBuilder, IcosphereFaceCountsRadiusAndOrientation) {
  for (int s = 0; s <= 4; ++s) {
    const SurfaceMesh m = make_icosphere({0, 0, 0}, 0.05, s);
    EXPECT_EQ(m.triangles.size(), static_cast<std::size_t>(20 * (1 << (2 * s))));
    for (const Vec3& v : m.vertices_m) EXPECT_NEAR(std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]), 0.05, 1e-12);
    EXPECT_TRUE(closed_and_consistent(m));
    EXPECT_GT(signed_volume(m), 0.0);
  }
  // Volume converges to the sphere's.
  EXPECT_NEAR(signed_volume(make_icosphere({0, 0, 0}, 0.05, 5)), 4.0 / 3.0 * M_PI * 1.25e-4, 0.01 * 5.236e-4);
}

TEST(SoftBodyBuilder, CylinderAndSlabAreClosedAndOutward) {
  SoftCylinder c;
  c.center_world_m = {0.01, 0.02, 0.03};
  const SurfaceMesh cyl = make_cylinder(c);
  EXPECT_TRUE(closed_and_consistent(cyl));
  // Inscribed polygon area: n/2·R²·sin(2π/n).
  const double polygon = 0.5 * c.segments_count * c.radius_m * c.radius_m * std::sin(2 * M_PI / c.segments_count);
  EXPECT_NEAR(signed_volume(cyl), polygon * c.length_m, 1e-9);

  SoftSlab s;
  const SurfaceMesh slab = make_slab(s);
  EXPECT_TRUE(closed_and_consistent(slab));
  EXPECT_NEAR(signed_volume(slab), s.size_m[0] * s.size_m[1] * s.size_m[2], 1e-12);
  EXPECT_EQ(slab.pinned_vertices.size(), static_cast<std::size_t>((s.top_cells_count[0] + 1) * (s.top_cells_count[1] + 1)));
}

TEST(SoftWorld, PaperSphereHas66NodesAnd128FacesAndRestsOnTheGround) {
  const SceneDescription scene = load_scene("scenes/spatula-sphere.toml");
  SoftWorld world(scene, false);
  EXPECT_EQ(world.soft().m_nodes.size(), 66);
  EXPECT_EQ(world.soft().m_faces.size(), 128);
  EXPECT_DOUBLE_EQ(world.sdf_voxel_m(), 0.01);  // only the flat ground meets the soft body in Bullet
  EXPECT_DOUBLE_EQ(SoftWorld(scene, true).sdf_voxel_m(), 0.001);  // bullet method: half the 2 mm spatula
  EXPECT_EQ(world.probe(), nullptr);
  for (int i = 0; i < 1000; ++i) world.step(0.001);
  std::vector<Eigen::Vector3d> nodes;
  world.copy_node_positions(nodes);
  double lowest = 1.0, highest = -1.0;
  for (const auto& p : nodes) {
    ASSERT_TRUE(p.allFinite());
    lowest = std::min(lowest, p.y());
    highest = std::max(highest, p.y());
  }
  EXPECT_GT(lowest, 0.0);                   // on, not through, the ground (margin 2 mm)
  EXPECT_LT(lowest, 0.005);                 // and not floating away
  EXPECT_NEAR(highest - lowest, 0.1, 0.01);  // still a ~10 cm ball
}

TEST(SoftWorld, ToolCollidesInBulletOnlyForTheBulletMethod) {
  const SceneDescription scene = load_scene("scenes/spatula-sphere.toml");
  SoftWorld ours(scene, false);
  SoftWorld bullet(scene, true);
  EXPECT_FALSE(ours.part_body(0).isInWorld());
  EXPECT_TRUE(bullet.part_body(0).isInWorld());
  EXPECT_NE(bullet.probe(), nullptr);
  EXPECT_TRUE(bullet.part_body(0).isKinematicObject());
}

TEST(SoftWorld, ClampJawsSitEitherSideOfTheGap) {
  const SceneDescription scene = load_scene("scenes/clamp-sphere.toml");
  ASSERT_EQ(tool_part_geometry(scene).part_count, 2);
  ToolPose tool;
  tool.position_world_m = {0.0, 0.06, 0.0};
  tool.orientation_world = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX());  // tool y → world z
  std::array<ToolPose, kMaxToolParts> parts{};
  tool_part_poses(scene, tool, 0.08, parts);
  const double offset = 0.5 * (0.08 + 0.003);
  EXPECT_TRUE(parts[0].position_world_m.isApprox(Eigen::Vector3d(0, 0.06, offset), 1e-12));
  EXPECT_TRUE(parts[1].position_world_m.isApprox(Eigen::Vector3d(0, 0.06, -offset), 1e-12));
  tool_part_poses(scene, tool, 1.0, parts);  // clamped to the fully open gap
  EXPECT_NEAR(parts[0].position_world_m.z(), 0.5 * (0.12 + 0.003), 1e-12);
}

TEST(SoftWorld, VesselAndSlabBuild) {
  const SceneDescription vessel = load_scene("scenes/clamp-vessel.toml");
  SoftWorld world(vessel, false);
  const SoftCylinder& c = std::get<SoftCylinder>(vessel.soft_bodies.front().shape);
  EXPECT_EQ(world.soft().m_nodes.size(), c.segments_count * c.rings_count + 2);
  SceneDescription slab = vessel;
  slab.soft_bodies.front().shape = SoftSlab{};
  SoftWorld slab_world(slab, false);
  int pinned = 0;
  for (int i = 0; i < slab_world.soft().m_nodes.size(); ++i) pinned += slab_world.soft().m_nodes[i].m_im == 0 ? 1 : 0;
  EXPECT_EQ(pinned, 17 * 17);
}

}  // namespace
}  // namespace fissure::host
