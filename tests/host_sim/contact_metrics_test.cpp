// Crossed nodes and penetration on hand-built configurations: the ruler every method is
// judged by must itself be right.
#include "fissure/host_sim/contact_metrics.hpp"

#include <gtest/gtest.h>

#include <array>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

namespace fissure::host {
namespace {

// A 40 × 4 × 40 mm plate (BRIEF §3's measurement plate), thin axis y.
const Eigen::Vector3d kPlateHalf_m(0.02, 0.002, 0.02);

Eigen::Isometry3d at(double x, double y, double z) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(x, y, z);
  return t;
}

TEST(ToolVolume, BoxSignedDistanceAndFootprint) {
  const ToolVolume box = ToolVolume::from_box(kPlateHalf_m);
  EXPECT_DOUBLE_EQ(box.half_thickness_m(), 0.002);
  EXPECT_NEAR(box.signed_distance_m({0, 0, 0}), -0.002, 1e-15);          // centre: depth = half thickness
  EXPECT_NEAR(box.signed_distance_m({0.019, 0.0015, 0}), -0.0005, 1e-15);  // nearest face: top
  EXPECT_NEAR(box.signed_distance_m({0, 0.003, 0}), 0.001, 1e-15);       // 1 mm above
  EXPECT_TRUE(box.in_footprint({0.0199, 0.5, -0.0199}));                 // any height
  EXPECT_FALSE(box.in_footprint({0.0201, 0.0, 0.0}));
}

TEST(ToolVolume, ConvexMeshOfABoxAgreesWithTheBox) {
  // The same plate as 12 outward triangles.
  std::vector<Eigen::Vector3d> v;
  for (int i = 0; i < 8; ++i) {
    v.emplace_back((i & 1 ? 1 : -1) * kPlateHalf_m.x(), (i & 2 ? 1 : -1) * kPlateHalf_m.y(), (i & 4 ? 1 : -1) * kPlateHalf_m.z());
  }
  const std::vector<std::array<int, 3>> t = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                                             {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  const ToolVolume mesh = ToolVolume::from_convex_mesh(v, t);
  const ToolVolume box = ToolVolume::from_box(kPlateHalf_m);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.03, 0.03);
  for (int k = 0; k < 1000; ++k) {
    const Eigen::Vector3d p(u(rng), u(rng) * 0.2, u(rng));
    EXPECT_NEAR(mesh.signed_distance_m(p), box.signed_distance_m(p), 1e-12);
    EXPECT_EQ(mesh.in_footprint(p), box.in_footprint(p));
  }
  EXPECT_NEAR(mesh.half_thickness_m(), 0.002, 1e-15);
}

// The plate given as its six face planes and eight corners (as a ToolNodes holds it) is the box.
TEST(ToolVolume, PlanesAndCornersOfABoxAgreeWithTheBox) {
  std::vector<Eigen::Vector3d> corners;
  for (int i = 0; i < 8; ++i) {
    corners.emplace_back((i & 1 ? 1 : -1) * kPlateHalf_m.x(), (i & 2 ? 1 : -1) * kPlateHalf_m.y(), (i & 4 ? 1 : -1) * kPlateHalf_m.z());
  }
  std::vector<std::pair<Eigen::Vector3d, double>> planes;
  for (int axis = 0; axis < 3; ++axis)
    for (const double sign : {1.0, -1.0}) planes.emplace_back(sign * Eigen::Vector3d::Unit(axis), kPlateHalf_m[axis]);
  const ToolVolume from_planes = ToolVolume::from_planes(planes, corners);
  const ToolVolume box = ToolVolume::from_box(kPlateHalf_m);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.03, 0.03);
  std::vector<Eigen::Vector3d> scratch;
  for (int k = 0; k < 1000; ++k) {
    const Eigen::Vector3d p(u(rng), u(rng) * 0.2, u(rng));
    EXPECT_EQ(from_planes.signed_distance_m(p), box.signed_distance_m(p));
    EXPECT_EQ(from_planes.in_footprint(p), box.in_footprint(p));
    const Eigen::Vector3d q(u(rng), u(rng) * 0.2, u(rng)), r(u(rng), u(rng) * 0.2, u(rng));
    EXPECT_EQ(from_planes.reaches_inside(p, q, r, 1e-4, scratch), box.reaches_inside(p, q, r, 1e-4, scratch));
  }
  EXPECT_NEAR(from_planes.half_thickness_m(), 0.002, 1e-15);
  EXPECT_THROW((void)ToolVolume::from_planes({planes.begin(), planes.begin() + 3}, corners), std::invalid_argument);
}

