#pragma once
// Ctrl-C for the long-running commands (run, rt, host): while a SigintFlag is alive, the first
// SIGINT sets its flag (the command then ramps the force out, stops cleanly and writes its
// outputs); the second says so on stderr and lets that finish; the third ends the process at
// once (the default action is restored by the handler on the second). The previous
// handler is put back when the SigintFlag goes out of scope, exception or not.
#include <atomic>
#include <csignal>

namespace fissure::session {

class SigintFlag {
 public:
  SigintFlag();
  ~SigintFlag();
  SigintFlag(const SigintFlag&) = delete;
  SigintFlag& operator=(const SigintFlag&) = delete;

  /// Set (relaxed) by the signal handler; lock-free, so safe to read from any thread.
  [[nodiscard]] static const std::atomic<bool>& flag() noexcept;
  [[nodiscard]] static bool raised() noexcept { return flag().load(std::memory_order_relaxed); }
  /// SIGINTs received since this SigintFlag was made.
  [[nodiscard]] static int count() noexcept;

 private:
  struct sigaction previous_ {};
};

}  // namespace fissure::session
