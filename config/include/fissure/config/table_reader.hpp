#pragma once
// Reading one table of a TOML configuration file strictly, so that every error names FILE,
// LINE and FIELD: keys carry their unit in the name; a key whose stem matches a known field
// but whose unit suffix does not is a "wrong unit", anything else unexpected is an "unknown
// key"; numbers must be finite and in range. Scene files (host_sim's loader) and the RT box's
// session configuration (fissure-rt) read their tables through it.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <toml++/toml.h>

#include "fissure/config/scene_error.hpp"
#include "fissure/shared/messages.hpp"

namespace fissure::config {

/// The text of a configuration file; SceneError (line 0) when it cannot be read.
[[nodiscard]] std::string read_config_file(const std::filesystem::path& file);

/// TOML text → its root table; a syntax error is a SceneError naming the line.
[[nodiscard]] toml::table parse_toml(std::string_view text, const std::string& file_label);

/// 1-based line of a node in its file.
[[nodiscard]] int line_of(const toml::node& node);

/// 1-based line of the value at `dotted_path` (e.g. "hand.waypoint[0].position_device_m") in a
/// configuration file, for checks made after loading; 0 when the file or the key is not there.
[[nodiscard]] int line_of_field(const std::filesystem::path& file, std::string_view dotted_path) noexcept;

/// "; is 'time_stp_s' (line 7) a misspelling of it?" when `table` has a key within two edits of
/// `expected` (a typo the missing-field error should point at); "" otherwise.
[[nodiscard]] std::string misspelling_hint(const toml::table& table, const std::string& expected);

/// A number as a person reads it: 4 significant digits ("1.798e+308", never 300 digits).
[[nodiscard]] std::string format_number(double value);

/// Human name of a key's unit suffix ("m_per_s" → "metres per second"), for error messages.
[[nodiscard]] std::string unit_name(const std::string& suffix);

/// One TOML table being read: remembers the keys consumed so that finish() can reject the
/// rest, and knows every field's (stem, unit) so that a different unit is named as such.
class TableReader {
 public:
  TableReader(const std::string& file, const toml::table& table, std::string path)
      : file_(file), table_(table), path_(std::move(path)) {}

  [[noreturn]] void fail(int line, const std::string& key, const std::string& message) const {
    const std::string field = key.empty() ? path_ : (path_.empty() ? key : path_ + "." + key);
    throw SceneError(file_, line, field, message);
  }
  [[noreturn]] void fail_at(const toml::node& node, const std::string& key, const std::string& message) const {
    fail(line_of(node), key, message);
  }
  int table_line() const { return std::max(1, line_of(table_)); }

  // Declares a field as (stem, unit suffix); unit "" means the key has no unit (names, enums).
  // Returns the node or nullptr. A missing key with a wrong-unit sibling fails here.
  const toml::node* find(const std::string& stem, const std::string& unit) {
    const std::string key = unit.empty() ? stem : stem + "_" + unit;
    known_.emplace(key, std::make_pair(stem, unit));
    used_.insert(key);
    if (const toml::node* node = table_.get(key)) return node;
    check_wrong_unit(stem, unit);
    return nullptr;
  }
  const toml::node& require(const std::string& stem, const std::string& unit) {
    const toml::node* node = find(stem, unit);
    if (node == nullptr) {
      const std::string key = unit.empty() ? stem : stem + "_" + unit;
      fail(table_line(), key,
           "missing field (expected '" + key + "'" + (unit.empty() ? "" : ", in " + unit_name(unit)) + ")" + misspelling_hint(table_, key));
    }
    return *node;
  }

