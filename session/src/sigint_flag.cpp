#include "fissure/session/sigint_flag.hpp"

namespace fissure::session {
namespace {

std::atomic<bool> g_sigint{false};
static_assert(std::atomic<bool>::is_always_lock_free, "set from a signal handler");

extern "C" void on_sigint(int /*signal*/) {
  g_sigint.store(true, std::memory_order_relaxed);
  std::signal(SIGINT, SIG_DFL);  // the second Ctrl-C ends the process at once
}

}  // namespace

SigintFlag::SigintFlag() {
  g_sigint.store(false);
  struct sigaction action {};
  action.sa_handler = on_sigint;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, &previous_);
}

SigintFlag::~SigintFlag() { sigaction(SIGINT, &previous_, nullptr); }

const std::atomic<bool>& SigintFlag::flag() noexcept { return g_sigint; }

}  // namespace fissure::session
