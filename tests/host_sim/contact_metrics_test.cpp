// Crossed nodes and penetration on hand-built configurations: the ruler every method is
// judged by must itself be right.
#include "fissure/host_sim/contact_metrics.hpp"

#include <gtest/gtest.h>

#include <random>

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
