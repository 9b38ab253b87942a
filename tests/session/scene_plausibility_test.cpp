// Values the scene loader's ranges allow but no Falcon bench has (session/scene_plausibility.hpp):
// each is named with its value and the plausible range; the shipped scenes have none.
#include "fissure/session/scene_plausibility.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <variant>

#include "fissure/host_sim/scene_loader.hpp"
#include "fissure/session/session_error.hpp"

namespace fissure::session {
namespace {

host::SceneDescription spatula_sphere() { return host::load_scene(host::resolve_scene_path("spatula-sphere")); }

/// The one finding for `scene`, or a failure naming how many there were.
ImplausibleValue only_finding(const host::SceneDescription& scene) {
  const std::vector<ImplausibleValue> found = implausible_values(scene);
  EXPECT_EQ(found.size(), 1u);
  return found.empty() ? ImplausibleValue{} : found.front();
}

TEST(ScenePlausibility, TheShippedScenesArePlausible) {
  for (const char* name : {"spatula-sphere", "convex-spatula-sphere", "clamp-sphere", "clamp-vessel"}) {
    const std::vector<ImplausibleValue> found = implausible_values(host::load_scene(host::resolve_scene_path(name)));
    EXPECT_TRUE(found.empty()) << name << ": " << (found.empty() ? "" : found.front().field + " " + found.front().value);
  }
}

TEST(ScenePlausibility, ARadiusInMetresThatWasMeantInMillimetresIsNamed) {
  host::SceneDescription scene = spatula_sphere();
  std::get<host::SoftSphere>(scene.soft_bodies.front().shape).radius_m = 50.0;
  const ImplausibleValue f = only_finding(scene);
  EXPECT_EQ(f.field, "soft_body.radius_m");
  EXPECT_EQ(f.value, "50 m");
  EXPECT_NE(f.plausible.find("0.5 m"), std::string::npos) << f.plausible;
}

TEST(ScenePlausibility, GravityMassHuntCrossleyAndGripOutOfAnyBenchAreNamed) {
  host::SceneDescription scene = spatula_sphere();
  scene.simulation.gravity_world_m_per_s2 = {0.0, -1e9, 0.0};
  EXPECT_EQ(only_finding(scene).field, "simulation.gravity_world_m_per_s2");
  scene = spatula_sphere();
  scene.soft_bodies.front().mass_kg = 1e9;
  EXPECT_EQ(only_finding(scene).field, "soft_body.mass_kg");
  scene = spatula_sphere();
  scene.hunt_crossley.k = 1e30;
  EXPECT_EQ(only_finding(scene).field, "hunt_crossley.stiffness_pa_per_m_pow_n");
  scene = spatula_sphere();
  scene.hunt_crossley.lambda = 1e30;
  EXPECT_EQ(only_finding(scene).field, "hunt_crossley.damping_pa_s_per_m_pow_n_plus_1");
  scene = spatula_sphere();
  scene.hand.grip_stiffness_n_per_m = 1e12;
  const ImplausibleValue grip = only_finding(scene);
  EXPECT_EQ(grip.field, "hand.grip_stiffness_n_per_m");
  EXPECT_EQ(grip.value, "1e+12 N/m");
}

TEST(ScenePlausibility, AHandWaypointOutsideTheFalconWorkspaceIsNamed) {
  host::SceneDescription scene = spatula_sphere();
  scene.hand.waypoints.at(1).position_device_m = {0.0, -5.0, 0.11};
  const ImplausibleValue f = only_finding(scene);
  EXPECT_EQ(f.field, "hand.waypoint[1].position_device_m");
  EXPECT_NE(f.plausible.find("workspace"), std::string::npos) << f.plausible;
}

TEST(ScenePlausibility, ATrajectoryUnderTheGroundIsNamed) {
  host::SceneDescription scene = spatula_sphere();
  scene.trajectory.waypoints.at(0).position_world_m = {0.0, -1.0, 0.0};
  EXPECT_EQ(only_finding(scene).field, "trajectory.waypoint[0].position_world_m");
}

TEST(ScenePlausibility, ClampModeOnABoxToolIsNamed) {
  host::SceneDescription scene = spatula_sphere();
  scene.device_mapping.clamp_mode = true;
  EXPECT_EQ(only_finding(scene).field, "device_mapping.clamp_mode");
}

TEST(ScenePlausibility, TheRefusalIsOneLineWithFileLineFieldValueAndRange) {
  const std::filesystem::path shipped = host::resolve_scene_path("spatula-sphere");
  std::stringstream text;
  text << std::ifstream(shipped).rdbuf();
  std::string toml = text.str();
  const std::string from = "radius_m = 0.05";
  const std::size_t at = toml.find(from);
  ASSERT_NE(at, std::string::npos);
  toml.replace(at, from.size(), "radius_m = 50.0");
  const std::filesystem::path file = std::filesystem::temp_directory_path() / ("fissure-plausible-" + std::to_string(::getpid()) + ".toml");
  std::ofstream(file) << toml;
  const int line = 1 + static_cast<int>(std::count(toml.begin(), toml.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
  try {
    (void)load_plausible_scene(file.string());
    ADD_FAILURE() << "a 50 m ball was accepted";
  } catch (const config::SceneError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_EQ(e.line(), line) << what;
    EXPECT_NE(what.find(file.string() + ":" + std::to_string(line) + ": field 'soft_body.radius_m': 50 m is implausible"),
              std::string::npos)
        << what;
  }
  std::filesystem::remove(file);
}

TEST(ScenePlausibility, ABodyWhoseNodesWentNonFiniteWhileSettlingIsRefusedWithoutPrintingInf) {
  // A 1000 km ball: every node NaN or infinite after settling. Its box printed as "settled to
  // -inf % of its height" before the run's own non-finite refusal.
  const host::SceneDescription scene = spatula_sphere();
  const Eigen::AlignedBox3d loaded(Eigen::Vector3d(-0.05, 0.0, -0.05), Eigen::Vector3d(0.05, 0.1, 0.05));
  const double inf = std::numeric_limits<double>::infinity();
  for (const Eigen::AlignedBox3d& settled :
       {Eigen::AlignedBox3d(), Eigen::AlignedBox3d(Eigen::Vector3d(-0.05, -inf, -0.05), Eigen::Vector3d(0.05, 0.1, 0.05))}) {
    try {
      (void)check_settled_on_ground(loaded, settled, scene, 1.0);
      ADD_FAILURE() << "non-finite node positions were accepted";
    } catch (const SessionError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("node positions became non-finite while settling"), std::string::npos) << what;
      EXPECT_NE(what.find("simulation.time_step_s"), std::string::npos) << what;
      EXPECT_EQ(what.find("inf"), std::string::npos) << what;
    }
  }
}

}  // namespace
}  // namespace fissure::session
