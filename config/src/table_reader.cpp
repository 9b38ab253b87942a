#include "fissure/config/table_reader.hpp"

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

std::string child_path(const TableReader& parent, const std::string& key) {
  return parent.path().empty() ? key : parent.path() + "." + key;
}

SceneError::SceneError(std::string file, int line, std::string field, const std::string& message)
    : std::runtime_error(format_error(file, line, field, message)), file_(std::move(file)), line_(line), field_(std::move(field)) {}

}  // namespace fissure::config
