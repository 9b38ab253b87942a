// The in-solver rim constraint (issue 22, item 2): a soft triangle draped over the tool's rim is
// tented over it, not cut between its nodes.
//
// Why a second primitive: the paired-node stages keep every soft *node* out of the tool, but a
// coarse triangle (24 mm on the paper's 128-face ball) can lie across a 1 mm blade's edge or a
// plate's rim with all three nodes outside while the tool passes through its interior. The node
// projection cannot see that; this constraint is the point–triangle primitive of cloth and IPC
// contact with the tool's feature edges as the points.
//
// The test is exact for a convex tool: over the intersection of the tool with the triangle's
// prism (the triangle swept along its normal), the lowest and highest height above the
// triangle's plane are reached at a vertex of that convex set — a tool feature edge where it
// enters or leaves the prism, or a triangle vertex's normal line where it enters or leaves the
// tool. The triangle is cut when the tool is both in front of and behind its plane inside the
// prism; it is then moved back (against its outward normal, into the body) until the deepest
// tool point lies on it, its free vertices weighted by that point's barycentric coordinates and
// their inverse masses (the point–triangle projection of position-based dynamics). Only a cut
// at most a tool thickness + solver_reach deep is resolved: a deeper one is a tool inside the
// body under the triangle, not a rim across it, and moving the surface that far in one iteration
// would tear it.
#include "collision_state.hpp"

#include <BulletSoftBody/btSoftBody.h>

#include <algorithm>
#include <array>
#include <limits>

