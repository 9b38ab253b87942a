// The FCL oracle of the contact metrics (fcl_oracle.hpp).
#include "fcl_oracle.hpp"

#include <LinearMath/btConvexHullComputer.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/shape/convex.h>
#include <fcl/geometry/shape/sphere.h>

#include <Eigen/QR>

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

namespace fissure::host::test_oracle {

namespace {

// OBBRSS: fcl collides it against a shape in the mesh's own frame; for AABB it copies the model to
// transform it, and that copy is allocated inside libfcl and freed by this build's Eigen operator
// delete[] (an allocator mismatch ASan reports).
using Bvh = fcl::BVHModel<fcl::OBBRSSd>;

// A convex hull computed by Bullet (float inside); its vertices mapped back to the nearest of the
// double-precision input points, its faces as loops of those input indices.
struct Hull {
  std::vector<int> vertex_of_input;       // per Bullet vertex: the input point it is
  std::vector<std::vector<int>> faces;    // per face: input indices, in Bullet's loop order
};

Hull bullet_hull(const std::vector<Eigen::Vector3d>& points) {
  std::vector<double> coords;
  coords.reserve(3 * points.size());
  for (const Eigen::Vector3d& v : points) coords.insert(coords.end(), {v.x(), v.y(), v.z()});
  btConvexHullComputer computer;
  if (computer.compute(coords.data(), static_cast<int>(3 * sizeof(double)), static_cast<int>(points.size()), btScalar(0), btScalar(0)) < 0 ||
      computer.faces.size() < 4)
    throw std::runtime_error("FclToolOracle: Bullet found no 3-D hull");
  Hull hull;
  for (int i = 0; i < computer.vertices.size(); ++i) {
    const btVector3& b = computer.vertices[i];
    const Eigen::Vector3d v(b.x(), b.y(), b.z());
    int nearest = 0;
    for (std::size_t k = 1; k < points.size(); ++k)
      if ((points[k] - v).squaredNorm() < (points[static_cast<std::size_t>(nearest)] - v).squaredNorm()) nearest = static_cast<int>(k);
    hull.vertex_of_input.push_back(nearest);
  }
  for (int f = 0; f < computer.faces.size(); ++f) {
    std::vector<int> loop;
    const btConvexHullComputer::Edge* first = &computer.edges[computer.faces[f]];
    const btConvexHullComputer::Edge* edge = first;
    do {
      loop.push_back(hull.vertex_of_input[static_cast<std::size_t>(edge->getSourceVertex())]);
      edge = edge->getNextEdgeOfFace();
    } while (edge != first);
    hull.faces.push_back(std::move(loop));
  }
  return hull;
}

// Newell's normal of a face loop (unnormalised), oriented away from `inside`.
Eigen::Vector3d outward_normal(const std::vector<Eigen::Vector3d>& points, std::vector<int>& loop, const Eigen::Vector3d& inside) {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < loop.size(); ++k)
    n += points[static_cast<std::size_t>(loop[k])].cross(points[static_cast<std::size_t>(loop[(k + 1) % loop.size()])]);
  if (n.dot(points[static_cast<std::size_t>(loop[0])] - inside) < 0.0) {
    std::reverse(loop.begin(), loop.end());
    n = -n;
  }
  return n;
}

struct Plane {
  Eigen::Vector3d normal;  // unit, outward
  double offset_m;         // n·x ≤ offset inside
};

// The tool (hull of its vertices) with every face moved shrink_m inward, as an FCL convex. Its
// vertices are found through the dual: with c inside, the planes n·x ≤ d map to the points
// n / (d − n·c), and each face of their hull is one vertex of the shrunk tool, met by the planes of
// that face; the vertex is solved from those planes in double precision (Bullet's shrink option
// moves the faces on its integer grid: 2–3 µm off on a 40 mm box, more than the margin).
struct ShrunkTool {
  std::shared_ptr<std::vector<fcl::Vector3d>> vertices;
  std::shared_ptr<fcl::Convexd> convex;
};

ShrunkTool shrunk_hull(const std::vector<Eigen::Vector3d>& tool_vertices_m, double shrink_m) {
  Hull tool = bullet_hull(tool_vertices_m);
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& v : tool_vertices_m) c += v;
  c /= static_cast<double>(tool_vertices_m.size());
  std::vector<Plane> planes;
  std::vector<Eigen::Vector3d> dual;
  for (std::vector<int>& loop : tool.faces) {
    const Eigen::Vector3d n = outward_normal(tool_vertices_m, loop, c).normalized();
    double d = -std::numeric_limits<double>::infinity();
    for (const int i : loop) d = std::max(d, n.dot(tool_vertices_m[static_cast<std::size_t>(i)]));
    d -= shrink_m;
    if (!(d - n.dot(c) > 0.0)) throw std::runtime_error("FclToolOracle: the shrunk tool does not contain the vertices' mean");
    planes.push_back({n, d});
    dual.push_back(n / (d - n.dot(c)));
  }
  const Hull dual_hull = bullet_hull(dual);
  std::vector<Eigen::Vector3d> shrunk;
  for (const std::vector<int>& loop : dual_hull.faces) {
    // The planes of this dual face meet at one vertex: least squares over all of them.
    Eigen::MatrixXd a(static_cast<Eigen::Index>(loop.size()), 3);
    Eigen::VectorXd b(static_cast<Eigen::Index>(loop.size()));
    for (std::size_t k = 0; k < loop.size(); ++k) {
      const Plane& p = planes[static_cast<std::size_t>(loop[k])];
      a.row(static_cast<Eigen::Index>(k)) = p.normal.transpose();
      b(static_cast<Eigen::Index>(k)) = p.offset_m;
    }
    const Eigen::Vector3d v = a.colPivHouseholderQr().solve(b);
    // Bullet may split a dual face of four or more coplanar points into triangles: one vertex each, equal.
    const bool known = std::any_of(shrunk.begin(), shrunk.end(), [&](const Eigen::Vector3d& u) { return (u - v).norm() < 1e-10; });
    if (!known) shrunk.push_back(v);
  }
  Hull shrunk_hull_faces = bullet_hull(shrunk);
  ShrunkTool out;
  out.vertices = std::make_shared<std::vector<fcl::Vector3d>>(shrunk.begin(), shrunk.end());
  // FCL's face encoding: count, then the indices counter-clockwise seen from outside.
  auto faces = std::make_shared<std::vector<int>>();
  for (std::vector<int>& loop : shrunk_hull_faces.faces) {
    (void)outward_normal(shrunk, loop, c);
    faces->push_back(static_cast<int>(loop.size()));
    faces->insert(faces->end(), loop.begin(), loop.end());
  }
  out.convex = std::make_shared<fcl::Convexd>(out.vertices, static_cast<int>(shrunk_hull_faces.faces.size()), faces);
  return out;
}

