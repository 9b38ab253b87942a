#pragma once
// Each subcommand group registers itself on the CLI tree; main.cpp only calls these.
// A callback reports failure by throwing fissure::app::CommandError (exit code 1) — or
// CLI::ValidationError for bad arguments (exit code 2, same as a parse error).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace CLI {
class App;
}

namespace fissure::app {

/// A failure of a subcommand at run time (device missing, scene file invalid, …).
/// main() prints "fissure: error: <what>" on one line and exits with `exit_code`.
class CommandError : public std::runtime_error {
 public:
  explicit CommandError(const std::string& what, int exit_code = 1) : std::runtime_error(what), exit_code_(exit_code) {}
  [[nodiscard]] int exit_code() const noexcept { return exit_code_; }

 private:
  int exit_code_;
};

/// A CLI11 check for a duration option: a number in [0, max_s], refused in the user's terms
/// ("at most 86400 s (one day)") instead of CLI11's "not in range 0.000000 to 86400.000000".
/// Returns "" when `text` is fine, else the message.
[[nodiscard]] inline std::string check_seconds_at_most(const std::string& text, double max_s, const char* why) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || !std::isfinite(v) || v < 0.0) return "expected a number of seconds >= 0, got '" + text + "'";
  if (v > max_s) {
    char limit[32];
    std::snprintf(limit, sizeof limit, "%g", max_s);
    return text + " s is too long: at most " + limit + " s (" + why + ")";
  }
  return {};
}

/// The subcommand groups shared by several modules' registrations.
struct CommandTree {
  CLI::App& root;
  CLI::App& bench;   ///< fissure bench …  (benchmarks: run time against error, JSON out)
  CLI::App& device;  ///< fissure device … (Falcon: kinematics, probe, firmware, home)
};

}  // namespace fissure::app
