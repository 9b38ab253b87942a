// Soft bodies from a closed surface mesh file: the shipped organ-like lobe loads as a Bullet
// soft body with the sphere's material (edge links, pose matching), its scene runs a lockstep
// plunge with no crossed node, and bad meshes are refused naming file, element and reason.
#include "fissure/host_sim/soft_body_builder.hpp"

#include <gtest/gtest.h>

#include <algorithm>
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
#include "mesh_test_meshes.hpp"

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
  const auto* mesh = std::get_if<SoftMesh>(&scene.soft_body.shape);
  ASSERT_NE(mesh, nullptr);
  EXPECT_EQ(mesh->triangles.size(), 1280U);
  EXPECT_LT(mesh->triangles.size(), 2000U);
  btSoftBodyWorldInfo info;
  const std::unique_ptr<btSoftBody> body(build_soft_body(info, scene.soft_body));
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
  EXPECT_EQ(scene.soft_body.shape_matching_ratio, sphere.soft_body.shape_matching_ratio);
  EXPECT_EQ(scene.soft_body.linear_stiffness_ratio, sphere.soft_body.linear_stiffness_ratio);
  EXPECT_FLOAT_EQ(body->m_cfg.kMT, static_cast<float>(sphere.soft_body.shape_matching_ratio));
  EXPECT_FLOAT_EQ(body->m_materials[0]->m_kLST, static_cast<float>(sphere.soft_body.linear_stiffness_ratio));
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

}  // namespace
}  // namespace fissure::host
