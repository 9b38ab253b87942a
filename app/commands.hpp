#pragma once
// Each subcommand group registers itself on the CLI tree; main.cpp only calls these.
// A callback reports failure by throwing fissure::app::CommandError (exit code 1) — or
// CLI::ValidationError for bad arguments (exit code 2, same as a parse error).
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

/// The subcommand groups shared by several modules' registrations.
struct CommandTree {
  CLI::App& root;
  CLI::App& bench;   ///< fissure bench …  (benchmarks: run time against error, JSON out)
  CLI::App& device;  ///< fissure device … (Falcon: kinematics, probe, firmware, home)
};

}  // namespace fissure::app
