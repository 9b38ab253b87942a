// Soft body meshes and their Bullet construction (soft_body_builder.hpp).
#include "fissure/host_sim/soft_body_builder.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <unordered_set>
#include <utility>

#include <BulletDynamics/Dynamics/btRigidBody.h>
#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftBodyHelpers.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "fissure/host_sim/mesh_checks.hpp"
#include "fissure/host_sim/mesh_file.hpp"
#include "fissure/host_sim/soft_bending_links.hpp"
#include "fissure/host_sim/tet_mesh_checks.hpp"
#include "fissure/host_sim/tet_mesh_file.hpp"

namespace fissure::host {

namespace {

constexpr double kPi = 3.14159265358979323846;
// A soft mesh's triangle is degenerate when |(b − a) × (c − a)| is at most this fraction of the
// squared mesh size (a sliver Bullet would give a NaN normal), as for a convex tool's nodes (thin_tool.cpp).
constexpr double kDegenerateCrossRelative = 1e-12;

Eigen::Vector3d e3(const Vec3& v) { return {v[0], v[1], v[2]}; }

// Every shape here is convex: orient each triangle so its normal points away from the
// mesh's vertex centroid (the soft collisions take "outward" from the winding).
void orient_outward(SurfaceMesh& mesh) {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Vec3& v : mesh.vertices_m) centre += e3(v);
  centre /= static_cast<double>(mesh.vertices_m.size());
  for (auto& t : mesh.triangles) {
    const Eigen::Vector3d a = e3(mesh.vertices_m[t[0]]), b = e3(mesh.vertices_m[t[1]]), c = e3(mesh.vertices_m[t[2]]);
    if ((b - a).cross(c - a).dot((a + b + c) / 3.0 - centre) < 0.0) std::swap(t[1], t[2]);
  }
}

}  // namespace

btSoftBody* create_from_tri_mesh(btSoftBodyWorldInfo& world_info, const std::vector<btScalar>& xyz, const std::vector<std::array<int, 3>>& triangles) {
  // btSoftBodyHelpers::CreateFromTriMesh's construction, step for step (nodes in index order,
  // a link for each edge the first time a triangle runs it, in the order (c, a), (a, b), (b, c),
  // the faces in order, then Bullet's own deterministic randomizeConstraints), with its
  // vertices × vertices table of seen edges — 10 GB at 100k vertices, and an int overflow past
  // 46,340 — replaced by a hash set of the edges.
  const int count = static_cast<int>(xyz.size() / 3);
  btAlignedObjectArray<btVector3> x;
  x.resize(count);
  for (int i = 0; i < count; ++i) x[i] = btVector3(xyz[3 * static_cast<std::size_t>(i)], xyz[3 * static_cast<std::size_t>(i) + 1], xyz[3 * static_cast<std::size_t>(i) + 2]);
  auto* body = new btSoftBody(&world_info, count, count > 0 ? &x[0] : nullptr, nullptr);
  std::unordered_set<std::uint64_t> seen;
  seen.reserve(3 * triangles.size());
  for (const auto& t : triangles) {
    for (int j = 2, k = 0; k < 3; j = k++) {
      const auto a = static_cast<std::uint32_t>(t[static_cast<std::size_t>(j)]), b = static_cast<std::uint32_t>(t[static_cast<std::size_t>(k)]);
      if (seen.insert((static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b)).second) body->appendLink(t[static_cast<std::size_t>(j)], t[static_cast<std::size_t>(k)]);
    }
    body->appendFace(t[0], t[1], t[2]);
  }
  body->randomizeConstraints();
  return body;
}

