// config/session_tables.cpp: the RT box reads [device_mapping] and [hand] of a scene file
// strictly, without the host's tables, and names file, line and field in every error.
#include "fissure/config/session_tables.hpp"

#include <filesystem>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

namespace fissure::config {
namespace {

constexpr const char* kTables = R"([device_mapping]
scale_ratio = 2.0
force_scale_ratio = 0.5
axis_permutation = [2, 0, 1]
axis_sign = [1, -1, 1]
device_origin_m = [0.0, 0.0, 0.11]
world_offset_m = [0.0, 0.12, 0.0]
clamp_mode = true
closing_axis_world = 1

[hand]
start_position_device_m = [0.0, 0.0, 0.11]
grip_stiffness_n_per_m = 300.0
grip_damping_n_s_per_m = 5.0
release_at_end = true

[[hand.waypoint]]
position_device_m = [0.0, -0.03, 0.11]
speed_m_per_s = 0.05
hold_s = 1.0

[[hand.button_event]]
time_s = 0.5
buttons = 3
)";

TEST(SessionTables, ReadsTheMappingAndTheHandAndIgnoresTheHostsTables) {
  std::ostringstream text;
  text << "[soft_body]\nshape = \"anything the host reads\"\n\n" << kTables;
  const RtSessionConfig config = load_rt_session_config_text(text.str(), "scenes/example.toml");
  EXPECT_EQ(config.scene_name, "example");
  const DeviceMapping& m = config.device_mapping;
  EXPECT_DOUBLE_EQ(m.scale, 2.0);
  EXPECT_DOUBLE_EQ(m.force_scale, 0.5);
  EXPECT_EQ(m.axis_permutation[0], 2);
  EXPECT_EQ(m.axis_permutation[2], 1);
  EXPECT_EQ(m.axis_sign[1], -1);
  EXPECT_DOUBLE_EQ(m.device_origin_m[2], 0.11);
  EXPECT_DOUBLE_EQ(m.world_offset_m[1], 0.12);
  EXPECT_TRUE(m.clamp_mode);
  EXPECT_EQ(m.closing_axis_world, 1);
  const HandScript& hand = config.hand;
  ASSERT_EQ(hand.waypoints.size(), 1u);
  EXPECT_DOUBLE_EQ(hand.waypoints[0].position_device_m[1], -0.03);
  EXPECT_DOUBLE_EQ(hand.waypoints[0].speed_m_per_s, 0.05);
  EXPECT_DOUBLE_EQ(hand.waypoints[0].hold_s, 1.0);
  ASSERT_EQ(hand.button_events.size(), 1u);
  EXPECT_EQ(hand.button_events[0].buttons, 3u);
  EXPECT_DOUBLE_EQ(hand.grip_stiffness_n_per_m, 300.0);
}

TEST(SessionTables, AWrongUnitNamesFileLineAndField) {
  std::string text = kTables;
  text.replace(text.find("grip_stiffness_n_per_m"), std::string("grip_stiffness_n_per_m").size(), "grip_stiffness_n_per_mm");
  try {
    (void)load_rt_session_config_text(text, "box.toml");
    FAIL() << "a wrong unit must be refused";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.file(), "box.toml");
    EXPECT_EQ(e.line(), 13);
    EXPECT_EQ(e.field(), "hand.grip_stiffness_n_per_mm");
    EXPECT_NE(std::string(e.what()).find("wrong unit"), std::string::npos) << e.what();
  }
}

TEST(SessionTables, ABadPermutationAndAMissingTableAreRefused) {
  std::string bad = kTables;
  bad.replace(bad.find("[2, 0, 1]"), 9, "[0, 0, 1]");
  EXPECT_THROW((void)load_rt_session_config_text(bad, "box.toml"), SceneError);
  try {
    (void)load_rt_session_config_text("[device_mapping]\nscale_ratio = 1.0\n", "box.toml");
    FAIL() << "a missing field must be refused";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.field(), "device_mapping.force_scale_ratio");
  }
  try {
    (void)load_rt_session_config_text("scale = [1,", "box.toml");
    FAIL() << "bad TOML must be refused";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("TOML syntax error"), std::string::npos) << e.what();
  }
}

TEST(SessionTables, EveryShippedSceneHasTablesTheRtBoxReads) {
  const std::filesystem::path dir = find_scenes_dir();
  ASSERT_FALSE(dir.empty());
  int scenes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".toml") continue;
    const RtSessionConfig config = load_rt_session_config(entry.path());
    EXPECT_GT(config.device_mapping.scale, 0.0) << entry.path();
    EXPECT_FALSE(config.hand.waypoints.empty()) << entry.path();
    ++scenes;
  }
  EXPECT_GE(scenes, 4);
  EXPECT_EQ(resolve_scene_path("spatula-sphere").stem(), "spatula-sphere");
  EXPECT_THROW((void)resolve_scene_path("no-such-scene"), SceneError);
}

}  // namespace
}  // namespace fissure::config