  double number(const std::string& stem, const std::string& unit, std::optional<double> fallback = std::nullopt) {
    const std::string key = stem + "_" + unit;
    const toml::node* node = fallback ? find(stem, unit) : &require(stem, unit);
    if (node == nullptr) return *fallback;
    if (auto v = node->value<double>(); v && (node->is_floating_point() || node->is_integer())) {
      if (!std::isfinite(*v)) fail_at(*node, key, "must be finite");
      return *v;
    }
    fail_at(*node, key, "expected a number in " + unit_name(unit));
  }
  double positive(const std::string& stem, const std::string& unit, std::optional<double> fallback = std::nullopt) {
    const double v = number(stem, unit, fallback);
    if (!(v > 0.0)) fail(line_for(stem, unit), stem + "_" + unit, "must be > 0 (got " + format_number(v) + ")");
    return v;
  }
  double in_range(const std::string& stem, const std::string& unit, double lo, double hi,
                  std::optional<double> fallback = std::nullopt) {
    const double v = number(stem, unit, fallback);
    if (v < lo || v > hi) {
      fail(line_for(stem, unit), stem + "_" + unit, "must be in [" + format_number(lo) + ", " + format_number(hi) + "] (got " + format_number(v) + ")");
    }
    return v;
  }
  int count(const std::string& stem, int lo, int hi, std::optional<int> fallback = std::nullopt) {
    const std::string key = stem + "_count";
    const toml::node* node = fallback ? find(stem, "count") : &require(stem, "count");
    if (node == nullptr) return *fallback;
    if (!node->is_integer()) fail_at(*node, key, "expected an integer");
    const std::int64_t v = *node->value<std::int64_t>();
    if (v < lo || v > hi) {
      fail_at(*node, key, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "] (got " + std::to_string(v) + ")");
    }
    return static_cast<int>(v);
  }
  /// A unit-less integer (an index, a bit mask).
  int integer(const std::string& key, int lo, int hi, std::optional<int> fallback = std::nullopt) {
    const toml::node* node = fallback ? find(key, "") : &require(key, "");
    if (node == nullptr) return *fallback;
    if (!node->is_integer()) fail_at(*node, key, "expected an integer");
    const std::int64_t v = *node->value<std::int64_t>();
    if (v < lo || v > hi) fail_at(*node, key, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "] (got " + std::to_string(v) + ")");
    return static_cast<int>(v);
  }
  Vec3 vec3(const std::string& stem, const std::string& unit, std::optional<Vec3> fallback = std::nullopt) {
    const std::string key = unit.empty() ? stem : stem + "_" + unit;
    const toml::node* node = fallback ? find(stem, unit) : &require(stem, unit);
    if (node == nullptr) return *fallback;
    const toml::array* arr = node->as_array();
    if (arr == nullptr || arr->size() != 3) fail_at(*node, key, "expected an array of 3 numbers" + (unit.empty() ? "" : " in " + unit_name(unit)));
    Vec3 out{};
    for (std::size_t i = 0; i < 3; ++i) {
      const toml::node& e = *arr->get(i);
      if (!(e.is_floating_point() || e.is_integer())) fail_at(e, key, "element " + std::to_string(i) + " is not a number");
      out[i] = *e.value<double>();
      if (!std::isfinite(out[i])) fail_at(e, key, "element " + std::to_string(i) + " must be finite");
    }
    return out;
  }
  std::string text(const std::string& key, std::optional<std::string> fallback = std::nullopt) {
    const toml::node* node = fallback ? find(key, "") : &require(key, "");
    if (node == nullptr) return *fallback;
    if (!node->is_string()) fail_at(*node, key, "expected a string");
    return *node->value<std::string>();
  }
  bool boolean(const std::string& key, std::optional<bool> fallback = std::nullopt) {
    const toml::node* node = fallback ? find(key, "") : &require(key, "");
    if (node == nullptr) return *fallback;
    if (!node->is_boolean()) fail_at(*node, key, "expected true or false");
    return *node->value<bool>();
  }
  template <typename Enum>
  Enum choice(const std::string& key, const std::vector<std::pair<std::string, Enum>>& options,
              std::optional<Enum> fallback = std::nullopt) {
    const toml::node* node = fallback ? find(key, "") : &require(key, "");
    if (node == nullptr) return *fallback;
    std::string valid;
    for (const auto& [name, value] : options) valid += (valid.empty() ? "" : ", ") + name;
    if (!node->is_string()) fail_at(*node, key, "expected one of: " + valid);
    const std::string got = *node->value<std::string>();
    for (const auto& [name, value] : options) {
      if (name == got) return value;
    }
    fail_at(*node, key, "'" + got + "' is not one of: " + valid);
  }
  const toml::table* subtable(const std::string& key, bool required) {
    known_.emplace(key, std::make_pair(key, std::string{}));
    used_.insert(key);
    const toml::node* node = table_.get(key);
    if (node == nullptr) {
      if (required) fail(table_line(), key, "missing table [" + (path_.empty() ? key : path_ + "." + key) + "]" + misspelling_hint(table_, key));
      return nullptr;
    }
    if (!node->is_table()) fail_at(*node, key, "expected a table");
    return node->as_table();
  }
  const toml::array* array_of_tables(const std::string& key) {
    known_.emplace(key, std::make_pair(key, std::string{}));
    used_.insert(key);
    const toml::node* node = table_.get(key);
    if (node == nullptr) return nullptr;
    const toml::array* arr = node->as_array();
    if (arr == nullptr || !arr->is_array_of_tables()) fail_at(*node, key, "expected an array of tables ([[" + key + "]])");
    return arr;
  }
  /// Marks a key as belonging to this table without reading it (shape-specific keys of
  /// another shape are still "unknown").
  int line_for(const std::string& stem, const std::string& unit) const {
    const toml::node* node = table_.get(unit.empty() ? stem : stem + "_" + unit);
    return node != nullptr ? line_of(*node) : table_line();
  }
  /// Every key not consumed is an error: a wrong unit when its stem is a known field's.
  void finish() const {
    for (const auto& [key, node] : table_) {
      const std::string k(key.str());
      if (used_.count(k) != 0) continue;
      for (const auto& [known_key, stem_unit] : known_) {
        const auto& [stem, unit] = stem_unit;
        if (!unit.empty() && k.rfind(stem + "_", 0) == 0) {
          fail_at(node, k, "wrong unit: this field is '" + known_key + "' (" + unit_name(unit) + ")");
        }
      }
      std::string valid;
      for (const auto& [known_key, stem_unit] : known_) valid += (valid.empty() ? "" : ", ") + known_key;
      fail_at(node, k, "unknown key (valid here: " + valid + ")");
    }
  }
  const std::string& path() const { return path_; }

 private:
  void check_wrong_unit(const std::string& stem, const std::string& unit) const {
    if (unit.empty()) return;
    for (const auto& [key, node] : table_) {
      const std::string k(key.str());
      if (k != stem + "_" + unit && k.rfind(stem + "_", 0) == 0 && known_.count(k) == 0) {
        fail_at(node, k, "wrong unit: expected '" + stem + "_" + unit + "' (" + unit_name(unit) + ")");
      }
    }
  }

  const std::string& file_;
  const toml::table& table_;
  std::string path_;
  std::map<std::string, std::pair<std::string, std::string>> known_;
  std::set<std::string> used_;
};

/// Dotted path of a child table, e.g. "hand.waypoint[2]".
[[nodiscard]] std::string child_path(const TableReader& parent, const std::string& key);

}  // namespace fissure::config
