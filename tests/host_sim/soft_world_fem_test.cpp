// host_sim/src/soft_world.cpp (FEM bodies) through HostSimulation: a volumetric FEM body
// (model = "fem", Bullet's deformable world) in the host simulation, met by the paired thin-body
// contact after each step — the spatula-fem-lobe scene on a coarse block instead of the lobe, so
// the test runs in a second. And fem_world.cpp's stable step, which sets the substeps.
#include <unistd.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <BulletSoftBody/btSoftBody.h>

#include "fissure/host_sim/fem_world.hpp"
#include "fissure/host_sim/host_simulation.hpp"
#include "fissure/host_sim/scene_loader.hpp"
#include "fissure/host_sim/soft_world.hpp"
#include "fissure/host_sim/tet_box.hpp"
#include "tet_test_meshes.hpp"

namespace fissure::host {
namespace {

const std::filesystem::path kScenes = "scenes";  // ctest runs in the source tree (scene_loader_test.cpp)

std::string read(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// The block: 60 × 20 × 60 mm of 10 mm Kuhn cells (147 nodes), its underside 2 mm above the
// ground and fixed to it; the spatula starts 28 mm above its top.
constexpr double kBlockTop_m = 0.022;

class FemHost : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("fissure-fem-host-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
    block_ = test_tets::kuhn_box({6, 2, 6}, 0.01, {-0.03, 0.0, -0.03});
    test_tets::write_vtk(block_, dir_ / "block.vtk");
    std::string text = read(kScenes / "spatula-fem-lobe.toml");
    text = replace(text, "\"meshes/organ-blob.1.node\"", "\"" + (dir_ / "block.vtk").string() + "\"");
    text = replace(text, "offset_world_m = [0.0, 0.02075, 0.0]", "offset_world_m = [0.0, 0.002, 0.0]");
    text = replace(text, "min_world_m = [-0.06, 0.0, -0.04]", "min_world_m = [-0.04, 0.0, -0.04]");
    text = replace(text, "max_world_m = [0.06, 0.0035, 0.04]", "max_world_m = [0.04, 0.0025, 0.04]");
    text = replace(text, "start_position_world_m = [0.0, 0.07, 0.0]", "start_position_world_m = [0.0, 0.05, 0.0]");
    scene_text_ = text;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  [[nodiscard]] SceneDescription scene(const std::string& text) const { return load_scene_text(text, "fem-block.toml", kScenes); }

  // The settled block's top [m, world y].
  [[nodiscard]] static double block_top_m(const btSoftBody& soft) {
    double top_m = 0.0;
    for (int i = 0; i < soft.m_nodes.size(); ++i) top_m = std::max(top_m, static_cast<double>(soft.m_nodes[i].m_x.y()));
    return top_m;
  }

  // Drives the spatula down at `speed` until its lower face (1 mm below its centre) is 6 mm below
  // `top_m`, noting the force as it passes 3 and 6 mm and the worst crossing on the way.
  struct Plunge {
    double force_at_3mm_n = -1.0, force_at_6mm_n = -1.0, penetration_max_m = 0.0, depth_m = 0.0;
    int crossed_max = 0;
    bool finite = true;
  };
  static constexpr double kSpatulaHalfThickness_m = 0.001;
  static Plunge plunge_6mm(HostSimulation& sim, ToolPose& pose, double top_m, double speed_m_per_s, double dt_s) {
    Plunge out;
    for (int i = 0; i < 2000; ++i) {
      pose.position_world_m.y() -= speed_m_per_s * dt_s;
      const HostStepResult& r = sim.step(pose);
      out.crossed_max = std::max(out.crossed_max, r.crossing.crossed_nodes);
      out.penetration_max_m = std::max(out.penetration_max_m, r.crossing.max_penetration_m);
      out.finite = out.finite && r.force_on_tool_world_n.allFinite();
      out.depth_m = top_m - (pose.position_world_m.y() - kSpatulaHalfThickness_m);
      if (out.force_at_3mm_n < 0.0 && out.depth_m >= 0.003) out.force_at_3mm_n = r.force_on_tool_world_n.y();
      if (out.depth_m >= 0.006) {
        out.force_at_6mm_n = r.force_on_tool_world_n.y();
        break;
      }
    }
    return out;
  }

  std::filesystem::path dir_;
  TetMesh block_;
  std::string scene_text_;
};

// Plunge speeds 5 cm/s to 10 m/s, ending 6 mm deep or, in 5 and 10 mm steps, the first step past
// it (7.5 and 12.6 mm). The block's interior nodes are the contact's candidates as its surface
// nodes are (broad_phase.cpp, take_faceless): without that, 5 interior nodes entered the tool
// during the 5 m/s hold and 15 passed through it at 10 m/s, where one step crosses a whole cell
// (docs/decisions.md, "Tissue (issue 24)").
class FemHostPlunge : public FemHost, public ::testing::WithParamInterface<double> {};

TEST_P(FemHostPlunge, TheSpatulaPressesTheFemBlockWithNoCrossedNodeAndAForceThatGrowsWithDepth) {
  const SceneDescription description = scene(scene_text_);
  ASSERT_EQ(description.soft_bodies.front().model, SoftBodyModel::kFem);
  HostSimulation sim(description);
  ASSERT_NE(sim.world().fem_world(), nullptr);
  // The substeps follow the stable step of the block's thinnest tetrahedron.
  const VolumeMesh mesh{std::get<SoftMesh>(description.soft_bodies.front().shape).vertices_world_m, block_.tetrahedra, {}};
  const int substeps = static_cast<int>(std::ceil(description.simulation.time_step_s / fem_stable_step_s(mesh, description.soft_bodies.front().fem)));
  EXPECT_EQ(sim.world().fem_substeps(), substeps);
  EXPECT_GE(substeps, 1);
  const int fixed = sim.world().anchored_nodes_count();
  EXPECT_EQ(fixed, 49);  // the 7 × 7 nodes of the underside

  sim.settle(0.3);
  const btSoftBody& soft = sim.world().soft();
  const double top_m = block_top_m(soft);
  EXPECT_LT(top_m, kBlockTop_m);           // it sags under its weight ...
  EXPECT_GT(top_m, kBlockTop_m - 0.004);  // ... a little (E 3 kPa, 20 mm thick, fixed underneath)

  const double speed_m_per_s = GetParam(), dt = description.simulation.time_step_s;
  ToolPose pose = sim.tool_pose();
  const Plunge plunge = plunge_6mm(sim, pose, top_m, speed_m_per_s, dt);
  int crossed_max = plunge.crossed_max;
  EXPECT_EQ(crossed_max, 0);
  EXPECT_TRUE(plunge.finite);
  EXPECT_GT(plunge.force_at_3mm_n, 0.0);  // the tissue pushes the tool up
  if (speed_m_per_s * dt < 0.003) {
    EXPECT_GT(plunge.force_at_6mm_n, plunge.force_at_3mm_n);  // and harder the deeper it goes (3 and 6 mm: one step above 3 mm a step)
  }
  // Held there, the body does not creep through the tool, and the fixed underside stays put.
  double held_force_n = 0.0;
  for (int i = 0; i < 200; ++i) {
    const HostStepResult& r = sim.step(pose);
    crossed_max = std::max(crossed_max, r.crossing.crossed_nodes);
    held_force_n = r.force_on_tool_world_n.y();
  }
  EXPECT_EQ(crossed_max, 0);
  EXPECT_GT(held_force_n, 0.0);
  int unmoved = 0;
  for (int i = 0; i < soft.m_nodes.size(); ++i) {
    if (soft.m_nodes[i].m_im != 0) continue;
    const Vec3& rest = block_.vertices_m[static_cast<std::size_t>(i)];
    unmoved += std::abs(static_cast<double>(soft.m_nodes[i].m_x.y()) - (rest[1] + 0.002)) < 1e-6 ? 1 : 0;
  }
  EXPECT_EQ(unmoved, fixed);
}

INSTANTIATE_TEST_SUITE_P(Speeds, FemHostPlunge, ::testing::Values(0.05, 1.0, 5.0, 10.0));

// The in-solver contact (contact_response = "in_solver"): one implicit step per 1 ms host step,
// the contact projected after each of its Newton iterations (fem_world.cpp). Plunge speeds 5 cm/s
// to 10 m/s as above (10 m/s: one 10 mm step through a 10 mm cell), then held 0.2 s.
class FemHostInSolverPlunge : public FemHost, public ::testing::WithParamInterface<double> {};

TEST_P(FemHostInSolverPlunge, TheImplicitStepHoldsTheContactWithNoCrossedNode) {
  const SceneDescription description = scene(replace(scene_text_, "collision_method = \"paired\"", "collision_method = \"paired\"\ncontact_response = \"in_solver\""));
  ASSERT_EQ(description.simulation.contact_response, ContactResponse::kInSolver);
  HostSimulation sim(description);
  ASSERT_NE(sim.world().fem_world(), nullptr);
  EXPECT_EQ(sim.world().fem_substeps(), 1);  // one implicit step, not the stable step's substeps

  sim.settle(0.3);
  const btSoftBody& soft = sim.world().soft();
  const double top_m = block_top_m(soft);
  EXPECT_LT(top_m, kBlockTop_m);
  EXPECT_GT(top_m, kBlockTop_m - 0.004);

  const double speed_m_per_s = GetParam(), dt = description.simulation.time_step_s;
  ToolPose pose = sim.tool_pose();
  const Plunge plunge = plunge_6mm(sim, pose, top_m, speed_m_per_s, dt);
  const double force_at_3mm = plunge.force_at_3mm_n, force_at_6mm = plunge.force_at_6mm_n;
  double penetration_max_m = plunge.penetration_max_m;
  int crossed_max = plunge.crossed_max;
  bool finite = plunge.finite;
  // Held 0.2 s; the force's mean and spread over its last 0.1 s (the plunge's ringing decays first).
  double held_sum = 0.0, held_sum2 = 0.0, held_force_n = 0.0;
  constexpr int kHoldSteps = 200, kMeasuredSteps = 100;
  for (int i = 0; i < kHoldSteps; ++i) {
    const HostStepResult& r = sim.step(pose);
    crossed_max = std::max(crossed_max, r.crossing.crossed_nodes);
    penetration_max_m = std::max(penetration_max_m, r.crossing.max_penetration_m);
    finite = finite && r.force_on_tool_world_n.allFinite();
    held_force_n = r.force_on_tool_world_n.y();
    if (i < kHoldSteps - kMeasuredSteps) continue;
    held_sum += held_force_n;
    held_sum2 += held_force_n * held_force_n;
  }
  const double held_mean = held_sum / kMeasuredSteps;
  const double held_std = std::sqrt(std::max(0.0, held_sum2 / kMeasuredSteps - held_mean * held_mean));
  std::printf("in_solver %.2f m/s: crossed %d, penetration %.3f mm, F 3 mm %.4f N, 6 mm %.4f N, held %.4f N (mean %.4f, std %.5f)\n", speed_m_per_s,
              crossed_max, penetration_max_m * 1e3, force_at_3mm, force_at_6mm, held_force_n, held_mean, held_std);
  EXPECT_EQ(crossed_max, 0);
  EXPECT_LT(penetration_max_m, 1e-6);
  EXPECT_TRUE(finite);
  EXPECT_GT(force_at_3mm, 0.0);
  // Above 3 mm a step, 3 and 6 mm deep are the same step.
  if (speed_m_per_s * dt < 0.003) {
    EXPECT_GT(force_at_6mm, force_at_3mm);
  }
  // The held force: within 0.5–1.5 N at 6 mm (0.70 N at 5 cm/s on 57 contacts; after_step holds
  // 1.55 N on 88 here, docs/decisions.md), scaled as x^1.5 to the depth the plunge ended at
  // (Hunt-Crossley's exponent), and steady over the hold's last 0.1 s (measured: 0.2 % at 5 cm/s,
  // 3.5 % at 1 m/s, 3 % at 10 m/s). At 5 m/s the plunge ends 7.5 mm deep in one 5 mm step and the
  // body still rings with its mass damping (10 /s): 9 %.
  const double depth_scale = std::pow(plunge.depth_m / 0.006, 1.5);
  EXPECT_GT(held_mean, 0.5 * depth_scale);
  EXPECT_LT(held_mean, 1.5 * depth_scale);
  EXPECT_LT(held_std, (speed_m_per_s < 2.0 ? 0.05 : 0.15) * held_mean);
  int unmoved = 0;
  for (int i = 0; i < soft.m_nodes.size(); ++i) {
    if (soft.m_nodes[i].m_im != 0) continue;
    const Vec3& rest = block_.vertices_m[static_cast<std::size_t>(i)];
    unmoved += std::abs(static_cast<double>(soft.m_nodes[i].m_x.y()) - (rest[1] + 0.002)) < 1e-6 ? 1 : 0;
  }
  EXPECT_EQ(unmoved, sim.world().anchored_nodes_count());
}

INSTANTIATE_TEST_SUITE_P(Speeds, FemHostInSolverPlunge, ::testing::Values(0.05, 1.0, 5.0, 10.0));

TEST_F(FemHost, BulletsMethodAndAShellBesideAnFemBodyAreRefused) {
  const auto error_of = [](const SceneDescription& s, std::optional<SceneCollisionMethod> method = std::nullopt) {
    try {
      HostSimulation sim(s, method);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error_of(scene(scene_text_), SceneCollisionMethod::kBullet).find("meets the tool through the paired or ray method"), std::string::npos);
  // A second body, a shell: the two models live in different Bullet worlds.
  SceneDescription mixed = scene(scene_text_);
  SoftBodyDescription shell = load_scene(resolve_scene_path("spatula-sphere")).soft_bodies.front();
  mixed.soft_bodies.push_back(shell);
  EXPECT_NE(error_of(mixed).find("an FEM body (model = \"fem\") and a shell cannot share a scene"), std::string::npos) << error_of(mixed);
}

TEST(FemStableStep, AKuhnCubeKeepsThreeTenthsOfItsEdgeAndASliverIsThin) {
  // A Kuhn cell's thinnest tetrahedron: altitude a/√2 over its largest face (legs a and a√2).
  const VolumeMesh cube = make_tet_box(even_coordinates(0.0, 0.01, 1), even_coordinates(0.0, 0.01, 1), even_coordinates(0.0, 0.01, 1));
  EXPECT_NEAR(thinnest_tetrahedron_m(cube), 0.01 / std::sqrt(2.0), 1e-15);
  FemMaterial material;
  EXPECT_NEAR(fem_stable_step_s(cube, material), 0.3 * 0.01 / p_wave_speed_m_per_s(material), 1e-15);
  // Four corners 0.1 mm out of one plane, every edge ≥ 10 mm: the altitude says what the edges do not.
  VolumeMesh sliver;
  sliver.vertices_m = {Vec3{0.0, 0.0, 0.0}, Vec3{0.01, 0.0, 0.0}, Vec3{0.01, 0.01, 0.0001}, Vec3{0.0, 0.01, 0.0}};
  sliver.tetrahedra = {{0, 1, 2, 3}};
  EXPECT_LT(thinnest_tetrahedron_m(sliver), 1e-4);
  EXPECT_GT(thinnest_tetrahedron_m(sliver), 0.0);
}

}  // namespace
}  // namespace fissure::host