btSoftBody* create_from_tet_mesh(btSoftBodyWorldInfo& world_info, const VolumeMesh& mesh, double density_kg_per_m3) {
  const int count = static_cast<int>(mesh.vertices_m.size());
  btAlignedObjectArray<btVector3> x;
  x.resize(count);
  for (int i = 0; i < count; ++i) {
    const Vec3& v = mesh.vertices_m[static_cast<std::size_t>(i)];
    x[i] = btVector3(static_cast<btScalar>(v[0]), static_cast<btScalar>(v[1]), static_cast<btScalar>(v[2]));
  }
  std::vector<double> mass_kg(static_cast<std::size_t>(count), 0.0);
  for (const auto& t : mesh.tetrahedra) {
    const Eigen::Vector3d a = e3(mesh.vertices_m[static_cast<std::size_t>(t[0])]);
    const double volume_m3 = (e3(mesh.vertices_m[static_cast<std::size_t>(t[1])]) - a)
                                 .dot((e3(mesh.vertices_m[static_cast<std::size_t>(t[2])]) - a).cross(e3(mesh.vertices_m[static_cast<std::size_t>(t[3])]) - a)) / 6.0;
    for (const int c : t) mass_kg[static_cast<std::size_t>(c)] += 0.25 * density_kg_per_m3 * volume_m3;
  }
  std::vector<btScalar> masses(mass_kg.begin(), mass_kg.end());
  auto* body = new btSoftBody(&world_info, count, count > 0 ? &x[0] : nullptr, count > 0 ? masses.data() : nullptr);
  // The edges first, so Bullet's arrays are reserved once: grown by doubling, its large Tetra
  // records (~0.4 kB each) are copied and their fresh pages faulted in again at every doubling.
  std::unordered_set<std::uint64_t> seen;
  seen.reserve(7 * mesh.tetrahedra.size() / 4 + 16);  // a tetrahedral mesh has ~1.2 edges per tetrahedron
  std::vector<std::array<int, 2>> edges;
  edges.reserve(7 * mesh.tetrahedra.size() / 4 + 16);
  constexpr int kEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  for (const auto& t : mesh.tetrahedra) {
    for (const auto& e : kEdges) {
      const int i = t[static_cast<std::size_t>(e[0])], j = t[static_cast<std::size_t>(e[1])];
      const auto a = static_cast<std::uint32_t>(i), b = static_cast<std::uint32_t>(j);
      if (seen.insert((static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b)).second) edges.push_back({i, j});
    }
  }
  body->m_links.reserve(static_cast<int>(edges.size()));
  body->m_tetras.reserve(static_cast<int>(mesh.tetrahedra.size()));
  body->m_faces.reserve(static_cast<int>(mesh.boundary_triangles.size()));
  for (const auto& e : edges) body->appendLink(e[0], e[1]);
  for (const auto& t : mesh.tetrahedra) body->appendTetra(t[0], t[1], t[2], t[3]);
  for (const auto& f : mesh.boundary_triangles) body->appendFace(f[0], f[1], f[2]);
  body->randomizeConstraints();
  return body;
}

bool is_icosphere_face_count(int faces) noexcept {
  for (long f = 20; f <= faces; f *= 4)
    if (f == faces) return true;
  return false;
}

