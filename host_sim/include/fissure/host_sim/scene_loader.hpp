#pragma once
// Scene files (TOML, docs/scenes.md) → a const SceneDescription. Validation is strict:
// an unknown key, a missing field, a wrong unit (the unit is part of every key's name, so
// `radius_mm` where `radius_m` is expected is caught), a value out of range, bad TOML
// syntax or an unreadable/invalid mesh throws SceneError naming FILE, LINE and FIELD, and
// nothing is returned.
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

#include "fissure/config/scene_error.hpp"
#include "fissure/config/session_tables.hpp"
#include "fissure/host_sim/scene_description.hpp"

namespace fissure::host {

/// Scene files share their error type and table reader with every configuration file.
using config::SceneError;

/// Parses and validates one scene file. Mesh paths are resolved relative to the file's
/// directory and the mesh is loaded (and checked) here, so a SceneDescription is complete.
[[nodiscard]] SceneDescription load_scene(const std::filesystem::path& file);

/// Same, from TOML text (tests); `file_label` names the text in errors, relative mesh
/// paths resolve against `base_dir`.
[[nodiscard]] SceneDescription load_scene_text(std::string_view toml_text, const std::string& file_label,
                                               const std::filesystem::path& base_dir);

/// Scene names resolve the same way for the host and for the RT box (config/session_tables.hpp).
using config::find_scenes_dir;
using config::resolve_scene_path;

/// Roll, pitch, yaw [deg] → unit quaternion (w, x, y, z) of R = Rz(yaw)·Ry(pitch)·Rx(roll), the
/// convention of the scene files' `*_rpy_deg` keys.
[[nodiscard]] Quat quat_from_rpy_deg(const Vec3& rpy_deg);

}  // namespace fissure::host