namespace fissure::host::thin_body {
namespace {

constexpr double kMaxLever = 3.0;
// Up to this many tool planes, testing each as a separating plane costs less than the prism clip.
constexpr std::size_t kPlanesWorthTesting = 16;

// The segment a → b clipped to the half-spaces m_k·(p − o_k) ≥ 0: false when nothing is left.
bool clip_to_prism(const std::array<Eigen::Vector3d, 3>& side_normal, const std::array<Eigen::Vector3d, 3>& side_origin,
                   const Eigen::Vector3d& a, const Eigen::Vector3d& b, double& t0, double& t1) {
  t0 = 0.0;
  t1 = 1.0;
  const Eigen::Vector3d d = b - a;
  for (std::size_t k = 0; k < 3; ++k) {
    const double fa = side_normal[k].dot(a - side_origin[k]);
    const double fd = side_normal[k].dot(d);
    if (fd == 0.0) {
      if (fa < 0.0) return false;
      continue;
    }
    const double t = -fa / fd;
    if (fd > 0.0) {
      t0 = std::max(t0, t);
    } else {
      t1 = std::min(t1, t);
    }
    if (t0 > t1) return false;
  }
  return true;
}

// Whether the line x + s·n meets the box grown by kInsideTolerance_m (slab test). The tool lies in
// its vertices' box, so a line that misses it misses the tool; the margin keeps rounding from
// rejecting a line the plane clip would keep.
bool line_meets_box(const Eigen::AlignedBox3d& box, const Eigen::Vector3d& x, const Eigen::Vector3d& n) {
  double s0 = -std::numeric_limits<double>::infinity();
  double s1 = std::numeric_limits<double>::infinity();
  for (int axis = 0; axis < 3; ++axis) {
    const double lo = box.min()[axis] - kInsideTolerance_m - x[axis];
    const double hi = box.max()[axis] + kInsideTolerance_m - x[axis];
    if (n[axis] == 0.0) {
      if (lo > 0.0 || hi < 0.0) return false;
      continue;
    }
    const double a = lo / n[axis], b = hi / n[axis];
    s0 = std::max(s0, std::min(a, b));
    s1 = std::min(s1, std::max(a, b));
    if (s0 > s1) return false;
  }
  return true;
}

// The line x + s·n clipped to the tool (every plane: normal·p ≤ offset): false when it misses.
bool clip_line_to_tool(const std::vector<ToolPlane>& planes, const Eigen::Vector3d& x, const Eigen::Vector3d& n, double& s0, double& s1) {
  s0 = -std::numeric_limits<double>::infinity();
  s1 = std::numeric_limits<double>::infinity();
  for (const ToolPlane& q : planes) {
    const double room = q.offset_m - q.normal_tool.dot(x);
    const double rate = q.normal_tool.dot(n);
    if (rate == 0.0) {
      if (room < 0.0) return false;
      continue;
    }
    const double s = room / rate;
    if (rate > 0.0) {
      s1 = std::min(s1, s);
    } else {
      s0 = std::max(s0, s);
    }
    if (s0 > s1) return false;
  }
  return true;
}

// Whether the triangle's three corners lie on or in front of `plane`.
bool corners_in_front_of(const ToolPlane& plane, const SoftTriangleInTool& triangle) {
  return plane.normal_tool.dot(triangle.x[0]) >= plane.offset_m && plane.normal_tool.dot(triangle.x[1]) >= plane.offset_m &&
         plane.normal_tool.dot(triangle.x[2]) >= plane.offset_m;
}

// Whether a tool plane that one of the triangle's corners is held on this step has all three
// corners on or in front of it.
bool separated_by_a_held_plane(const CollisionModel& model, const StepFrame& frame, const CollisionData& data, const std::array<int, 3>& nodes,
                               const SoftTriangleInTool& triangle) {
  for (const int node : nodes) {
    const auto n = static_cast<std::size_t>(node);
    if (data.displacement.hold_stamp[n] != frame.step || data.displacement.hold_plane[n] < 0) continue;
    if (corners_in_front_of(model.tool.planes()[static_cast<std::size_t>(data.displacement.hold_plane[n])], triangle)) return true;
  }
  return false;
}

// Whether some tool face plane has all three of the triangle's corners on or in front of it.
bool separated_by_a_tool_plane(const CollisionModel& model, const SoftTriangleInTool& triangle) {
  return std::any_of(model.tool.planes().begin(), model.tool.planes().end(),
                     [&triangle](const ToolPlane& plane) { return corners_in_front_of(plane, triangle); });
}

}  // namespace

bool soft_triangle_in_tool(const CollisionModel& model, const StepFrame& frame, const btSoftBody& soft, int face, SoftTriangleInTool& out) {
  const std::array<int, 3>& nodes = model.soft.face_nodes[static_cast<std::size_t>(face)];
  for (std::size_t k = 0; k < 3; ++k) out.x[k] = to_tool(frame, soft.m_nodes[nodes[k]].m_x);
  out.normal = model.soft.outward_sign * (out.x[1] - out.x[0]).cross(out.x[2] - out.x[0]);
  out.twice_area = out.normal.norm();
  if (!(out.twice_area > 0.0)) return false;
  out.normal /= out.twice_area;
  return true;
}

std::array<double, 3> barycentric_of_foot(const SoftTriangleInTool& triangle, const Eigen::Vector3d& point) {
  const auto& x = triangle.x;
  const Eigen::Vector3d foot = point - triangle.normal.dot(point - x[0]) * triangle.normal;
  std::array<double, 3> w{};
  for (std::size_t k = 0; k < 3; ++k) {
    const Eigen::Vector3d& b = x[(k + 1) % 3];
    const Eigen::Vector3d& c = x[(k + 2) % 3];
    w[k] = std::max(0.0, triangle.normal.dot((c - b).cross(foot - b)) / triangle.twice_area);
  }
  return w;
}

TriangleToolExtent triangle_tool_extent(const ToolNodes& tool, const std::array<Eigen::Vector3d, 3>& x, const Eigen::Vector3d& normal,
                                        double reach_m) {
  TriangleToolExtent extent;
  // A tool wholly beyond reach_m of the triangle's box is either not in its prism or wholly deeper
  // (or further in front) than the callers look: nothing to report.
  Eigen::AlignedBox3d near_box;
  for (const Eigen::Vector3d& corner : x) near_box.extend(corner);
  near_box.min().array() -= reach_m;
  near_box.max().array() += reach_m;
  if (!near_box.intersects(tool.bounds_tool_m())) return extent;
  // The prism lies inside the cylinder round the centroid's normal line through the farthest
  // corner: a tool edge that misses the cylinder misses the prism (the rounded spatula has ~10²
  // feature edges; a candidate triangle's prism meets a few). Exact, unlike a box, at any depth.
  const Eigen::Vector3d centre = (x[0] + x[1] + x[2]) / 3.0;
  const auto across = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector3d d = p - centre;
    return Eigen::Vector3d(d - normal.dot(d) * normal);
  };
  double radius_m = 0.0;
  for (const Eigen::Vector3d& corner : x) radius_m = std::max(radius_m, across(corner).norm());
  radius_m += kInsideTolerance_m;
  std::array<Eigen::Vector3d, 3> side_normal, side_origin;
  for (std::size_t k = 0; k < 3; ++k) {
    const Eigen::Vector3d& a = x[k];
    const Eigen::Vector3d& b = x[(k + 1) % 3];
    Eigen::Vector3d m = normal.cross(b - a);
    if (m.dot(x[(k + 2) % 3] - a) < 0.0) m = -m;
    side_normal[k] = m;
    side_origin[k] = a;
  }
  const auto take = [&](const Eigen::Vector3d& p) {
    const double h = normal.dot(p - x[0]);
    if (h < extent.lowest_m) {
      extent.lowest_m = h;
      extent.deepest_tool_m = p;
    }
    extent.highest_m = std::max(extent.highest_m, h);
    extent.meets = true;
  };
  const auto& edges = tool.feature_edges_tool_m();
  const auto& midpoints = tool.feature_edge_midpoints_tool_m();
  const auto& half_lengths = tool.feature_edge_half_lengths_m();
  const auto& balls = tool.feature_edge_balls();
  const auto& order = tool.feature_edge_ball_order();
  const auto test_edge = [&](std::size_t e) {
    // Every point of the edge lies within half its length of its midpoint: a midpoint farther than
    // radius + that from the normal line leaves the whole edge outside the cylinder (the slack
    // keeps rounding from dropping an edge the exact test below would keep).
    const double reach = radius_m + half_lengths[e] + kInsideTolerance_m;
    if (across(midpoints[e]).squaredNorm() > reach * reach) return;
    const auto& edge = edges[e];
    const Eigen::Vector3d a = across(edge[0]);
    const Eigen::Vector3d ab = across(edge[1]) - a;
    const double ab2 = ab.squaredNorm();
    const double t = ab2 > 0.0 ? std::clamp(-a.dot(ab) / ab2, 0.0, 1.0) : 0.0;
    if ((a + t * ab).squaredNorm() > radius_m * radius_m) return;
    double t0 = 0.0, t1 = 0.0;
    if (!clip_to_prism(side_normal, side_origin, edge[0], edge[1], t0, t1)) return;
    const Eigen::Vector3d d = edge[1] - edge[0];
    take(edge[0] + t0 * d);
    take(edge[0] + t1 * d);
  };
  // The ball tree: a ball that misses the cylinder holds no edge that meets it.
  std::array<int, ToolNodes::kFeatureEdgeBallDepth + 2> stack{};
  int top = 0;
  if (!balls.empty()) stack[static_cast<std::size_t>(top++)] = 0;
  while (top > 0) {
    const ToolNodes::FeatureEdgeBall& ball = balls[static_cast<std::size_t>(stack[static_cast<std::size_t>(--top)])];
    const double reach = radius_m + ball.radius_m + kInsideTolerance_m;
    if (across(ball.centre_tool_m).squaredNorm() > reach * reach) continue;
    if (ball.first_child >= 0) {
      stack[static_cast<std::size_t>(top++)] = ball.first_child + 1;
      stack[static_cast<std::size_t>(top++)] = ball.first_child;
      continue;
    }
    for (int i = ball.begin; i < ball.end; ++i) test_edge(static_cast<std::size_t>(order[static_cast<std::size_t>(i)]));
  }
  for (std::size_t k = 0; k < 3; ++k) {
    double s0 = 0.0, s1 = 0.0;
    if (!line_meets_box(tool.bounds_tool_m(), x[k], normal) || !clip_line_to_tool(tool.planes(), x[k], normal, s0, s1)) continue;
    take(x[k] + s0 * normal);
    take(x[k] + s1 * normal);
  }
  return extent;
}

