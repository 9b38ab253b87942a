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

#include "fissure/host_sim/scene_description.hpp"

namespace fissure::host {

class SceneError : public std::runtime_error {
 public:
  SceneError(std::string file, int line, std::string field, const std::string& message);
  [[nodiscard]] const std::string& file() const noexcept { return file_; }
  [[nodiscard]] int line() const noexcept { return line_; }      ///< 1-based; 0 when the file is unreadable
  [[nodiscard]] const std::string& field() const noexcept { return field_; }  ///< dotted key path, e.g. "soft_body.radius_m"

 private:
  std::string file_;
  int line_;
  std::string field_;
};

/// Parses and validates one scene file. Mesh paths are resolved relative to the file's
/// directory and the mesh is loaded (and checked) here, so a SceneDescription is complete.
[[nodiscard]] SceneDescription load_scene(const std::filesystem::path& file);

/// Same, from TOML text (tests); `file_label` names the text in errors, relative mesh
/// paths resolve against `base_dir`.
[[nodiscard]] SceneDescription load_scene_text(std::string_view toml_text, const std::string& file_label,
                                               const std::filesystem::path& base_dir);

/// Finds a scene: an existing path is taken as is; otherwise NAME (with or without
/// ".toml") is looked up in $FISSURE_SCENES_DIR, ./scenes, and the scenes/ directory of the
/// source tree the executable was built in (…/scenes next to build-*/bin/). Throws
/// SceneError (line 0) listing where it looked.
[[nodiscard]] std::filesystem::path resolve_scene_path(std::string_view name_or_path);

/// The scenes/ directory found as above (empty when none).
[[nodiscard]] std::filesystem::path find_scenes_dir();

/// Roll, pitch, yaw [deg] → unit quaternion (w, x, y, z) of R = Rz(yaw)·Ry(pitch)·Rx(roll), the
/// convention of the scene files' `*_rpy_deg` keys.
[[nodiscard]] Quat quat_from_rpy_deg(const Vec3& rpy_deg);

}  // namespace fissure::host
