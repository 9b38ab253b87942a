#include "fissure/session/sigint_flag.hpp"

#include <unistd.h>

namespace fissure::session {
namespace {

std::atomic<bool> g_sigint{false};
std::atomic<int> g_sigint_count{0};
static_assert(std::atomic<bool>::is_always_lock_free, "set from a signal handler");
static_assert(std::atomic<int>::is_always_lock_free, "counted in a signal handler");

// A second Ctrl-C comes while the force ramps out and the outputs are written (an impatient
// user, `timeout -s INT` twice): it must not cut that short. It says what is going on and
// restores the default action, so only a third Ctrl-C ends the process at once.
constexpr char kSecondSigintMessage[] =
    "\nfissure: already stopping: ramping the force out and writing the outputs (Ctrl-C again quits at once; "
    "earlier outputs then stay as they were)\n";

extern "C" void on_sigint(int /*signal*/) {
  g_sigint.store(true, std::memory_order_relaxed);
  if (g_sigint_count.fetch_add(1, std::memory_order_relaxed) + 1 >= 2) {
    // write(2) and signal() are async-signal-safe; stdio is not.
    [[maybe_unused]] const ssize_t written = ::write(STDERR_FILENO, kSecondSigintMessage, sizeof kSecondSigintMessage - 1);
    std::signal(SIGINT, SIG_DFL);
  }
}

}  // namespace

SigintFlag::SigintFlag() {
  g_sigint.store(false);
  g_sigint_count.store(0);
  struct sigaction action {};
  action.sa_handler = on_sigint;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, &previous_);
}

SigintFlag::~SigintFlag() { sigaction(SIGINT, &previous_, nullptr); }

const std::atomic<bool>& SigintFlag::flag() noexcept { return g_sigint; }

int SigintFlag::count() noexcept { return g_sigint_count.load(std::memory_order_relaxed); }

}  // namespace fissure::session