int project_rim_contacts(const CollisionModel& model, const StepFrame& frame, btSoftBody& soft, CollisionData& data) {
  const double band_m = model.tool.thickness_m() + model.params.solver_reach_m;
  // A triangle whose corners sit on one tool face (+ skin) has the face skin_m behind it: that is
  // contact, not a cut. Ten skins of slack leave it alone; the cut metric counts from 0.1 mm.
  const double tolerance_m = 10.0 * model.params.skin_m;
  int projected = 0;
  for (const int face : data.broad.candidate_faces) {
    const std::array<int, 3>& nodes = model.soft.face_nodes[static_cast<std::size_t>(face)];
    std::array<double, 3> inverse_mass{};
    std::array<double, 3> body_inverse_mass{};
    for (std::size_t k = 0; k < 3; ++k) {
      // A node held on a tool face this step is in contact with the rigid tool already: moving it
      // would break that contact, so the rim moves the free corners only.
      body_inverse_mass[k] = soft.m_nodes[nodes[k]].m_im;
      inverse_mass[k] = (data.displacement.hold_stamp[static_cast<std::size_t>(nodes[k])] == frame.step) ? 0.0 : body_inverse_mass[k];
    }
    if (body_inverse_mass[0] + body_inverse_mass[1] + body_inverse_mass[2] == 0.0) continue;
    SoftTriangleInTool triangle;
    if (!soft_triangle_in_tool(model, frame, soft, face, triangle)) continue;
    // A tool face plane with all three corners on or in front of it separates the triangle from
    // the tool; inside the prism the tool then lies on one side of the triangle's plane, so the
    // triangle is not cut. The planes its corners are held on are the ones to try: a triangle
    // pressed flat under a face is the common candidate, and this spares it the prism clip.
    if (separated_by_a_held_plane(model, frame, data, nodes, triangle)) continue;
    // The same separation by any face plane, where the tool has few (a box has six: cheaper than
    // the prism clip; a rounded mesh's hundreds are not).
    if (model.tool.planes().size() <= kPlanesWorthTesting && separated_by_a_tool_plane(model, triangle)) continue;
    // A cut needs the tool on both sides of the triangle's plane: most candidates lie wholly on
    // one side, and the corners say so without the prism clip.
    const ToolHeightRange range = tool_height_range(model, triangle.x[0], triangle.normal);
    if (!(range.lowest_m < -tolerance_m && range.highest_m > tolerance_m)) continue;
    const TriangleToolExtent extent = triangle_tool_extent(model.tool, triangle.x, triangle.normal, band_m);
    const double lowest_m = extent.lowest_m;
    // Cut: the tool is on both sides of the plane inside the prism, no deeper than the band.
    if (!(lowest_m < -tolerance_m && extent.highest_m > tolerance_m && lowest_m >= -band_m)) continue;
    const std::array<double, 3> w = barycentric_of_foot(triangle, extent.deepest_tool_m);
    const double depth_m = -lowest_m + model.params.skin_m;
    // The free corners alone carry the move unless the deepest point lies so near the held ones
    // that a free corner would travel more than kMaxLever × the depth (3: the most any corner of
    // a triangle with equal masses travels); then every corner moves, as the body's masses say.
    double weight_sum = 0.0;
    double largest_w_over_sum = 0.0;
    for (std::size_t k = 0; k < 3; ++k) weight_sum += w[k] * w[k] * inverse_mass[k];
    for (std::size_t k = 0; k < 3; ++k)
      if (weight_sum > 0.0) largest_w_over_sum = std::max(largest_w_over_sum, w[k] * inverse_mass[k] / weight_sum);
    if (!(weight_sum > 0.0) || largest_w_over_sum > kMaxLever) {
      inverse_mass = body_inverse_mass;
      weight_sum = 0.0;
      for (std::size_t k = 0; k < 3; ++k) weight_sum += w[k] * w[k] * inverse_mass[k];
      if (!(weight_sum > 0.0)) continue;
    }
    for (std::size_t k = 0; k < 3; ++k) {
      if (inverse_mass[k] == 0.0 || w[k] == 0.0) continue;
      const Eigen::Vector3d move_tool = -triangle.normal * (depth_m * w[k] * inverse_mass[k] / weight_sum);
      write_tool_position(frame, triangle.x[k] + move_tool, soft.m_nodes[nodes[k]].m_x);
      const auto n = static_cast<std::size_t>(nodes[k]);
      if (data.solver.rim_correction_stamp[n] != frame.step) {
        data.solver.rim_correction_stamp[n] = frame.step;
        data.solver.rim_correction_world_m[n].setZero();
      }
      data.solver.rim_correction_world_m[n] += frame.r_cur * move_tool;
    }
    ++projected;
  }
  return projected;
}

