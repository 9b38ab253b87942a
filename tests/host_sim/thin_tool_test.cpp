// ToolNodes: node placement and pairing at load (BRIEF §3 item 1), and the generated convex
// spatula mesh with rounded rims (paper Fig. 1 middle / Fig. 2).
#include <fissure/host_sim/thin_tool.hpp>

#include "fissure/host_sim/mesh_bvh.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace fissure::host {
namespace {

BoxToolShape plate_shape() {
  BoxToolShape shape;
  shape.half_extents_m = Eigen::Vector3d(0.02, 0.002, 0.02);
  shape.thin_axis = 1;
  shape.nodes_u = 9;
  shape.nodes_v = 7;
  return shape;
}

TEST(ToolNodesBox, GridOnBothLargeFacesPairedAcrossTheThickness) {
  const ToolNodes tool = ToolNodes::from_box(plate_shape());
  // Node count changed with the edge nodes: 2·9·7 face nodes (indices unchanged, first) + the
  // unpaired edge rows 2·7 (sides normal to x, along z) + 2·9 (sides normal to z, along x).
  constexpr int kFaceNodes = 2 * 9 * 7;
  ASSERT_EQ(tool.node_count(), kFaceNodes + 2 * 7 + 2 * 9);
  EXPECT_EQ(tool.pairing_report().mutual, kFaceNodes);
  EXPECT_EQ(tool.pairing_report().one_way, 0);
  EXPECT_EQ(tool.pairing_report().unpaired, 2 * 7 + 2 * 9);
  EXPECT_TRUE(tool.is_thin());
  EXPECT_EQ(tool.thin_axis(), 1);
  EXPECT_DOUBLE_EQ(tool.thickness_m(), 0.004);
  for (int i = 0; i < kFaceNodes; ++i) {
    const auto& p = tool.positions_tool_m()[static_cast<std::size_t>(i)];
    const auto& n = tool.normals_tool()[static_cast<std::size_t>(i)];
    const int pair = tool.pair_of()[static_cast<std::size_t>(i)];
    const auto& q = tool.positions_tool_m()[static_cast<std::size_t>(pair)];
    EXPECT_NEAR(std::abs(p.y()), 0.002, 1e-15) << "node on a large face";
    EXPECT_DOUBLE_EQ(n.y(), p.y() > 0 ? 1.0 : -1.0) << "outward normal";
    EXPECT_DOUBLE_EQ(p.x(), q.x());
    EXPECT_DOUBLE_EQ(p.z(), q.z());
    EXPECT_DOUBLE_EQ(p.y(), -q.y()) << "pair across the thickness";
    EXPECT_EQ(tool.pair_of()[static_cast<std::size_t>(pair)], i);
    // The node's plane is the face it lies on.
    const ToolPlane& plane = tool.planes()[static_cast<std::size_t>(tool.plane_of_node()[static_cast<std::size_t>(i)])];
    EXPECT_NEAR(plane.normal_tool.dot(p) - plane.offset_m, 0.0, 1e-15);
    EXPECT_DOUBLE_EQ(plane.normal_tool.dot(n), 1.0);
  }
  // Grid covers the face to its edges.
  double max_x = 0.0;
  for (const auto& p : tool.positions_tool_m()) max_x = std::max(max_x, p.x());
  EXPECT_DOUBLE_EQ(max_x, 0.02);
}

// Edge (rim) nodes: one row along the middle of each thin side face, at the face grid's
// positions along its long direction, unpaired, on that side's plane with its outward normal.
TEST(ToolNodesBox, EdgeNodesOnTheFourSideFacesUnpaired) {
  const ToolNodes tool = ToolNodes::from_box(plate_shape());
  constexpr int kFaceNodes = 2 * 9 * 7;
  ASSERT_EQ(tool.edge_node_count(), 2 * 7 + 2 * 9);
  int per_side[6] = {0, 0, 0, 0, 0, 0};
  for (int i = 0; i < tool.node_count(); ++i) {
    const auto n = static_cast<std::size_t>(i);
    EXPECT_EQ(tool.edge_node_flags()[n] != 0, i >= kFaceNodes) << "edge nodes come after the face nodes";
    if (i < kFaceNodes) continue;
    const Eigen::Vector3d& p = tool.positions_tool_m()[n];
    const Eigen::Vector3d& normal = tool.normals_tool()[n];
    EXPECT_EQ(tool.pair_of()[n], -1);
    EXPECT_DOUBLE_EQ(p.y(), 0.0) << "middle of the thickness";
    EXPECT_DOUBLE_EQ(normal.y(), 0.0);
    const int plane_index = tool.plane_of_node()[n];
    const ToolPlane& plane = tool.planes()[static_cast<std::size_t>(plane_index)];
    EXPECT_NEAR(plane.normal_tool.dot(p) - plane.offset_m, 0.0, 1e-15) << "on its side face";
    EXPECT_DOUBLE_EQ(plane.normal_tool.dot(normal), 1.0);
    EXPECT_DOUBLE_EQ(tool.signed_distance_m(p), 0.0);
    ++per_side[plane_index];
  }
  EXPECT_EQ(per_side[0], 7);  // +x side: along z, nodes_v
  EXPECT_EQ(per_side[1], 7);
  EXPECT_EQ(per_side[2], 0);  // large faces ±y: none
  EXPECT_EQ(per_side[3], 0);
  EXPECT_EQ(per_side[4], 9);  // +z side: along x, nodes_u
  EXPECT_EQ(per_side[5], 9);
  BoxToolShape faces_only = plate_shape();
  faces_only.edge_nodes = false;
  EXPECT_EQ(ToolNodes::from_box(faces_only).node_count(), kFaceNodes);
  EXPECT_EQ(ToolNodes::from_box(faces_only).edge_node_count(), 0);
}

TEST(ToolNodesBox, SignedDistanceAndFootprint) {
  const ToolNodes tool = ToolNodes::from_box(plate_shape());
  EXPECT_NEAR(tool.signed_distance_m(Eigen::Vector3d(0, 0, 0)), -0.002, 1e-15);
  EXPECT_NEAR(tool.signed_distance_m(Eigen::Vector3d(0.01, 0.0015, 0)), -0.0005, 1e-15);
  EXPECT_NEAR(tool.signed_distance_m(Eigen::Vector3d(0, -0.003, 0)), 0.001, 1e-15);
  EXPECT_TRUE(tool.in_footprint(Eigen::Vector3d(0.019, 0.5, -0.019)));
  EXPECT_FALSE(tool.in_footprint(Eigen::Vector3d(0.021, 0.0, 0.0)));
}

TEST(ToolNodesBox, RejectsBadShapes) {
  BoxToolShape shape = plate_shape();
  shape.thin_axis = 3;
  EXPECT_THROW((void)ToolNodes::from_box(shape), std::invalid_argument);
  shape = plate_shape();
  shape.nodes_u = 0;
  EXPECT_THROW((void)ToolNodes::from_box(shape), std::invalid_argument);
  shape = plate_shape();
  shape.half_extents_m.y() = 0.0;
  EXPECT_THROW((void)ToolNodes::from_box(shape), std::invalid_argument);
}

constexpr double kThickness_m = 0.002;

// The rim the in-solver rim constraint drapes soft triangles over: a box's 12 edges, each the
// length of one of its extents.
TEST(ToolNodesBox, FeatureEdgesAreTheTwelveBoxEdges) {
  const ToolNodes tool = ToolNodes::from_box(plate_shape());
  const auto& edges = tool.feature_edges_tool_m();
  ASSERT_EQ(edges.size(), 12u);
  int along[3] = {0, 0, 0};
  for (const auto& e : edges) {
    const Eigen::Vector3d d = (e[1] - e[0]).cwiseAbs();
    int axis = 0;
    d.maxCoeff(&axis);
    EXPECT_NEAR(d[axis], 2.0 * plate_shape().half_extents_m[axis], 1e-15);
    EXPECT_NEAR(d.sum(), d[axis], 1e-15) << "an edge runs along one axis";
    ++along[axis];
  }
  EXPECT_EQ(along[0], 4);
  EXPECT_EQ(along[1], 4);
  EXPECT_EQ(along[2], 4);
}

// A mesh's feature edges are the triangle edges between two different planes: a cube split into
// 12 triangles has its 12 cube edges, not the 6 face diagonals.
TEST(ToolNodesConvexMesh, FeatureEdgesLeaveOutEdgesInsideAFlatFace) {
  ConvexMeshToolShape cube;
  for (int c = 0; c < 8; ++c) cube.vertices_tool_m.emplace_back((c & 1) ? 0.01 : -0.01, (c & 2) ? 0.001 : -0.001, (c & 4) ? 0.01 : -0.01);
  // Two triangles per face, outward (counter-clockwise seen from outside).
  cube.triangles = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                    {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  const ToolNodes tool = ToolNodes::from_convex_mesh(cube);
  ASSERT_EQ(tool.planes().size(), 6u);
  const auto& edges = tool.feature_edges_tool_m();
  ASSERT_EQ(edges.size(), 12u);
  for (const auto& e : edges) {
    const Eigen::Vector3d d = (e[1] - e[0]).cwiseAbs();
    EXPECT_EQ((d.array() > 1e-12).count(), 1) << "a cube edge, not a face diagonal: " << d.transpose();
  }
}

TEST(RoundedSpatulaMesh, IsAClosedConvexThinMeshWithManyRimTriangles) {
  RoundedSpatulaParams params;
  params.thickness_m = kThickness_m;
  const ConvexMeshToolShape mesh = make_rounded_spatula_mesh(params, 3.0 * kThickness_m);
  const ToolNodes tool = ToolNodes::from_convex_mesh(mesh);  // throws if not convex / closed
  EXPECT_EQ(tool.node_count(), static_cast<int>(mesh.triangles.size()));
  EXPECT_EQ(tool.thin_axis(), 1);
  EXPECT_NEAR(tool.thickness_m(), kThickness_m, 1e-12);
  // The sampled rim profile lies inside the true half circle (chord sag ≤ r·(1 − cos(π/2/segments))).
  EXPECT_LE(tool.bounds_tool_m().sizes().x(), params.length_m + 1e-12);
  EXPECT_NEAR(tool.bounds_tool_m().sizes().x(), params.length_m, 1e-4);
  EXPECT_NEAR(tool.bounds_tool_m().sizes().z(), params.width_m, 1e-4);
  // Every node's plane passes through it with the node's normal; the flat faces merge to one plane each.
  int on_top = 0;
  for (int i = 0; i < tool.node_count(); ++i) {
    const auto& p = tool.positions_tool_m()[static_cast<std::size_t>(i)];
    const ToolPlane& plane = tool.planes()[static_cast<std::size_t>(tool.plane_of_node()[static_cast<std::size_t>(i)])];
    EXPECT_NEAR(plane.normal_tool.dot(p), plane.offset_m, 1e-12);
    EXPECT_GT(plane.normal_tool.dot(tool.normals_tool()[static_cast<std::size_t>(i)]), 1.0 - 1e-9);
    if (tool.normals_tool()[static_cast<std::size_t>(i)].y() > 1.0 - 1e-12) ++on_top;
  }
  EXPECT_GT(on_top, 20);
  EXPECT_LT(static_cast<int>(tool.planes().size()), tool.node_count()) << "coplanar triangles share a plane";
  // Rim triangles (paper Fig. 2): centroids far closer to one another than the thickness.
  double min_rim_spacing = 1.0;
  for (int i = 0; i < tool.node_count(); ++i) {
    if (std::abs(tool.normals_tool()[static_cast<std::size_t>(i)].y()) > 0.999) continue;
    for (int j = i + 1; j < tool.node_count(); ++j) {
      if (std::abs(tool.normals_tool()[static_cast<std::size_t>(j)].y()) > 0.999) continue;
      min_rim_spacing = std::min(min_rim_spacing, (tool.positions_tool_m()[static_cast<std::size_t>(i)] -
                                                   tool.positions_tool_m()[static_cast<std::size_t>(j)]).norm());
    }
  }
  EXPECT_LT(min_rim_spacing, 0.5 * kThickness_m);
  // Edge flags: exactly the triangles more than 60° off the thin axis.
  int edge = 0;
  for (int i = 0; i < tool.node_count(); ++i) {
    const bool rim = std::abs(tool.normals_tool()[static_cast<std::size_t>(i)].y()) < 0.5;
    EXPECT_EQ(tool.edge_node_flags()[static_cast<std::size_t>(i)] != 0, rim);
    edge += rim ? 1 : 0;
  }
  EXPECT_GT(edge, 0);
  EXPECT_EQ(tool.edge_node_count(), edge);
}

// The rim's ball tree over feature edges: every edge sits in exactly one leaf, every ball holds
// its edges and its children whole (so a ball that misses a query holds nothing that meets it),
// and the depth stays within the traversal's fixed stack.
TEST(ToolNodesConvexMesh, FeatureEdgeBallTreeHoldsEveryEdgeWhole) {
  RoundedSpatulaParams params;
  params.thickness_m = kThickness_m;
  for (const ToolNodes& tool : {ToolNodes::from_convex_mesh(make_rounded_spatula_mesh(params, 3.0 * kThickness_m)),
                                ToolNodes::from_box(plate_shape())}) {
    const auto& edges = tool.feature_edges_tool_m();
    const auto& balls = tool.feature_edge_balls();
    const auto& order = tool.feature_edge_ball_order();
    ASSERT_FALSE(balls.empty());
    ASSERT_EQ(order.size(), edges.size());
    std::vector<int> seen(edges.size(), 0);
    const double slack_m = 1e-12;
    struct Visit { int ball; int depth; };
    std::vector<Visit> pending{{0, 1}};
    int deepest = 0;
    while (!pending.empty()) {
      const Visit visit = pending.back();
      pending.pop_back();
      deepest = std::max(deepest, visit.depth);
      const auto& ball = balls[static_cast<std::size_t>(visit.ball)];
      for (int i = ball.begin; i < ball.end; ++i) {
        const auto& edge = edges[static_cast<std::size_t>(order[static_cast<std::size_t>(i)])];
        EXPECT_LE((edge[0] - ball.centre_tool_m).norm(), ball.radius_m + slack_m);
        EXPECT_LE((edge[1] - ball.centre_tool_m).norm(), ball.radius_m + slack_m);
      }
      if (ball.first_child < 0) {
        for (int i = ball.begin; i < ball.end; ++i) ++seen[static_cast<std::size_t>(order[static_cast<std::size_t>(i)])];
        continue;
      }
      for (int child = ball.first_child; child <= ball.first_child + 1; ++child) {
        const auto& inner = balls[static_cast<std::size_t>(child)];
        EXPECT_GE(inner.begin, ball.begin);
        EXPECT_LE(inner.end, ball.end);
        pending.push_back({child, visit.depth + 1});
      }
    }
    for (std::size_t e = 0; e < seen.size(); ++e) EXPECT_EQ(seen[e], 1) << "feature edge " << e;
    EXPECT_LE(deepest, ToolNodes::kFeatureEdgeBallDepth);
  }
}

// The paper's Fig. 2 problem and its fix: with an unlimited ray, rim nodes pair with nodes on the
// far side of the tool (across the edge); the limited ray leaves them unpaired instead.
TEST(ToolNodesConvexMesh, LimitedRayStopsRimNodesPairingAcrossTheEdge) {
  RoundedSpatulaParams params;
  params.thickness_m = kThickness_m;
  const double limit = 3.0 * kThickness_m;
  const ToolNodes limited = ToolNodes::from_convex_mesh(make_rounded_spatula_mesh(params, limit));
  const ToolNodes unlimited = ToolNodes::from_convex_mesh(make_rounded_spatula_mesh(params, 1.0));

  // How far apart (across the tool's plane, x–z) a node and its pair lie: a pair across the edge
  // of Fig. 2 joins opposite rims, a tool width apart.
  const auto widest_pair = [](const ToolNodes& tool) {
    double widest = 0.0;
    for (int i = 0; i < tool.node_count(); ++i) {
      const int pair = tool.pair_of()[static_cast<std::size_t>(i)];
      if (pair < 0) continue;
      Eigen::Vector3d d = tool.positions_tool_m()[static_cast<std::size_t>(i)] - tool.positions_tool_m()[static_cast<std::size_t>(pair)];
      d.y() = 0.0;
      widest = std::max(widest, d.norm());
    }
    return widest;
  };
  EXPECT_GT(widest_pair(unlimited), 0.5 * params.width_m) << "unlimited rays pair across the whole tool";
  EXPECT_LT(widest_pair(limited), 0.25 * params.width_m) << "the limited ray keeps pairs local";
  EXPECT_GT(limited.pairing_report().unpaired, unlimited.pairing_report().unpaired);

  for (const ToolNodes* tool : {&limited, &unlimited}) {
    const PairingReport& r = tool->pairing_report();
    EXPECT_EQ(r.mutual + r.one_way + r.unpaired, tool->node_count());
    EXPECT_GT(r.mutual, 0);
    EXPECT_GT(r.one_way, 0) << "pairs on a mesh are not always mutual (paper)";
    EXPECT_TRUE(tool->is_thin());
  }
  // Flat-face nodes pair straight across the thickness.
  for (int i = 0; i < limited.node_count(); ++i) {
    if (limited.normals_tool()[static_cast<std::size_t>(i)].y() < 1.0 - 1e-12) continue;
    const int pair = limited.pair_of()[static_cast<std::size_t>(i)];
    ASSERT_GE(pair, 0);
    EXPECT_NEAR(limited.positions_tool_m()[static_cast<std::size_t>(pair)].y(), -0.5 * kThickness_m, 1e-12);
  }
  // paired_by is the exact reverse of pair_of.
  int reverse_entries = 0;
  for (int i = 0; i < limited.node_count(); ++i) {
    for (int k = limited.paired_by_begin()[static_cast<std::size_t>(i)]; k < limited.paired_by_begin()[static_cast<std::size_t>(i + 1)]; ++k) {
      EXPECT_EQ(limited.pair_of()[static_cast<std::size_t>(limited.paired_by_nodes()[static_cast<std::size_t>(k)])], i);
      ++reverse_entries;
    }
  }
  EXPECT_EQ(reverse_entries, limited.pairing_report().mutual + limited.pairing_report().one_way);
}

TEST(ToolNodesConvexMesh, NoRayLimitMeansNotThin) {
  RoundedSpatulaParams params;
  const ToolNodes tool = ToolNodes::from_convex_mesh(make_rounded_spatula_mesh(params, 0.0));
  EXPECT_FALSE(tool.is_thin());
  EXPECT_EQ(tool.pairing_report().unpaired, tool.node_count());
}

TEST(ToolNodesConvexMesh, RejectsNonConvexAndBrokenMeshes) {
  ConvexMeshToolShape mesh = make_rounded_spatula_mesh(RoundedSpatulaParams{}, 0.006);
  ConvexMeshToolShape dented = mesh;
  dented.vertices_tool_m.front() *= 0.5;  // pull a rim vertex inward: a dent
  EXPECT_THROW((void)ToolNodes::from_convex_mesh(dented), std::invalid_argument);
  ConvexMeshToolShape bad_index = mesh;
  bad_index.triangles.front()[0] = static_cast<int>(mesh.vertices_tool_m.size());
  EXPECT_THROW((void)ToolNodes::from_convex_mesh(bad_index), std::invalid_argument);
  ConvexMeshToolShape too_small;
  EXPECT_THROW((void)ToolNodes::from_convex_mesh(too_small), std::invalid_argument);
  // Winding does not matter: a fully flipped mesh gives the same planes.
  ConvexMeshToolShape flipped = mesh;
  for (auto& t : flipped.triangles) std::swap(t[1], t[2]);
  const ToolNodes a = ToolNodes::from_convex_mesh(mesh);
  const ToolNodes b = ToolNodes::from_convex_mesh(flipped);
  ASSERT_EQ(a.node_count(), b.node_count());
  for (int i = 0; i < a.node_count(); ++i)
    EXPECT_TRUE(a.normals_tool()[static_cast<std::size_t>(i)].isApprox(b.normals_tool()[static_cast<std::size_t>(i)]));
  EXPECT_NEAR(a.signed_distance_m(Eigen::Vector3d::Zero()), -0.001, 1e-9);
}

// The box trees and the plane hash give what the scans they replaced gave: the same planes (each
// triangle on the first plane within 1 − 1e-9 in cosine and tol in offset) and the same pairs
// (nearest hit within the limit, the last of equal hits). The tilted copy puts the planes off
// the axes, across the hash's cell boundaries.
TEST(ToolNodesConvexMesh, PlanesAndPairsAreTheScansAnswers) {
  RoundedSpatulaParams params;
  params.corner_segments = 10;
  params.face_divisions = 12;
  const ConvexMeshToolShape flat = make_rounded_spatula_mesh(params, 3.0 * params.thickness_m);
  ConvexMeshToolShape tilted = flat;
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1.0, 2.0, 3.0).normalized()));
  for (auto& v : tilted.vertices_tool_m) v = turn * v;
  for (const ConvexMeshToolShape* shape : {&flat, static_cast<const ConvexMeshToolShape*>(&tilted)}) {
    // The scans, as from_convex_mesh ran them before the trees.
    const auto& verts = shape->vertices_tool_m;
    Eigen::AlignedBox3d box;
    for (const auto& p : verts) box.extend(p);
    const double tol_m = 1e-6 * box.diagonal().norm();
    std::vector<Eigen::Vector3d> n, a, b, c;
    for (const auto& t : shape->triangles) {
      a.push_back(verts[static_cast<std::size_t>(t[0])]);
      b.push_back(verts[static_cast<std::size_t>(t[1])]);
      c.push_back(verts[static_cast<std::size_t>(t[2])]);
      n.push_back((b.back() - a.back()).cross(c.back() - a.back()).normalized());  // outward: the generator's winding
    }
    std::vector<ToolPlane> planes;
    std::vector<int> plane_of;
    for (std::size_t f = 0; f < n.size(); ++f) {
      const double offset = n[f].dot(a[f]);
      int index = -1;
      for (std::size_t q = 0; q < planes.size() && index < 0; ++q)
        if (planes[q].normal_tool.dot(n[f]) > 1.0 - 1e-9 && std::abs(planes[q].offset_m - offset) <= tol_m) index = static_cast<int>(q);
      if (index < 0) {
        index = static_cast<int>(planes.size());
        planes.push_back(ToolPlane{n[f], offset});
      }
      plane_of.push_back(index);
    }
    const ToolNodes tool = ToolNodes::from_convex_mesh(*shape);
    ASSERT_EQ(tool.planes().size(), planes.size());
    EXPECT_EQ(tool.plane_of_node(), plane_of);
    for (std::size_t i = 0; i < n.size(); ++i) {
      const Eigen::Vector3d origin = (a[i] + b[i] + c[i]) / 3.0;
      double best_t = shape->pairing_ray_limit_m;
      int best = -1;
      for (std::size_t j = 0; j < n.size(); ++j) {
        if (j == i) continue;
        const double t = ray_triangle(origin, -n[i], a[j], b[j], c[j]);
        if (t > tol_m && t <= best_t) {
          best_t = t;
          best = static_cast<int>(j);
        }
      }
      EXPECT_EQ(tool.pair_of()[i], best) << "node " << i << (shape == &tilted ? " (tilted)" : "");
    }
  }
}

}  // namespace
}  // namespace fissure::host