// A 1 mm blade slicing a coarse triangle between its vertices: every vertex is 10 mm outside,
// the triangle's middle is 0.5 mm deep (the half thickness). A 12-per-edge sample grid (1.7 mm
// apart on this 20 mm triangle) can fall either side of the blade; the clip cannot.
TEST(ToolVolume, ReachesInsideFindsATriangleSlicedBetweenItsVertices) {
  const ToolVolume blade = ToolVolume::from_box({0.05, 0.0005, 0.05});
  std::vector<Eigen::Vector3d> scratch;
  const Eigen::Vector3d a(-0.01, -0.01, 0.0), b(0.01, -0.01, 0.0), c(0.0, 0.01, 0.0);
  for (const Eigen::Vector3d& v : {a, b, c}) EXPECT_GT(blade.signed_distance_m(v), 0.009);
  EXPECT_TRUE(blade.reaches_inside(a, b, c, 1e-4, scratch));
  EXPECT_TRUE(blade.reaches_inside(a, b, c, 4.9e-4, scratch));   // just under the 0.5 mm it reaches
  EXPECT_FALSE(blade.reaches_inside(a, b, c, 5.1e-4, scratch));  // just over
  // Beside the blade (x beyond its 50 mm half length), or above it: not cut.
  const Eigen::Vector3d beside(0.07, 0.0, 0.0);
  EXPECT_FALSE(blade.reaches_inside(a + beside, b + beside, c + beside, 1e-4, scratch));
  const Eigen::Vector3d above(0.0, 0.0106, 0.0);
  EXPECT_FALSE(blade.reaches_inside(a + above, b + above, c + above, 1e-4, scratch));
  // A triangle lying flat in the blade's mid-plane is inside over its whole area.
  EXPECT_TRUE(blade.reaches_inside({-0.01, 0, -0.01}, {0.01, 0, -0.01}, {0, 0, 0.01}, 1e-4, scratch));
}

TEST(ToolVolume, TrianglesCutCountsOnlyTheSlicedOnesInTheToolsOwnFrame) {
  const ToolVolume blade = ToolVolume::from_box({0.05, 0.0005, 0.05});
  // The tool at x = 1 m, turned 90° about z: its thin axis is world x.
  Eigen::Isometry3d tool_to_world = at(1.0, 0.0, 0.0);
  tool_to_world.rotate(Eigen::AngleAxisd(0.5 * 3.14159265358979323846, Eigen::Vector3d::UnitZ()));
  const std::vector<Eigen::Vector3d> nodes = {
      {0.99, -0.01, 0.0}, {1.01, -0.01, 0.0}, {1.0, 0.01, 0.0},    // spans world x across the blade: cut
      {0.99, 0.02, 0.0},  {0.99, 0.04, 0.0},  {0.99, 0.03, 0.01},  // 10 mm to its side: not
  };
  const std::vector<std::array<int, 3>> faces = {{0, 1, 2}, {3, 4, 5}};
  EXPECT_EQ(triangles_cut_by_volume(blade, nodes, faces, tool_to_world, 1e-4), 1);
  EXPECT_EQ(triangles_cut_by_volume(blade, nodes, faces, at(1.0, 0.0, 0.0), 1e-4), 1);  // unturned: the first still spans y
  EXPECT_EQ(triangles_cut_by_volume(blade, nodes, faces, at(1.2, 0.0, 0.0), 1e-4), 0);  // moved away
}

TEST(CrossingTracker, NodePushedThroughThePlateIsCrossed) {
  CrossingTracker tracker(ToolVolume::from_box(kPlateHalf_m), 3);
  // Node 0 under the plate's footprint below it, node 1 outside the footprint, node 2 above.
  std::vector<Eigen::Vector3d> nodes = {{0.0, -0.01, 0.0}, {0.05, -0.01, 0.0}, {0.01, 0.01, 0.0}};
  tracker.reset(nodes, at(0, 0, 0));
  CrossingSnapshot s = tracker.update(nodes, at(0, 0, 0));
  EXPECT_EQ(s.crossed_nodes, 0);
  EXPECT_EQ(s.max_penetration_m, 0.0);

  // The plate jumps down 2 cm in one step (tunnelling): node 0 is now above its mid-plane.
  s = tracker.update(nodes, at(0, -0.02, 0));
  EXPECT_EQ(s.wrong_side_nodes, 1);
  EXPECT_EQ(s.crossed_nodes, 1);
  EXPECT_EQ(s.inside_nodes, 0);
  // It stays crossed while it stays under the footprint.
  s = tracker.update(nodes, at(0, -0.03, 0));
  EXPECT_EQ(s.crossed_nodes, 1);
}