fcl::CollisionRequestd exhaustive_request(std::size_t max_contacts) {
  fcl::CollisionRequestd request(std::max<std::size_t>(1, max_contacts), false);
  request.gjk_solver_type = fcl::GST_LIBCCD;
  request.gjk_tolerance = kMprToleranceM;
  return request;
}

// Which of `faces` (their triangles in `mesh`, world frame) collide with `tool` at `tool_to_world`.
std::vector<char> colliding_triangles(const Bvh& mesh, std::size_t face_count, const fcl::Convexd& tool,
                                      const Eigen::Isometry3d& tool_to_world) {
  const fcl::CollisionRequestd request = exhaustive_request(face_count);
  fcl::CollisionResultd result;
  (void)fcl::collide(&mesh, fcl::Transform3d::Identity(), &tool, fcl::Transform3d(tool_to_world.matrix()), request, result);
  std::vector<char> flags(face_count, 0);
  std::vector<fcl::Contactd> contacts;
  result.getContacts(contacts);
  for (const fcl::Contactd& c : contacts) flags.at(static_cast<std::size_t>(c.b1)) = 1;
  return flags;
}

bool node_collides(const fcl::Sphered& node, const Eigen::Vector3d& p_tool, const fcl::Convexd& tool) {
  const fcl::CollisionRequestd request = exhaustive_request(1);
  fcl::CollisionResultd result;
  fcl::Transform3d at = fcl::Transform3d::Identity();
  at.translation() = p_tool;
  return fcl::collide(&node, at, &tool, fcl::Transform3d::Identity(), request, result) > 0;
}

}  // namespace

struct FclToolOracle::Impl {
  std::vector<Eigen::Vector3d> tool_vertices;
  Eigen::AlignedBox3d tool_bounds;  // tool frame: a node outside it is outside every shrunk hull
  ShrunkTool at_tolerance, loose, strict;
  std::vector<Eigen::Vector3d> shrunk_vertices;
};

FclToolOracle::FclToolOracle(const std::vector<Eigen::Vector3d>& tool_vertices_tool_m, double depth_tolerance_m)
    : impl_(std::make_unique<Impl>()) {
  if (!(depth_tolerance_m > kAgreementMarginM)) throw std::invalid_argument("FclToolOracle: the tolerance must exceed the margin");
  impl_->tool_vertices = tool_vertices_tool_m;
  for (const Eigen::Vector3d& v : tool_vertices_tool_m) impl_->tool_bounds.extend(v);
  impl_->at_tolerance = shrunk_hull(tool_vertices_tool_m, depth_tolerance_m);
  impl_->loose = shrunk_hull(tool_vertices_tool_m, depth_tolerance_m - kAgreementMarginM);
  impl_->strict = shrunk_hull(tool_vertices_tool_m, depth_tolerance_m + kAgreementMarginM);
  for (const fcl::Vector3d& v : *impl_->at_tolerance.vertices) impl_->shrunk_vertices.emplace_back(v);
}

