#include "fissure/config/table_reader.hpp"

#include <algorithm>
#include <cstdio>
#include <vector>
#include <fstream>

namespace fissure::config {

namespace {

std::string format_error(const std::string& file, int line, const std::string& field, const std::string& message) {
  std::ostringstream out;
  out << file;
  if (line > 0) out << ':' << line;  // line 0: the file as a whole (unreadable, not found)
  out << ": ";
  if (!field.empty()) out << "field '" << field << "': ";
  out << message;
  return out.str();
}

}  // namespace

int line_of(const toml::node& node) { return static_cast<int>(node.source().begin.line); }

int line_of_field(const std::filesystem::path& file, std::string_view dotted_path) noexcept {
  try {
    const toml::table root = toml::parse_file(file.string());
    const toml::node_view<const toml::node> node = root.at_path(dotted_path);
    return node ? line_of(*node.node()) : 0;
  } catch (...) {
    return 0;  // only a line number for a message is lost
  }
}

namespace {

/// Levenshtein distance (insert, delete, substitute) between two short keys.
std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

/// Edits that still read as a typo of the key rather than another key.
constexpr std::size_t kTypoEdits = 2;

}  // namespace

std::string misspelling_hint(const toml::table& table, const std::string& expected) {
  for (const auto& [key, node] : table) {
    const std::string k(key.str());
    if (k != expected && edit_distance(k, expected) <= kTypoEdits) {
      return "; is '" + k + "' (line " + std::to_string(line_of(node)) + ") a misspelling of it?";
    }
  }
  return {};
}

std::string format_number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", value);
  return text;
}

// Unit suffixes we recognise at the end of a key, longest first so "_m_per_s2" wins over
// "_m". Used only to tell "wrong unit" from "unknown key".
std::string unit_name(const std::string& suffix) {
  static const std::map<std::string, std::string> kNames{
      {"m", "metres"}, {"s", "seconds"}, {"kg", "kilograms"}, {"ratio", "a dimensionless ratio"},
      {"count", "a count"}, {"m_per_s", "metres per second"}, {"m_per_s2", "metres per second squared"},
      {"n_per_m", "newtons per metre"}, {"n_s_per_m", "newton-seconds per metre"},
      {"pa_per_m_pow_n", "Pa per metreⁿ (per unit area)"}, {"n_per_m_pow_n", "N per metreⁿ (per triangle)"},
      {"pa_s_per_m_pow_n_plus_1", "Pa·s per metreⁿ⁺¹ (per unit area)"}, {"pa_s_per_m", "Pa·s per metre (N·s/m³, per unit contact area)"},
      {"n_s_per_m_pow_n_plus_1", "N·s per metreⁿ⁺¹ (per triangle)"}, {"deg", "degrees"},
      {"kpr", "Bullet's kPR coefficient"}, {"kvc", "Bullet's kVC coefficient"}, {"pa", "pascals"},
      {"kg_per_m3", "kilograms per cubic metre"}, {"per_s", "per second"}};
  const auto it = kNames.find(suffix);
  return it == kNames.end() ? "'" + suffix + "'" : it->second;
}

std::string read_config_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw SceneError(file.string(), 0, "", "cannot open the scene file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

toml::table parse_toml(std::string_view text, const std::string& file_label) {
  try {
    return toml::parse(text, file_label);
  } catch (const toml::parse_error& e) {
    throw SceneError(file_label, static_cast<int>(e.source().begin.line), "", "TOML syntax error: " + std::string(e.description()));
  }
}

std::string child_path(const TableReader& parent, const std::string& key) {
  return parent.path().empty() ? key : parent.path() + "." + key;
}

SceneError::SceneError(std::string file, int line, std::string field, const std::string& message)
    : std::runtime_error(format_error(file, line, field, message)), file_(std::move(file)), line_(line), field_(std::move(field)) {}

}  // namespace fissure::config