TEST(CrossingTracker, GoingRoundTheRimIsNotCrossing) {
  CrossingTracker tracker(ToolVolume::from_box(kPlateHalf_m), 1);
  std::vector<Eigen::Vector3d> node = {{0.0, -0.01, 0.0}};
  tracker.reset(node, at(0, 0, 0));
  // The node walks out past the rim, up, and back in above the plate.
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.03, -0.01, 0), Eigen::Vector3d(0.03, 0.01, 0), Eigen::Vector3d(0.0, 0.01, 0)}) {
    node[0] = p;
    EXPECT_EQ(tracker.update(node, at(0, 0, 0)).crossed_nodes, 0) << p.transpose();
  }
  EXPECT_EQ(tracker.sides()[0], 1);
}

TEST(CrossingTracker, SlidingAlongASideFaceIsNotCrossing) {
  // The paired method holds a node on a side (rim) face; its projection is then on the
  // footprint's edge, and it may slide past the mid-plane along the face (bench collision:
  // convex spatula at 2 m/s reported 1 wrong-side node that was exactly this).
  CrossingTracker tracker(ToolVolume::from_box(kPlateHalf_m), 1);
  std::vector<Eigen::Vector3d> node = {{0.0, -0.01, 0.0}};
  tracker.reset(node, at(0, 0, 0));
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.02, -0.001, 0), Eigen::Vector3d(0.02, 0.001, 0), Eigen::Vector3d(0.0, 0.01, 0)}) {
    node[0] = p;
    EXPECT_EQ(tracker.update(node, at(0, 0, 0)).crossed_nodes, 0) << p.transpose();
  }
  // Just inside the side face it is inside the plate, where the memory stays frozen.
  node[0] = {0.0, -0.01, 0.0};
  tracker.reset(node, at(0, 0, 0));
  node[0] = {0.0199, 0.001, 0.0};
  EXPECT_EQ(tracker.update(node, at(0, 0, 0)).wrong_side_nodes, 1);
}

TEST(CrossingTracker, PenetrationAndInsideTolerance) {
  CrossingTracker tracker(ToolVolume::from_box(kPlateHalf_m), 2);
  std::vector<Eigen::Vector3d> nodes = {{0.0, -0.01, 0.0}, {0.01, -0.01, 0.0}};
  tracker.reset(nodes, at(0, 0, 0));
  nodes[0] = {0.0, -0.002 + 0.5 * kInsideToleranceM, 0.0};  // within tolerance: penetrates, not "inside"
  nodes[1] = {0.01, -0.0015, 0.0};                          // 0.5 mm inside from below: inside, right side
  const CrossingSnapshot s = tracker.update(nodes, at(0, 0, 0));
  EXPECT_NEAR(s.max_penetration_m, 0.0005, 1e-12);
  EXPECT_EQ(s.inside_nodes, 1);
  EXPECT_EQ(s.wrong_side_nodes, 0);
  EXPECT_EQ(s.crossed_nodes, 1);
}

TEST(CrossingTracker, RotatedToolUsesItsOwnThinAxis) {
  // A blade standing on edge: tool y (thin axis) along world x.
  Eigen::Isometry3d blade = Eigen::Isometry3d::Identity();
  blade.linear() = Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();  // tool y → world x
  CrossingTracker tracker(ToolVolume::from_box(kPlateHalf_m), 1);
  std::vector<Eigen::Vector3d> node = {{-0.01, 0.0, 0.0}};  // on the blade's −x side
  tracker.reset(node, blade);
  EXPECT_EQ(tracker.update(node, blade).crossed_nodes, 0);
  node[0] = {0.01, 0.0, 0.0};  // moved through the blade to +x
  EXPECT_EQ(tracker.update(node, blade).crossed_nodes, 1);
}

}  // namespace
}  // namespace fissure::host
