#include "fissure/eval/stress_parallel.hpp"

#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>

#include "fissure/eval/eval_error.hpp"
#include "fissure/eval/stress_row_json.hpp"

namespace fissure::eval {
namespace {

struct RunningCase {
  pid_t pid = -1;
  int read_fd = -1;
  std::size_t index = 0;
  std::string output;  ///< the child's row as JSON, as read so far
};

/// The row of a case whose process ended without handing one over (or handed over garbage).
StressRow lost_row(const StressCase& c, std::uint64_t seed, const std::string& why) {
  StressRow row;
  row.name = c.name;
  row.group = c.group;
  row.seed = seed;
  row.failures.push_back("error: " + why);
  return row;
}

std::string exit_text(int status) {
  if (WIFSIGNALED(status)) {
    const int sig = WTERMSIG(status);
    return "case process ended by signal " + std::to_string(sig) + " (" + strsignal(sig) + ")";
  }
  if (WIFEXITED(status)) return "case process exited with status " + std::to_string(WEXITSTATUS(status)) + " without a row";
  return "case process ended abnormally";
}

[[noreturn]] void run_child(const StressCase& c, StressProfile profile, std::uint64_t seed, int write_fd) {
  std::string text;
  try {
    text = stress_row_to_json(run_stress_case(c, profile, seed)).dump();
  } catch (const std::exception& e) {
    text = stress_row_to_json(lost_row(c, seed, e.what())).dump();
  }
  std::size_t written = 0;
  while (written < text.size()) {
    const ssize_t n = ::write(write_fd, text.data() + written, text.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) ::_exit(3);
    written += static_cast<std::size_t>(n);
  }
  ::close(write_fd);
  std::fflush(stdout);
  // _exit: no atexit handlers or static destructors of the parent's copy (Bullet, spdlog).
  ::_exit(0);
}

RunningCase start_child(const StressCase& c, std::size_t index, StressProfile profile, std::uint64_t seed) {
  int fds[2];
  if (::pipe(fds) != 0) throw EvalError(std::string("stress: cannot create a pipe: ") + std::strerror(errno));
  std::fflush(stdout);  // else the child would print the parent's buffered lines again
  std::fflush(stderr);
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    throw EvalError(std::string("stress: cannot start a case process: ") + std::strerror(errno));
  }
  if (pid == 0) {
    ::close(fds[0]);
    run_child(c, profile, seed, fds[1]);
  }
  ::close(fds[1]);
  return RunningCase{pid, fds[0], index, {}};
}

StressRow finish_child(RunningCase& running, const StressCase& c, std::uint64_t seed) {
  ::close(running.read_fd);
  int status = 0;
  while (::waitpid(running.pid, &status, 0) < 0 && errno == EINTR) {
  }
  const bool clean_exit = WIFEXITED(status) && WEXITSTATUS(status) == 0;
  if (!clean_exit || running.output.empty()) return lost_row(c, seed, exit_text(status));
  try {
    return stress_row_from_json(nlohmann::json::parse(running.output));
  } catch (const nlohmann::json::exception& e) {
    return lost_row(c, seed, std::string("case process handed over an unreadable row: ") + e.what());
  }
}

}  // namespace

std::vector<StressRow> run_stress_cases_forked(const std::vector<StressCase>& cases, StressProfile profile, std::uint64_t base_seed,
                                               unsigned jobs, const std::function<void(const StressRow&)>& on_row) {
  if (jobs == 0) jobs = 1;
  std::vector<std::optional<StressRow>> rows(cases.size());
  std::vector<RunningCase> running;
  std::size_t next_to_start = 0;
  std::size_t next_to_report = 0;
  while (next_to_report < cases.size()) {
    while (running.size() < jobs && next_to_start < cases.size()) {
      const StressCase& c = cases[next_to_start];
      running.push_back(start_child(c, next_to_start, profile, stress_case_seed(base_seed, c.name)));
      ++next_to_start;
    }
    std::vector<pollfd> fds;
    for (const RunningCase& r : running) fds.push_back(pollfd{r.read_fd, POLLIN, 0});
    if (::poll(fds.data(), fds.size(), -1) < 0) {
      if (errno == EINTR) continue;
      throw EvalError(std::string("stress: poll failed: ") + std::strerror(errno));
    }
    for (std::size_t i = 0; i < running.size();) {
      if ((fds[i].revents & (POLLIN | POLLHUP | POLLERR)) == 0) {
        ++i;
        continue;
      }
      char buffer[4096];
      const ssize_t n = ::read(running[i].read_fd, buffer, sizeof buffer);
      if (n > 0) {
        running[i].output.append(buffer, static_cast<std::size_t>(n));
        ++i;
        continue;
      }
      if (n < 0 && errno == EINTR) {
        ++i;
        continue;
      }
      // EOF (or a read error): the child is done with the pipe.
      const StressCase& c = cases[running[i].index];
      rows[running[i].index] = finish_child(running[i], c, stress_case_seed(base_seed, c.name));
      running.erase(running.begin() + static_cast<std::ptrdiff_t>(i));
      fds.erase(fds.begin() + static_cast<std::ptrdiff_t>(i));
    }
    while (next_to_report < cases.size() && rows[next_to_report].has_value()) {
      on_row(*rows[next_to_report]);
      ++next_to_report;
    }
  }
  std::vector<StressRow> out;
  out.reserve(rows.size());
  for (auto& r : rows) out.push_back(std::move(*r));
  return out;
}

}  // namespace fissure::eval
