#pragma once
// The error of every configuration file the programs read (scene files, the RT box's session
// configuration): one line "FILE:LINE: field 'FIELD': what is wrong", with the parts kept
// for callers that point at them.
#include <stdexcept>
#include <string>

namespace fissure::config {

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

}  // namespace fissure::config