// Why: Bullet derives the velocity from the solved positions, v = (x − q)/h, so the rim's push —
// up to a tool thickness, and on a coarse shell several millimetres at a free corner — became a
// velocity away from the tool of that push per step. The corner flew off the rim in the next step,
// the links pulled it back onto it, the rim pushed again: a limit cycle of 2–4 steps with the
// contact set changing on every step (the edge-first blade on the 128-face ball). Kept as a
// position correction only (as split-impulse position correction does for rigid contacts), the
// push leaves the corner no faster along it than the tool moves there, so a corner the tool
// carries keeps the tool's speed, and a resting one stays at rest.
void inelastic_rim_velocities(const StepFrame& frame, btSoftBody& soft, const CollisionData& data) {
  for (const int node : data.broad.candidate_nodes) {
    const auto n = static_cast<std::size_t>(node);
    if (data.solver.rim_correction_stamp[n] != frame.step) continue;
    const Eigen::Vector3d& push_m = data.solver.rim_correction_world_m[n];
    const double push_length_m = push_m.norm();
    if (!(push_length_m > 0.0)) continue;
    const Eigen::Vector3d direction = push_m / push_length_m;
    btSoftBody::Node& soft_node = soft.m_nodes[node];
    const Eigen::Vector3d x_world(soft_node.m_x.x(), soft_node.m_x.y(), soft_node.m_x.z());
    const Eigen::Vector3d v_world(soft_node.m_v.x(), soft_node.m_v.y(), soft_node.m_v.z());
    const Eigen::Vector3d tool_velocity = frame.velocity_world_m_s + frame.angular_velocity_world.cross(x_world - frame.t_cur);
    const double along_m_s = v_world.dot(direction);
    const double allowed_m_s = std::max(0.0, tool_velocity.dot(direction));
    if (along_m_s <= allowed_m_s) continue;
    const Eigen::Vector3d removed = (along_m_s - allowed_m_s) * direction;
    soft_node.m_v -= btVector3(static_cast<btScalar>(removed.x()), static_cast<btScalar>(removed.y()), static_cast<btScalar>(removed.z()));
  }
}

}  // namespace fissure::host::thin_body