FclToolOracle FclToolOracle::from_box(const Eigen::Vector3d& half_extents_m, double depth_tolerance_m) {
  std::vector<Eigen::Vector3d> corners;
  for (const double x : {-1.0, 1.0})
    for (const double y : {-1.0, 1.0})
      for (const double z : {-1.0, 1.0}) corners.push_back(half_extents_m.cwiseProduct(Eigen::Vector3d(x, y, z)));
  return FclToolOracle(corners, depth_tolerance_m);
}

FclToolOracle::~FclToolOracle() = default;
FclToolOracle::FclToolOracle(FclToolOracle&&) noexcept = default;
FclToolOracle& FclToolOracle::operator=(FclToolOracle&&) noexcept = default;

const std::vector<Eigen::Vector3d>& FclToolOracle::shrunk_vertices_tool_m() const { return impl_->shrunk_vertices; }

OracleCounts FclToolOracle::check(const std::vector<Eigen::Vector3d>& soft_nodes_world_m, const std::vector<std::array<int, 3>>& faces,
                                  const Eigen::Isometry3d& tool_to_world, bool with_margins) const {
  OracleCounts out;
  if (!faces.empty()) {
    Bvh mesh;
    std::vector<fcl::Vector3d> points(soft_nodes_world_m.begin(), soft_nodes_world_m.end());
    std::vector<fcl::Triangle> triangles;
    triangles.reserve(faces.size());
    for (const std::array<int, 3>& f : faces)
      triangles.emplace_back(static_cast<std::size_t>(f[0]), static_cast<std::size_t>(f[1]), static_cast<std::size_t>(f[2]));
    mesh.beginModel(static_cast<int>(triangles.size()), static_cast<int>(points.size()));
    mesh.addSubModel(points, triangles);
    mesh.endModel();
    out.cut = colliding_triangles(mesh, faces.size(), *impl_->at_tolerance.convex, tool_to_world);
    if (with_margins) {
      out.cut_loose = colliding_triangles(mesh, faces.size(), *impl_->loose.convex, tool_to_world);
      out.cut_strict = colliding_triangles(mesh, faces.size(), *impl_->strict.convex, tool_to_world);
    }
  }
  const Eigen::Isometry3d world_to_tool = tool_to_world.inverse();
  const fcl::Sphered node(kNodeRadiusM);
  for (const Eigen::Vector3d& p_world : soft_nodes_world_m) {
    const Eigen::Vector3d p = world_to_tool * p_world;
    const bool near = impl_->tool_bounds.exteriorDistance(p) <= kNodeRadiusM;
    out.inside.push_back(near && node_collides(node, p, *impl_->at_tolerance.convex) ? 1 : 0);
    if (!with_margins) continue;
    out.inside_loose.push_back(near && node_collides(node, p, *impl_->loose.convex) ? 1 : 0);
    out.inside_strict.push_back(near && node_collides(node, p, *impl_->strict.convex) ? 1 : 0);
  }
  return out;
}

bool FclToolOracle::triangle_cut(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) const {
  return check({a, b, c}, {{0, 1, 2}}, Eigen::Isometry3d::Identity()).cut[0] != 0;
}

int OracleCounts::count(const std::vector<char>& flags) { return static_cast<int>(std::count(flags.begin(), flags.end(), 1)); }

Agreement compare(const std::vector<char>& project, const std::vector<char>& oracle, const std::vector<char>& oracle_loose,
                  const std::vector<char>& oracle_strict) {
  if (project.size() != oracle.size() || oracle_loose.size() != oracle.size() || oracle_strict.size() != oracle.size())
    throw std::invalid_argument("test_oracle::compare: the four flag lists must have one entry per item (check() with margins)");
  Agreement a;
  for (std::size_t i = 0; i < project.size(); ++i) {
    a.project += project[i] != 0 ? 1 : 0;
    a.oracle += oracle[i] != 0 ? 1 : 0;
    if ((project[i] != 0) == (oracle[i] != 0)) continue;
    ++a.differ;
    // Accepted only between the strict (t + margin) and the loose (t − margin) answer.
    const bool explained = project[i] != 0 ? oracle_loose[i] != 0 : oracle_strict[i] == 0;
    a.beyond_margin += explained ? 0 : 1;
  }
  return a;
}

void RunTally::add(const Agreement& triangles, const Agreement& nodes) {
  ++steps;
  project_max_cut = std::max(project_max_cut, triangles.project);
  oracle_max_cut = std::max(oracle_max_cut, triangles.oracle);
  project_steps_with_cut += triangles.project > 0 ? 1 : 0;
  oracle_steps_with_cut += triangles.oracle > 0 ? 1 : 0;
  project_max_inside = std::max(project_max_inside, nodes.project);
  oracle_max_inside = std::max(oracle_max_inside, nodes.oracle);
  triangles_differ += triangles.differ;
  triangles_beyond_margin += triangles.beyond_margin;
  nodes_differ += nodes.differ;
  nodes_beyond_margin += nodes.beyond_margin;
}

}  // namespace fissure::host::test_oracle