SurfaceMesh make_icosphere(const Vec3& center_m, double radius_m, int subdivisions) {
  const double phi = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> v = {{-1, phi, 0}, {1, phi, 0}, {-1, -phi, 0}, {1, -phi, 0}, {0, -1, phi}, {0, 1, phi},
                                    {0, -1, -phi}, {0, 1, -phi}, {phi, 0, -1}, {phi, 0, 1}, {-phi, 0, -1}, {-phi, 0, 1}};
  for (auto& p : v) p.normalize();
  std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                       {11, 10, 2}, {10, 7, 6}, {7, 1, 8},   {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                                       {3, 8, 9},  {4, 9, 5},  {2, 4, 11},  {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> midpoint;
    auto mid = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      v.push_back((v[static_cast<std::size_t>(a)] + v[static_cast<std::size_t>(b)]).normalized());
      const int index = static_cast<int>(v.size()) - 1;
      midpoint.emplace(key, index);
      return index;
    };
    std::vector<std::array<int, 3>> next;
    next.reserve(f.size() * 4);
    for (const auto& t : f) {
      const int ab = mid(t[0], t[1]), bc = mid(t[1], t[2]), ca = mid(t[2], t[0]);
      next.push_back({t[0], ab, ca});
      next.push_back({t[1], bc, ab});
      next.push_back({t[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    f = std::move(next);
  }
  SurfaceMesh mesh;
  for (const auto& p : v) mesh.vertices_m.push_back({center_m[0] + radius_m * p.x(), center_m[1] + radius_m * p.y(), center_m[2] + radius_m * p.z()});
  mesh.triangles = std::move(f);
  orient_outward(mesh);
  return mesh;
}

SurfaceMesh make_cylinder(const SoftCylinder& c) {
  SurfaceMesh mesh;
  const int n = c.segments_count, rings = c.rings_count;
  for (int k = 0; k < rings; ++k) {
    const double x = c.center_world_m[0] - 0.5 * c.length_m + c.length_m * k / (rings - 1);
    for (int j = 0; j < n; ++j) {
      const double angle = 2.0 * kPi * j / n;
      mesh.vertices_m.push_back({x, c.center_world_m[1] + c.radius_m * std::cos(angle), c.center_world_m[2] + c.radius_m * std::sin(angle)});
    }
  }
  for (int k = 0; k + 1 < rings; ++k) {
    for (int j = 0; j < n; ++j) {
      const int a = k * n + j, b = k * n + (j + 1) % n, cc = (k + 1) * n + (j + 1) % n, d = (k + 1) * n + j;
      mesh.triangles.push_back({a, b, cc});
      mesh.triangles.push_back({a, cc, d});
    }
  }
  for (int end = 0; end < 2; ++end) {
    const int centre = static_cast<int>(mesh.vertices_m.size());
    const double x = c.center_world_m[0] + (end == 0 ? -0.5 : 0.5) * c.length_m;
    mesh.vertices_m.push_back({x, c.center_world_m[1], c.center_world_m[2]});
    const int ring = end == 0 ? 0 : rings - 1;
    for (int j = 0; j < n; ++j) mesh.triangles.push_back({centre, ring * n + j, ring * n + (j + 1) % n});
  }
  orient_outward(mesh);
  return mesh;
}

SurfaceMesh make_slab(const SoftSlab& s) {
  SurfaceMesh mesh;
  const int nx = s.top_cells_count[0], nz = s.top_cells_count[1];
  const int per_face = (nx + 1) * (nz + 1);
  for (int face = 0; face < 2; ++face) {  // 0 = top, 1 = bottom
    const double y = s.center_world_m[1] + (face == 0 ? 0.5 : -0.5) * s.size_m[1];
    for (int i = 0; i <= nx; ++i) {
      for (int j = 0; j <= nz; ++j) {
        mesh.vertices_m.push_back({s.center_world_m[0] - 0.5 * s.size_m[0] + s.size_m[0] * i / nx, y,
                                   s.center_world_m[2] - 0.5 * s.size_m[2] + s.size_m[2] * j / nz});
        if (face == 1) mesh.pinned_vertices.push_back(static_cast<int>(mesh.vertices_m.size()) - 1);
      }
    }
  }
  auto index = [&](int face, int i, int j) { return face * per_face + i * (nz + 1) + j; };
  for (int face = 0; face < 2; ++face) {
    for (int i = 0; i < nx; ++i) {
      for (int j = 0; j < nz; ++j) {
        mesh.triangles.push_back({index(face, i, j), index(face, i + 1, j), index(face, i + 1, j + 1)});
        mesh.triangles.push_back({index(face, i, j), index(face, i + 1, j + 1), index(face, i, j + 1)});
      }
    }
  }
  // Side walls: one quad row joining the top and bottom grids' boundary loops.
  std::vector<std::pair<int, int>> loop;
  for (int i = 0; i < nx; ++i) loop.emplace_back(i, 0);
  for (int j = 0; j < nz; ++j) loop.emplace_back(nx, j);
  for (int i = nx; i > 0; --i) loop.emplace_back(i, nz);
  for (int j = nz; j > 0; --j) loop.emplace_back(0, j);
  for (std::size_t k = 0; k < loop.size(); ++k) {
    const auto [i0, j0] = loop[k];
    const auto [i1, j1] = loop[(k + 1) % loop.size()];
    mesh.triangles.push_back({index(0, i0, j0), index(0, i1, j1), index(1, i1, j1)});
    mesh.triangles.push_back({index(0, i0, j0), index(1, i1, j1), index(1, i0, j0)});
  }
  orient_outward(mesh);
  return mesh;
}

SurfaceMesh make_organ_blob(int subdivisions) {
  SurfaceMesh mesh = make_icosphere({0.0, 0.0, 0.0}, 1.0, subdivisions);  // unit directions, outward
  // Radial and axis-wise scalings keep the surface star-shaped about the origin, so the sphere's
  // outward winding stays outward.
  constexpr double kHalfAxes_m[3] = {0.05, 0.025, 0.035};
  constexpr double kUnderside = 0.75;        // flatter where it lies on its bed
  constexpr double kDentDepth = 0.25;        // the dent pulls the +z pole in by a quarter
  constexpr double kDentWidth2 = 0.18;       // its Gaussian width², in squared unit-sphere distance (~25°)
  for (Vec3& v : mesh.vertices_m) {
    const Eigen::Vector3d d = e3(v);
    const double dent = 1.0 - kDentDepth * std::exp(-(d - Eigen::Vector3d::UnitZ()).squaredNorm() / kDentWidth2);
    v = {kHalfAxes_m[0] * dent * d.x(), kHalfAxes_m[1] * (d.y() < 0.0 ? kUnderside : 1.0) * dent * d.y(), kHalfAxes_m[2] * dent * d.z()};
  }
  return mesh;
}

SurfaceMesh read_soft_body_mesh(const std::string& path) {
  MeshFile file = read_mesh_file(path, kSoftMeshMaxTriangles);
  Eigen::AlignedBox3d bounds;
  for (const Vec3& v : file.vertices_m) bounds.extend(e3(v));
  const double size_m = file.vertices_m.empty() || !bounds.diagonal().allFinite() ? 0.0 : bounds.diagonal().norm();
  try {
    check_closed_surface(file.vertices_m, file.triangles, kDegenerateCrossRelative * size_m * size_m);
  } catch (const MeshDefect& defect) {
    throw MeshError(describe(file, defect));
  }
  SurfaceMesh mesh;
  mesh.vertices_m = std::move(file.vertices_m);
  mesh.triangles = std::move(file.triangles);
  return mesh;
}

VolumeMesh read_soft_body_tet_mesh(const std::string& path) {
  TetMesh tet = read_tet_mesh_file(path, kSoftMeshMaxTetrahedra);
  (void)weld_and_compact(tet);
  return volume_mesh_from(std::move(tet));
}

VolumeMesh volume_mesh_from(TetMesh tet) {
  TetBoundary boundary = check_tet_mesh(tet);
  VolumeMesh mesh;
  mesh.vertices_m = std::move(tet.vertices_m);
  mesh.tetrahedra = std::move(tet.tetrahedra);
  mesh.boundary_triangles = std::move(boundary.triangles);
  return mesh;
}

btSoftBody* build_soft_body(btSoftBodyWorldInfo& world_info, const SoftBodyDescription& d) {
  btSoftBody* body = nullptr;
  std::vector<int> pinned;
  const auto* volume = std::get_if<SoftMesh>(&d.shape);
  if (volume != nullptr && !volume->tetrahedra.empty()) {
    VolumeMesh mesh{volume->vertices_world_m, volume->tetrahedra, volume->triangles};
    TetMesh tet{"", volume->vertices_world_m, volume->tetrahedra, {}, 0};
    body = create_from_tet_mesh(world_info, mesh, d.mass_kg / tet_mesh_volume_m3(tet));
  } else if (const auto* sphere = std::get_if<SoftSphere>(&d.shape); sphere != nullptr && sphere->tessellation == SphereTessellation::kBulletEllipsoid) {
    // CreateEllipsoid builds the convex hull of res + 3 points: 2·(res + 3) − 4 faces.
    const int res = (sphere->faces_count - 2) / 2;
    body = btSoftBodyHelpers::CreateEllipsoid(world_info, btVector3(static_cast<btScalar>(sphere->center_world_m[0]), static_cast<btScalar>(sphere->center_world_m[1]), static_cast<btScalar>(sphere->center_world_m[2])),
                                              btVector3(1, 1, 1) * static_cast<btScalar>(sphere->radius_m), res);
    if (body->m_faces.size() != sphere->faces_count) {
      const int got = body->m_faces.size();
      delete body;
      throw std::runtime_error("CreateEllipsoid gave " + std::to_string(got) + " faces, not the requested " + std::to_string(sphere->faces_count));
    }
  } else {
    SurfaceMesh mesh;
    if (const auto* ico = std::get_if<SoftSphere>(&d.shape)) {
      int subdivisions = 0;
      for (int faces = 20; faces < ico->faces_count; faces *= 4) ++subdivisions;
      mesh = make_icosphere(ico->center_world_m, ico->radius_m, subdivisions);
    } else if (const auto* cylinder = std::get_if<SoftCylinder>(&d.shape)) {
      mesh = make_cylinder(*cylinder);
    } else if (const auto* file = std::get_if<SoftMesh>(&d.shape)) {
      // Checked outward at load (read_soft_body_mesh): orient_outward's centroid test would be
      // wrong for a body that is not convex.
      mesh.vertices_m = file->vertices_world_m;
      mesh.triangles = file->triangles;
    } else {
      mesh = make_slab(std::get<SoftSlab>(d.shape));
    }
    std::vector<btScalar> xyz;
    xyz.reserve(mesh.vertices_m.size() * 3);
    for (const Vec3& v : mesh.vertices_m) {
      for (double c : v) xyz.push_back(static_cast<btScalar>(c));
    }
    body = create_from_tri_mesh(world_info, xyz, mesh.triangles);
    pinned = mesh.pinned_vertices;
  }
  body->m_materials[0]->m_kLST = static_cast<btScalar>(d.linear_stiffness_ratio);
  if (d.bending_stiffness_ratio > 0.0) (void)append_bending_links(*body, d.bending_distance_count, d.bending_stiffness_ratio);
  body->m_cfg.kPR = static_cast<btScalar>(d.pressure_kpr);
  body->m_cfg.kVC = static_cast<btScalar>(d.volume_conservation_kvc);
  body->m_cfg.kDP = static_cast<btScalar>(d.damping_ratio);
  body->m_cfg.kDF = static_cast<btScalar>(d.friction_ratio);
  body->m_cfg.piterations = d.position_iterations_count;
  // Contact hardness 1 for static/kinematic (kKHR) and dynamic (kCHR) rigid contacts: the
  // "fair" Bullet baseline (BRIEF §3; the default 0.1 lets nodes leak even at 0.1 m/s).
  body->m_cfg.kKHR = 1;
  body->m_cfg.kCHR = 1;
  body->getCollisionShape()->setMargin(static_cast<btScalar>(d.collision_margin_m));
  body->setTotalMass(static_cast<btScalar>(d.mass_kg), false);
  for (int i : pinned) body->setMass(i, 0);
  body->m_cfg.kMT = static_cast<btScalar>(d.shape_matching_ratio);
  // setPose records the rest shape: its volume for kVC, its node frame for kMT (pose matching).
  if (d.volume_conservation_kvc > 0.0 || d.shape_matching_ratio > 0.0)
    body->setPose(d.volume_conservation_kvc > 0.0, d.shape_matching_ratio > 0.0);
  body->setActivationState(DISABLE_DEACTIVATION);
  return body;
}

SoftBodyRest soft_body_rest(const SoftBodyDescription& description) {
  btSoftBodyWorldInfo info;
  const std::unique_ptr<btSoftBody> body(build_soft_body(info, description));
  SoftBodyRest rest;
  rest.nodes_world_m.reserve(static_cast<std::size_t>(body->m_nodes.size()));
  for (int i = 0; i < body->m_nodes.size(); ++i) {
    const btVector3& x = body->m_nodes[i].m_x;
    rest.nodes_world_m.push_back({x.x(), x.y(), x.z()});
  }
  if (body->m_pose.m_bframe) {
    // setPose's weights and rest offsets, summed in double: the figure is the body's, not the
    // rounding of this sum.
    const btSoftBody::Pose& pose = body->m_pose;
    Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
    for (int i = 0; i < pose.m_pos.size(); ++i) {
      const Eigen::Vector3d q(pose.m_pos[i].x(), pose.m_pos[i].y(), pose.m_pos[i].z());
      a += static_cast<double>(pose.m_wgh[i]) * q * q.transpose();
    }
    const double norm_1 = a.cwiseAbs().colwise().sum().maxCoeff();
    const double norm_inf = a.cwiseAbs().rowwise().sum().maxCoeff();
    rest.pose_matrix_norm_product_m4 = norm_1 * norm_inf;
    rest.pose_radius_of_gyration_m = std::sqrt(a.trace());
  }
  return rest;
}

std::vector<int> nodes_in_anchor_box(const std::vector<Vec3>& nodes_world_m, const SoftAnchorBox& box) {
  std::vector<int> inside;
  for (std::size_t i = 0; i < nodes_world_m.size(); ++i) {
    bool in = true;
    for (std::size_t a = 0; a < 3; ++a) in = in && nodes_world_m[i][a] >= box.min_world_m[a] && nodes_world_m[i][a] <= box.max_world_m[a];
    if (in) inside.push_back(static_cast<int>(i));
  }
  return inside;
}

std::vector<int> anchored_nodes(const std::vector<Vec3>& nodes_world_m, const SoftBodyDescription& description) {
  std::vector<int> out;
  for (std::size_t b = 0; b < description.anchors.size(); ++b) {
    const std::vector<int> selected = nodes_in_anchor_box(nodes_world_m, description.anchors[b]);
    if (selected.empty()) throw std::invalid_argument("soft_body.anchor[" + std::to_string(b) + "] selects no soft node");
    out.insert(out.end(), selected.begin(), selected.end());
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

int anchor_soft_body(btSoftBody& body, btRigidBody& bed, const SoftBodyDescription& description) {
  if (description.anchors.empty()) return 0;
  std::vector<Vec3> nodes;
  nodes.reserve(static_cast<std::size_t>(body.m_nodes.size()));
  for (int i = 0; i < body.m_nodes.size(); ++i) {
    const btVector3& x = body.m_nodes[i].m_x;
    nodes.push_back({x.x(), x.y(), x.z()});
  }
  const std::vector<int> selected = anchored_nodes(nodes, description);
  for (const int i : selected) {
    // disableCollisionBetweenLinkedBodies = false: that flag would switch off the contact of
    // EVERY node with the bed (btSoftBody::m_collisionDisabledObjects is per body), and the
    // free nodes must still land on it. Influence 1: the full anchor impulse (the anchor's
    // stiffness is Bullet's kAHR, default 0.7 of the offset per solver pass).
    body.appendAnchor(i, &bed, false, 1);
  }
  return static_cast<int>(selected.size());
}

}  // namespace fissure::host
