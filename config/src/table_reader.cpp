#include "fissure/config/table_reader.hpp"

#include <fstream>

namespace fissure::config {

namespace {

std::string format_error(const std::string& file, int line, const std::string& field, const std::string& message) {
  std::ostringstream out;
  out << file << ':' << line << ": ";
  if (!field.empty()) out << "field '" << field << "': ";
  out << message;
  return out.str();
}

}  // namespace

int line_of(const toml::node& node) { return static_cast<int>(node.source().begin.line); }

// Unit suffixes we recognise at the end of a key, longest first so "_m_per_s2" wins over
// "_m". Used only to tell "wrong unit" from "unknown key".
std::string unit_name(const std::string& suffix) {
  static const std::map<std::string, std::string> kNames{
      {"m", "metres"}, {"s", "seconds"}, {"kg", "kilograms"}, {"ratio", "a dimensionless ratio"},
      {"count", "a count"}, {"m_per_s", "metres per second"}, {"m_per_s2", "metres per second squared"},
      {"n_per_m", "newtons per metre"}, {"n_s_per_m", "newton-seconds per metre"},
      {"pa_per_m_pow_n", "Pa per metreⁿ (per unit area)"}, {"n_per_m_pow_n", "N per metreⁿ (per triangle)"},
      {"pa_s_per_m_pow_n_plus_1", "Pa·s per metreⁿ⁺¹ (per unit area)"},
      {"n_s_per_m_pow_n_plus_1", "N·s per metreⁿ⁺¹ (per triangle)"}, {"deg", "degrees"},
      {"kpr", "Bullet's kPR coefficient"}, {"kvc", "Bullet's kVC coefficient"}};
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
