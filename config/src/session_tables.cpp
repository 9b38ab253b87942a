#include "fissure/config/session_tables.hpp"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <vector>

namespace fissure::config {
namespace {

/// Longest hand hold [s]: a day at the bench (a session is at most that long).
constexpr double kMaxHold_s = 86400.0;

std::array<std::uint8_t, 3> read_permutation(TableReader& t) {
  const toml::node& node = t.require("axis_permutation", "");
  const toml::array* arr = node.as_array();
  std::array<std::uint8_t, 3> out{};
  std::array<bool, 3> seen{};
  if (arr == nullptr || arr->size() != 3) t.fail_at(node, "axis_permutation", "expected 3 integers, a permutation of 0, 1, 2");
  for (std::size_t i = 0; i < 3; ++i) {
    const auto v = arr->get(i)->value<std::int64_t>();
    if (!arr->get(i)->is_integer() || !v || *v < 0 || *v > 2 || seen[static_cast<std::size_t>(*v)]) {
      t.fail_at(node, "axis_permutation", "expected a permutation of 0, 1, 2");
    }
    seen[static_cast<std::size_t>(*v)] = true;
    out[i] = static_cast<std::uint8_t>(*v);
  }
  return out;
}

std::array<std::int8_t, 3> read_signs(TableReader& t) {
  const toml::node& node = t.require("axis_sign", "");
  const toml::array* arr = node.as_array();
  std::array<std::int8_t, 3> out{};
  if (arr == nullptr || arr->size() != 3) t.fail_at(node, "axis_sign", "expected 3 integers, each 1 or -1");
  for (std::size_t i = 0; i < 3; ++i) {
    const auto v = arr->get(i)->value<std::int64_t>();
    if (!arr->get(i)->is_integer() || !v || (*v != 1 && *v != -1)) t.fail_at(node, "axis_sign", "expected 3 integers, each 1 or -1");
    out[i] = static_cast<std::int8_t>(*v);
  }
  return out;
}

}  // namespace

void read_device_mapping(TableReader& t, DeviceMapping& map) {
  map.scale = t.positive("scale", "ratio");
  map.force_scale = t.positive("force_scale", "ratio");
  map.axis_permutation = read_permutation(t);
  map.axis_sign = read_signs(t);
  map.device_origin_m = t.vec3("device_origin", "m");
  map.world_offset_m = t.vec3("world_offset", "m");
  map.clamp_mode = t.boolean("clamp_mode");
  map.closing_axis_world = static_cast<std::uint8_t>(t.integer("closing_axis_world", 0, 2, 2));
  t.finish();
}

void read_hand(const std::string& file, TableReader& t, HandScript& hand) {
  hand.start_position_device_m = t.vec3("start_position_device", "m");
  hand.grip_stiffness_n_per_m = t.positive("grip_stiffness", "n_per_m");
  hand.grip_damping_n_s_per_m = t.in_range("grip_damping", "n_s_per_m", 0.0, 1e6);
  hand.release_at_end = t.boolean("release_at_end");
  if (const toml::array* legs = t.array_of_tables("waypoint")) {
    for (std::size_t i = 0; i < legs->size(); ++i) {
      TableReader w(file, *legs->get(i)->as_table(), child_path(t, "waypoint[" + std::to_string(i) + "]"));
      HandWaypoint wp;
      wp.position_device_m = w.vec3("position_device", "m");
      wp.speed_m_per_s = w.positive("speed", "m_per_s");
      wp.hold_s = w.in_range("hold", "s", 0.0, kMaxHold_s, 0.0);
      w.finish();
      hand.waypoints.push_back(wp);
    }
  }
  if (const toml::array* events = t.array_of_tables("button_event")) {
    for (std::size_t i = 0; i < events->size(); ++i) {
      TableReader e(file, *events->get(i)->as_table(), child_path(t, "button_event[" + std::to_string(i) + "]"));
      ButtonEvent ev;
      ev.time_s = e.in_range("time", "s", 0.0, 1e9);
      ev.buttons = static_cast<std::uint32_t>(e.integer("buttons", 0, 0xF));  // bit mask of the 4 grip buttons
      e.finish();
      hand.button_events.push_back(ev);
    }
  }
  t.finish();
}

RtSessionConfig load_rt_session_config_text(std::string_view toml_text, const std::string& file_label) {
  const toml::table root = parse_toml(toml_text, file_label);
  RtSessionConfig config;
  config.scene_name = std::filesystem::path(file_label).stem().string();
  TableReader top(file_label, root, "");
  {
    TableReader t(file_label, *top.subtable("device_mapping", true), "device_mapping");
    read_device_mapping(t, config.device_mapping);
  }
  {
    TableReader t(file_label, *top.subtable("hand", true), "hand");
    read_hand(file_label, t, config.hand);
  }
  return config;
}

RtSessionConfig load_rt_session_config(const std::filesystem::path& file) {
  return load_rt_session_config_text(read_config_file(file), file.string());
}

namespace {

/// Where scene names are looked up, in order: $FISSURE_SCENES_DIR, ./scenes, then scenes/ in
/// every directory above the executable (build-*/bin/fissure: the source tree's scenes/).
std::vector<std::filesystem::path> scene_dir_candidates() {
  namespace fs = std::filesystem;
  std::vector<fs::path> candidates;
  if (const char* env = std::getenv("FISSURE_SCENES_DIR")) candidates.emplace_back(env);
  std::error_code ec;
  candidates.push_back(fs::current_path(ec) / "scenes");
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    for (fs::path dir = exe.parent_path(); !dir.empty() && dir != dir.root_path(); dir = dir.parent_path()) {
      candidates.push_back(dir / "scenes");
    }
  }
  std::vector<fs::path> unique;
  for (const fs::path& c : candidates) {
    if (std::find(unique.begin(), unique.end(), c.lexically_normal()) == unique.end()) unique.push_back(c.lexically_normal());
  }
  return unique;
}

/// The scene names (file stems) in `dir`, sorted.
std::vector<std::string> scene_names_in(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    if (entry.path().extension() == ".toml" && entry.is_regular_file(ec)) names.push_back(entry.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace

std::filesystem::path find_scenes_dir() {
  std::error_code ec;
  for (const std::filesystem::path& c : scene_dir_candidates()) {
    if (std::filesystem::is_directory(c, ec)) return c;
  }
  return {};
}

std::filesystem::path resolve_scene_path(std::string_view name_or_path) {
  namespace fs = std::filesystem;
  const fs::path given{std::string(name_or_path)};
  std::error_code ec;
  if (fs::is_regular_file(given, ec)) return given;
  if (fs::is_directory(given, ec)) {
    throw SceneError(given.string(), 0, "", "is a directory, not a scene file (a scene is one .toml file, e.g. scenes/spatula-sphere.toml)");
  }
  std::string looked;
  std::vector<std::string> known;
  for (const fs::path& dir : scene_dir_candidates()) {
    fs::path candidate = dir / given;
    if (candidate.extension() != ".toml") candidate += ".toml";
    if (fs::is_regular_file(candidate, ec)) return candidate;
    const bool is_dir = fs::is_directory(dir, ec);
    looked += (looked.empty() ? "" : ", ") + candidate.string() + (is_dir ? "" : " (no such directory)");
    if (is_dir && known.empty()) known = scene_names_in(dir);
  }
  std::string names;
  for (const std::string& n : known) names += (names.empty() ? "" : ", ") + n;
  throw SceneError(std::string(name_or_path), 0, "",
                   "no such scene file or scene name; looked for " + looked +
                       (names.empty() ? std::string("; no scenes found") : "; known scenes: " + names));
}

}  // namespace fissure::config
