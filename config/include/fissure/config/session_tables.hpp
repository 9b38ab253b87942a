#pragma once
// The tables of a scene file that both halves of a session read: [device_mapping] (device axes →
// tool, applied by rt_core) and [hand] (the scripted hand on SimFalcon's grip). host_sim's scene
// loader reads them with the rest of the scene; the RT box (fissure-rt) reads only these, so it
// needs neither Bullet nor the meshes.
#include <filesystem>
#include <string>
#include <string_view>

#include "fissure/config/table_reader.hpp"
#include "fissure/shared/session_config.hpp"

namespace fissure::config {

void read_device_mapping(TableReader& table, DeviceMapping& mapping);
void read_hand(const std::string& file, TableReader& table, HandScript& hand);

/// What the rt end of a session needs from a scene file.
struct RtSessionConfig {
  std::string scene_name;   ///< the file's stem
  DeviceMapping device_mapping{};
  HandScript hand{};
};

/// Reads [device_mapping] and [hand] of a scene file, strictly (SceneError naming file, line
/// and field); the other tables are the host's and are not read here.
[[nodiscard]] RtSessionConfig load_rt_session_config(const std::filesystem::path& file);
[[nodiscard]] RtSessionConfig load_rt_session_config_text(std::string_view toml_text, const std::string& file_label);

/// Finds a scene: an existing path is taken as is; otherwise NAME (with or without ".toml") is
/// looked up in $FISSURE_SCENES_DIR, ./scenes, and the scenes/ directory of the source tree the
/// executable was built in (…/scenes next to build-*/bin/). Throws SceneError (line 0) listing
/// where it looked.
[[nodiscard]] std::filesystem::path resolve_scene_path(std::string_view name_or_path);

/// The scenes/ directory found as above (empty when none).
[[nodiscard]] std::filesystem::path find_scenes_dir();

}  // namespace fissure::config
