// Soft bodies from a closed surface mesh file: the shipped organ-like lobe loads as a Bullet
// soft body with the sphere's material (edge links, pose matching), its scene runs a lockstep
// plunge with no crossed node, and bad meshes are refused naming file, element and reason.
#include "fissure/host_sim/soft_body_builder.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <set>
#include <string>

#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftBodyHelpers.h>

#include "fissure/host_sim/host_simulation.hpp"
#include "fissure/host_sim/scene_loader.hpp"
#include "fissure/host_sim/soft_world.hpp"
#include "fissure/host_sim/tet_mesh_checks.hpp"
#include "fissure/host_sim/tet_mesh_file.hpp"
#include "mesh_test_meshes.hpp"
#include "tet_test_meshes.hpp"

namespace fissure::host {
namespace {

namespace tm = test_meshes;

const std::filesystem::path kScenes = "scenes";  // ctest runs in the source tree (scene_loader_test.cpp)

std::string read_error(const std::string& path) {
  try {
    (void)read_soft_body_mesh(path);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

// The linear-memory construction gives Bullet's CreateFromTriMesh body: nodes, links and faces
// in the same order (after the same randomizeConstraints).
TEST(SoftBodyMesh, CreateFromTriMeshReplicaBuildsBulletsBody) {
  const SurfaceMesh mesh = make_organ_blob(2);
  std::vector<btScalar> xyz;
  for (const Vec3& v : mesh.vertices_m)
    for (double c : v) xyz.push_back(static_cast<btScalar>(c));
  std::vector<int> flat;
  for (const auto& t : mesh.triangles) flat.insert(flat.end(), t.begin(), t.end());
  btSoftBodyWorldInfo info;
  const std::unique_ptr<btSoftBody> bullet(btSoftBodyHelpers::CreateFromTriMesh(info, xyz.data(), flat.data(), static_cast<int>(mesh.triangles.size()), true));
  const std::unique_ptr<btSoftBody> ours(create_from_tri_mesh(info, xyz, mesh.triangles));
  ASSERT_EQ(ours->m_nodes.size(), bullet->m_nodes.size());
  ASSERT_EQ(ours->m_links.size(), bullet->m_links.size());
  ASSERT_EQ(ours->m_faces.size(), bullet->m_faces.size());
  const auto node = [](const btSoftBody& b, const btSoftBody::Node* n) { return static_cast<int>(n - &b.m_nodes[0]); };
  for (int i = 0; i < ours->m_nodes.size(); ++i) EXPECT_EQ(ours->m_nodes[i].m_x, bullet->m_nodes[i].m_x);
  for (int i = 0; i < ours->m_links.size(); ++i) {
    EXPECT_EQ(node(*ours, ours->m_links[i].m_n[0]), node(*bullet, bullet->m_links[i].m_n[0])) << "link " << i;
    EXPECT_EQ(node(*ours, ours->m_links[i].m_n[1]), node(*bullet, bullet->m_links[i].m_n[1])) << "link " << i;
  }
  for (int i = 0; i < ours->m_faces.size(); ++i)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(node(*ours, ours->m_faces[i].m_n[k]), node(*bullet, bullet->m_faces[i].m_n[k])) << "face " << i;
}

TEST(SoftBodyMesh, ShippedLobeIsAClosedNonConvexSurfaceBuiltWithLinksOnItsEdges) {
  const SceneDescription scene = load_scene(kScenes / "spatula-blob.toml");
  const auto* mesh = std::get_if<SoftMesh>(&scene.soft_bodies.front().shape);
  ASSERT_NE(mesh, nullptr);
  EXPECT_EQ(mesh->triangles.size(), 1280U);
  EXPECT_LT(mesh->triangles.size(), 2000U);
  btSoftBodyWorldInfo info;
  const std::unique_ptr<btSoftBody> body(build_soft_body(info, scene.soft_bodies.front()));
  ASSERT_EQ(body->m_nodes.size(), static_cast<int>(mesh->vertices_world_m.size()));
  EXPECT_EQ(body->m_faces.size(), 1280);
  EXPECT_EQ(body->m_links.size(), 1280 * 3 / 2) << "one link per edge of the closed surface";
  // The file's vertices, moved by offset_world_m.
  for (int i = 0; i < body->m_nodes.size(); ++i) {
    const btVector3& x = body->m_nodes[i].m_x;
    const Vec3& v = mesh->vertices_world_m[static_cast<std::size_t>(i)];
    EXPECT_NEAR(x.x(), v[0], 1e-6);
    EXPECT_NEAR(x.y(), v[1], 1e-6);
    EXPECT_NEAR(x.z(), v[2], 1e-6);
  }
  // The sphere scenes' material and pose matching (spatula-sphere.toml).
  const SceneDescription sphere = load_scene(kScenes / "spatula-sphere.toml");
  EXPECT_EQ(scene.soft_bodies.front().shape_matching_ratio, sphere.soft_bodies.front().shape_matching_ratio);
  EXPECT_EQ(scene.soft_bodies.front().linear_stiffness_ratio, sphere.soft_bodies.front().linear_stiffness_ratio);
  EXPECT_FLOAT_EQ(body->m_cfg.kMT, static_cast<float>(sphere.soft_bodies.front().shape_matching_ratio));
  EXPECT_FLOAT_EQ(body->m_materials[0]->m_kLST, static_cast<float>(sphere.soft_bodies.front().linear_stiffness_ratio));
  EXPECT_TRUE(body->m_pose.m_bframe) << "setPose recorded the rest shape for pose matching";
  double lowest = 1.0;
  for (const Vec3& v : mesh->vertices_world_m) lowest = std::min(lowest, v[1]);
  EXPECT_NEAR(lowest, 0.002, 1e-6) << "rests a soft margin above the ground";
}

// Issue 24's check of an imported body: the scene's scripted plunge (1 kHz lockstep steps,
// simulated time) into the lobe's top, a hold and the withdrawal, with the paired method.
TEST(SoftBodyMesh, LobeSceneRunsItsPlungeWithNoCrossedNode) {
  const SceneDescription scene = load_scene(kScenes / "spatula-blob.toml");
  HostSimulation sim(scene);
  sim.settle(0.3);
  const long steps = std::lround(trajectory_duration_s(scene) / scene.simulation.time_step_s);
  int crossed_max = 0, contact_steps = 0;
  double force_max_n = 0.0;
  bool finite = true;
  for (long i = 0; i < steps; ++i) {
    const TrajectorySample target = sim.scripted_target();
    const HostStepResult& r = sim.step(to_tool_pose(target.pose), target.jaw_gap_m);
    crossed_max = std::max(crossed_max, r.crossing.crossed_nodes);
    contact_steps += r.contact_count > 0 ? 1 : 0;
    finite = finite && r.force_on_tool_world_n.allFinite();
    force_max_n = std::max(force_max_n, r.force_on_tool_world_n.norm());
  }
  EXPECT_EQ(crossed_max, 0);
  EXPECT_TRUE(finite);
  EXPECT_GT(contact_steps, 100) << "the spatula reaches the lobe";
  EXPECT_GT(force_max_n, 0.1);
}

TEST(SoftBodyMesh, BadMeshesAreRefusedNamingFileElementAndReason) {
  const auto dir = tm::scratch_dir("soft_body_mesh");
  tm::Mesh open = tm::cube(0.05, 0.05, 0.05);
  open.triangles.pop_back();
  const std::string open_path = tm::write_obj(open, dir / "open.obj");
  EXPECT_NE(read_error(open_path).find("open.obj': triangle 5 (line 14): open: its edge 2–6 has no other triangle"), std::string::npos)
      << read_error(open_path);
  tm::Mesh inverted = tm::cube(0.05, 0.05, 0.05);
  for (auto& t : inverted.triangles) std::swap(t[1], t[2]);
  const std::string inverted_path = tm::write_stl_ascii(inverted, dir / "inverted.stl");
  EXPECT_NE(read_error(inverted_path).find("inverted.stl': inverted: the triangles face inwards"), std::string::npos) << read_error(inverted_path);
  tm::Mesh flipped = tm::cube(0.05, 0.05, 0.05);
  std::swap(flipped.triangles[6][1], flipped.triangles[6][2]);
  const std::string flipped_path = tm::write_bytes(tm::stl_binary_bytes(flipped), dir / "flipped.stl");
  EXPECT_NE(read_error(flipped_path).find("flipped.stl': triangle 8: inconsistent orientation"), std::string::npos) << read_error(flipped_path);
  // A non-convex closed surface is fine for a soft body (only tools must be convex).
  tm::Mesh dented = tm::cube(0.05, 0.05, 0.05);
  dented.vertices_m.push_back({0.025, 0.025, 0.04});  // the +z face's centre pushed in by 1 cm, as a fan of 4
  dented.triangles.erase(dented.triangles.begin() + 2, dented.triangles.begin() + 4);
  dented.triangles.push_back({4, 5, 8});
  dented.triangles.push_back({5, 6, 8});
  dented.triangles.push_back({6, 7, 8});
  dented.triangles.push_back({7, 4, 8});
  EXPECT_EQ(read_error(tm::write_obj(dented, dir / "dented.obj")), "(no error)");
}

// The scene loader puts the mesh's error behind the scene's file, line and field.
TEST(SoftBodyMesh, SceneLoaderNamesTheSceneLineAndField) {
  const auto dir = tm::scratch_dir("soft_body_mesh_scene");
  tm::Mesh open = tm::cube(0.05, 0.05, 0.05);
  open.triangles.pop_back();
  tm::write_obj(open, dir / "open.obj");
  std::string text;
  {
    std::ifstream in(kScenes / "spatula-blob.toml");
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const std::string key = "mesh_path = \"meshes/organ-blob.obj\"";
  ASSERT_NE(text.find(key), std::string::npos);
  text.replace(text.find(key), key.size(), "mesh_path = \"" + (dir / "open.obj").string() + "\"");
  try {
    (void)load_scene_text(text, "lobe.toml", kScenes);
    FAIL() << "an open soft mesh loaded";
  } catch (const SceneError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("lobe.toml:"), std::string::npos) << what;
    EXPECT_NE(what.find("soft_body.mesh_path"), std::string::npos) << what;
    EXPECT_NE(what.find("open.obj': triangle 5 (line 14): open"), std::string::npos) << what;
  }
}

// A volumetric body from a tetrahedral mesh: a node per vertex with its lumped share of
// density × volume, a link per tetrahedron edge, a Bullet tetra per tetrahedron, the boundary
// as outward faces.
TEST(SoftBodyTetMesh, CreateFromTetMeshBuildsNodesLinksTetrasAndBoundaryFaces) {
  const TetMesh box = test_tets::kuhn_box({3, 2, 4}, 0.01);
  const TetBoundary boundary = check_tet_mesh(box);
  const VolumeMesh mesh{box.vertices_m, box.tetrahedra, boundary.triangles};
  constexpr double kDensity_kg_per_m3 = 1000.0;  // water; soft tissue is 1000–1100
  btSoftBodyWorldInfo info;
  const std::unique_ptr<btSoftBody> body(create_from_tet_mesh(info, mesh, kDensity_kg_per_m3));
  ASSERT_EQ(body->m_nodes.size(), 4 * 3 * 5);
  EXPECT_EQ(body->m_tetras.size(), 6 * 24);
  EXPECT_EQ(body->m_faces.size(), static_cast<int>(boundary.triangles.size()));
  // Edges of a Kuhn grid of nx × ny × nz cells: the axis edges, one diagonal per face square, one per cell.
  const int nx = 3, ny = 2, nz = 4;
  const int axis = nx * (ny + 1) * (nz + 1) + (nx + 1) * ny * (nz + 1) + (nx + 1) * (ny + 1) * nz;
  const int squares = nx * ny * (nz + 1) + nx * (ny + 1) * nz + (nx + 1) * ny * nz;
  EXPECT_EQ(body->m_links.size(), axis + squares + nx * ny * nz) << "one link per tetrahedron edge, shared edges once";
  double total_kg = 0.0;
  for (int i = 0; i < body->m_nodes.size(); ++i) total_kg += 1.0 / body->m_nodes[i].m_im;
  EXPECT_NEAR(total_kg, kDensity_kg_per_m3 * 0.03 * 0.02 * 0.04, 1e-6 * 0.024) << "btScalar is float: 1e-6 relative";
  // The corner (0, 0, 0) is a corner of one tetrahedron of each of its cell's 6 (all meet on
  // the cell's diagonal): 6 × (1 cm³ / 6) / 4 of the density.
  EXPECT_NEAR(1.0 / body->m_nodes[0].m_im, kDensity_kg_per_m3 * 1e-6 / 4.0, 1e-6 * 2.5e-4);
  // Faces outward: each face normal points away from its tetrahedron's fourth corner.
  for (int f = 0; f < body->m_faces.size(); ++f) {
    const auto& face = body->m_faces[f];
    const btVector3 n = (face.m_n[1]->m_x - face.m_n[0]->m_x).cross(face.m_n[2]->m_x - face.m_n[0]->m_x);
    const btVector3 centre(0.015F, 0.01F, 0.02F);
    const btVector3 middle = (face.m_n[0]->m_x + face.m_n[1]->m_x + face.m_n[2]->m_x) / 3;
    EXPECT_GT(n.dot(middle - centre), 0.0F) << "face " << f << " faces out of the (convex) box";
  }
  for (int t = 0; t < body->m_tetras.size(); ++t) EXPECT_GT(body->m_tetras[t].m_rv, 0.0F) << "tetra " << t << "'s rest volume";
}

// A scene's [soft_body] shape = "mesh" with a TetGen file: a volumetric body of the scene's
// mass, which settles on the ground under gravity (0.5 s, 1 kHz) with every node finite.
TEST(SoftBodyTetMesh, SceneWithATetGenMeshSettlesFinite) {
  const auto dir = test_meshes::scratch_dir("soft_body_tet_scene");
  const std::string node_path = test_tets::write_tetgen(test_tets::kuhn_box({4, 2, 4}, 0.01), dir / "box");
  std::string text;
  {
    std::ifstream in(kScenes / "spatula-blob.toml");
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const auto replace_line = [&](const std::string& key, const std::string& line) {
    const std::size_t at = text.find("\n" + key);
    ASSERT_NE(at, std::string::npos) << key;
    text.replace(at + 1, text.find('\n', at + 1) - at - 1, line);
  };
  replace_line("mesh_path", "mesh_path = \"" + node_path + "\"");
  replace_line("offset_world_m", "offset_world_m = [-0.02, 0.002, -0.02]");  // 40 × 20 × 40 mm, 2 mm (the soft margin) above the ground
  // Too small for Bullet's pose matching (the loader refuses it): the tetras' links hold it.
  replace_line("shape_matching_ratio", "shape_matching_ratio = 0.0");
  std::ofstream(dir / "scene.toml") << text;
  const SceneDescription scene = load_scene(dir / "scene.toml");
  const auto* mesh = std::get_if<SoftMesh>(&scene.soft_bodies.front().shape);
  ASSERT_NE(mesh, nullptr);
  EXPECT_EQ(mesh->tetrahedra.size(), 6U * 32U);
  EXPECT_EQ(mesh->triangles.size(), 4U * (4 * 2 + 2 * 4 + 4 * 4)) << "the box's boundary";
  EXPECT_DOUBLE_EQ(mesh->vertices_world_m.front()[1], 0.002);
  SoftWorld world(scene, false);
  const btSoftBody& body = world.soft();
  EXPECT_EQ(body.m_tetras.size(), 6 * 32);
  double total_kg = 0.0;
  for (int i = 0; i < body.m_nodes.size(); ++i) total_kg += 1.0 / body.m_nodes[i].m_im;
  EXPECT_NEAR(total_kg, scene.soft_bodies.front().mass_kg, 1e-6 * scene.soft_bodies.front().mass_kg) << "the scene's mass, spread by volume";
  for (int step = 0; step < 500; ++step) world.step(scene.simulation.time_step_s);
  std::vector<Eigen::Vector3d> nodes;
  world.copy_node_positions(nodes);
  double lowest_m = 1.0, highest_m = -1.0;
  for (const Eigen::Vector3d& p : nodes) {
    ASSERT_TRUE(p.allFinite());
    lowest_m = std::min(lowest_m, p.y());
    highest_m = std::max(highest_m, p.y());
  }
  // Resting on the ground within its margin, neither fallen through nor blown up.
  EXPECT_GT(lowest_m, -scene.soft_bodies.front().collision_margin_m);
  EXPECT_LT(highest_m, 0.022 + 0.002);
  EXPECT_GT(highest_m, 0.005) << "still a body, not a puddle";
}

// TetGen (the Debian package) tetrahedralises a closed STL; its .node/.ele load as a body.
TEST(SoftBodyTetMesh, TetGenOutputOfAnStlLoads) {
#ifndef FISSURE_TETGEN_EXECUTABLE
  GTEST_SKIP() << "tetgen was not on PATH when the build was configured (apt-get install tetgen)";
#else
  const auto dir = test_meshes::scratch_dir("soft_body_tetgen_run");
  const std::string stl = test_meshes::write_stl_ascii(test_meshes::cube(0.04, 0.03, 0.05), dir / "block.stl");
  std::filesystem::remove(dir / "block.1.node");
  // -p: a piecewise linear complex from the surface; -q1.4: radius-edge ratio ≤ 1.4; -a: the
  // largest tetrahedron volume [m³]; -Q: quiet. Writes block.1.node / block.1.ele.
  const std::string command = std::string(FISSURE_TETGEN_EXECUTABLE) + " -pq1.4a2e-6 -Q '" + stl + "'";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  const VolumeMesh mesh = read_soft_body_tet_mesh((dir / "block.1.node").string());
  EXPECT_GT(mesh.tetrahedra.size(), 100U);
  double volume_m3 = 0.0;
  for (const auto& t : mesh.tetrahedra) {
    TetMesh one{"", mesh.vertices_m, {t}, {}, 0};
    volume_m3 += tet_mesh_volume_m3(one);
  }
  EXPECT_NEAR(volume_m3, 0.04 * 0.03 * 0.05, 1e-12) << "the tetrahedra fill the block";
  const TetMesh raw = read_tet_mesh_file((dir / "block.1.ele").string(), kSoftMeshMaxTetrahedra);
  std::printf("tetgen: %zu points, %zu tetrahedra, %d turned round, %zu boundary triangles\n", raw.vertices_m.size(), raw.tetrahedra.size(),
              raw.reordered_count, mesh.boundary_triangles.size());
  btSoftBodyWorldInfo info;
  const std::unique_ptr<btSoftBody> body(create_from_tet_mesh(info, mesh, 1000.0));
  EXPECT_EQ(body->m_tetras.size(), static_cast<int>(mesh.tetrahedra.size()));
#endif
}

}  // namespace
}  // namespace fissure::host
