// `fissure bench all --out DIR [--quick] [--docs DOCS_DIR] [--only NAME]... [--report-only] [--stress-full]`:
// the report. Each benchmark runs as a child process of this same executable (/proc/self/exe)
// with its output in DIR/logs/NAME.log: a benchmark that crashes or exits non-zero is reported
// (here, in DIR/bench_all.json and in the report) and the others still run. Then
// tools/report/make_report.py turns DIR/*.json into PNG plots and DIR/report.md; with --docs it
// also writes DOCS_DIR/benchmarks.md with its plots in DOCS_DIR/images/bench/ (the committed
// report). The report needs Debian's python3 + matplotlib: checked before any benchmark runs,
// so a missing package costs one line, not ten minutes.
#include "fissure/eval/bench_all.hpp"
#include "fissure/eval/eval_error.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "fissure/session/machine_info.hpp"
#include "fissure/session/shell_quote.hpp"

namespace fissure::eval {
using namespace fissure::session;  // the session library: SessionHost, run_session, LinkBridge, …
namespace {

namespace fs = std::filesystem;

/// How often the progress line is redrawn while a child runs.
constexpr std::chrono::milliseconds kPollPeriod{250};
/// The python that has matplotlib: Debian's (toolchain/setup.sh installs python3-matplotlib),
/// not whatever python is first on PATH (a pyenv shim here has no matplotlib). FISSURE_PYTHON
/// overrides it.
constexpr const char* kDefaultPython = "/usr/bin/python3";


/// One benchmark child: its subcommand words (the --json FILE is appended), the extra options
/// of a --quick run, and its wall time measured on this 2-core VM under load (only to weigh the
/// progress bar; the real time is measured and reported).
struct Child {
  std::string name;
  std::vector<std::string> command;
  std::vector<std::string> full_options;
  std::vector<std::string> quick_options;
  double estimate_s = 0.0;
  double quick_estimate_s = 0.0;
  bool opt_in = false;  ///< long: runs only when asked for by name (--only) or by its own flag
};

/// Simulated time of the 10 m/s plunge frames [s]: the plunge (15 mm above to 20 mm below the
/// sphere's top, render --plunge) is over after 3.5 ms; 10 ms shows where the tool ended up.
constexpr const char* kPlungeFrameAt_s = "0.01";

std::vector<Child> children(const fs::path& out_dir) {
  const std::string view_runs = (out_dir / "view-runs").string();
  auto plunge = [&](const std::string& method) {
    const std::vector<std::string> options{"--method", method, "--plunge", "10", "--hold", "0.1", "--frames",
                                           (out_dir / ("plunge-" + method)).string(), "--frame-at", kPlungeFrameAt_s};
    return Child{"plunge_" + method, {"render", "spatula-sphere"}, options, options, 5, 5};
  };
  return {
      {"kinematics", {"bench", "kinematics"}, {}, {"--samples", "5000", "--repeats", "2"}, 6, 2},
      // best_effort: on a machine without SCHED_FIFO the tick/Z-width parts still run and the
      // JSON says what could not be had (wakeup_us.*.sched_fifo), instead of no rt figures.
      {"rt", {"bench", "rt"}, {"--rt-policy", "best_effort"}, {"--rt-policy", "best_effort", "--seconds", "3"}, 75, 20},
      {"collision", {"bench", "collision"}, {}, {"--quick"}, 150, 30},
      // Issue 22's in-solver response (not yet the scenes' default): its sweep and cells with the
      // tool's friction and without it (issue 23 asks for both).
      {"collision_in_solver", {"bench", "collision"}, {"--only", "sweep", "--only", "cells", "--contact-response", "in_solver"},
       {"--quick", "--only", "sweep", "--only", "cells", "--contact-response", "in_solver"}, 45, 10},
      {"collision_in_solver_frictionless", {"bench", "collision"},
       {"--only", "sweep", "--only", "cells", "--contact-response", "in_solver", "--in-solver-friction", "off"},
       {"--quick", "--only", "sweep", "--only", "cells", "--contact-response", "in_solver", "--in-solver-friction", "off"}, 45, 10},
      {"proxy", {"bench", "proxy"}, {}, {"--host-rates", "1000", "100"}, 5, 3},
      // Mesh import load times (issue 24): up to 362k-triangle tools; --quick stops at 41k.
      {"mesh", {"bench", "mesh"}, {}, {"--quick"}, 60, 2},
      // Grasp, lift, slip and pull-out with friction (issue 23).
      {"grasp", {"bench", "grasp"}, {}, {"--quick"}, 12, 10},
      // FEM tissue against its analytic anchors and its cost per host step (issue 24).
      {"tissue", {"bench", "tissue"}, {}, {"--quick"}, 350, 30},
      {"pareto", {"bench", "pareto"}, {}, {"--quick", "--repeats", "1"}, 12, 4},
      {"view", {"bench", "view"}, {"--out", view_runs}, {"--repeats", "1", "--out", view_runs}, 25, 9},
      // The ci profile in both modes (the report carries its summary): 80-260 s on the loaded VM.
      {"stress", {"stress"}, {"--profile", "ci"}, {"--profile", "ci"}, 90, 90},
      // The full profile: ≥ 1e6 rt ticks per case, one process per core
      // (~10 min on 2 cores). Only with --stress-full (or --only stress_full); --quick keeps it full.
      {"stress_full", {"stress"}, {"--profile", "full"}, {"--profile", "full"}, 700, 700, true},
      // A Bullet-vs-paired pair of frames of the 10 m/s plunge in the report.
      plunge("bullet"),
      plunge("paired"),
  };
}

std::string join_command(const std::vector<std::string>& argv) {
  std::string s;
  for (const std::string& a : argv) {
    if (!s.empty()) s += ' ';
    const bool plain = !a.empty() && a.find_first_of(" '\"$\\`*?;&|<>()") == std::string::npos;
    s += plain ? a : shell_quote(a);
  }
  return s;
}

std::string python_executable() {
  const char* env = std::getenv("FISSURE_PYTHON");
  return env != nullptr && *env != '\0' ? env : kDefaultPython;
}

/// tools/report/make_report.py: FISSURE_TOOLS_DIR, ./tools, or a tools/ above the executable
/// (build-x/bin/fissure → the source tree's tools/).
fs::path find_report_script() {
  std::vector<fs::path> candidates;
  if (const char* env = std::getenv("FISSURE_TOOLS_DIR")) candidates.emplace_back(env);
  candidates.push_back(fs::current_path() / "tools");
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    for (fs::path dir = exe.parent_path(); !dir.empty() && dir != dir.root_path(); dir = dir.parent_path()) {
      candidates.push_back(dir / "tools");
    }
  }
  for (const fs::path& dir : candidates) {
    if (fs::is_regular_file(dir / "report" / "make_report.py", ec)) return dir / "report" / "make_report.py";
  }
  throw EvalError("bench all: tools/report/make_report.py not found (run from the source tree or set FISSURE_TOOLS_DIR)");
}

/// The source tree the report script lives in: its git commit and how many tracked files
/// differ from it — the report says what code its figures come from (a benchmark built from a
/// tree with uncommitted changes is not the commit's figures). Empty fields when git is absent.
nlohmann::json source_tree(const fs::path& script) {
  const fs::path root = script.parent_path().parent_path().parent_path();
  auto read = [&](const std::string& arguments) {
    const std::string command = "git -C " + shell_quote(root.string()) + " " + arguments + " 2>/dev/null";
    std::string text;
    if (FILE* pipe = ::popen(command.c_str(), "r")) {
      char buffer[4096];
      std::size_t n = 0;
      while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) text.append(buffer, n);
      ::pclose(pipe);
    }
    return text;
  };
  std::string commit = read("rev-parse --short HEAD");
  while (!commit.empty() && (commit.back() == '\n' || commit.back() == ' ')) commit.pop_back();
  const std::string status = read("status --porcelain --untracked-files=no");
  const auto modified = std::count(status.begin(), status.end(), '\n');
  return {{"path", root.string()}, {"commit", commit}, {"modified_tracked_files", modified}};
}

/// Fails in one line when the report cannot be made (before any benchmark runs).
void check_python() {
  const std::string python = python_executable();
  const std::string command = shell_quote(python) + " -c 'import matplotlib' >/dev/null 2>&1";
  if (std::system(command.c_str()) != 0) {
    throw EvalError("bench all: the report needs python3 with matplotlib: '" + python +
                       " -c \"import matplotlib\"' failed (install Debian's python3-matplotlib, see toolchain/setup.sh, or set "
                       "FISSURE_PYTHON)");
  }
}

/// The last non-empty line of a log (the child's own progress line), for the status line.
std::string last_log_line(const fs::path& log) {
  std::ifstream in(log, std::ios::binary);
  if (!in) return {};
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  const std::streamoff from = std::max<std::streamoff>(0, size - 4096);
  in.seekg(from);
  std::string tail(static_cast<std::size_t>(size - from), '\0');
  in.read(tail.data(), static_cast<std::streamsize>(tail.size()));
  for (char& c : tail) {
    if (c == '\r') c = '\n';
  }
  std::string last;
  std::istringstream lines(tail);
  for (std::string line; std::getline(lines, line);) {
    // Drop terminal escapes (the children's "erase to end of line").
    std::string clean;
    for (std::size_t i = 0; i < line.size(); ++i) {
      if (line[i] == '\033') {
        while (i < line.size() && !std::isalpha(static_cast<unsigned char>(line[i]))) ++i;
        continue;
      }
      if (std::isprint(static_cast<unsigned char>(line[i])) || (static_cast<unsigned char>(line[i]) & 0x80)) clean += line[i];
    }
    if (clean.find_first_not_of(' ') != std::string::npos) last = clean;
  }
  return last;
}

class ProgressBar {
 public:
  ProgressBar(double total_weight, std::size_t count) : total_(std::max(1e-9, total_weight)), count_(count), tty_(isatty(STDERR_FILENO) != 0) {}

  void draw(double done_weight, std::size_t index, const std::string& name, double elapsed_s, const std::string& status) {
    const double fraction = std::clamp(done_weight / total_, 0.0, 1.0);
    constexpr int kWidth = 28;
    const int filled = static_cast<int>(fraction * kWidth);
    std::string line = "bench all [" + std::string(static_cast<std::size_t>(filled), '#') +
                       std::string(static_cast<std::size_t>(kWidth - filled), '.') + "] ";
    char text[96];
    std::snprintf(text, sizeof text, "%3.0f%% %zu/%zu %s %.0fs", 100.0 * fraction, index + 1, count_, name.c_str(), elapsed_s);
    line += text;
    if (!status.empty()) line += " | " + status;
    if (tty_) {
      if (line.size() > 150) line.resize(150);
      std::fprintf(stderr, "\r%s\033[K", line.c_str());
    }
  }
  void start(std::size_t index, const std::string& name, const std::string& command) {
    if (!tty_) std::fprintf(stderr, "bench all: %zu/%zu %s: %s\n", index + 1, count_, name.c_str(), command.c_str());
  }
  void finish(std::size_t index, const std::string& name, const std::string& outcome) {
    if (tty_) std::fprintf(stderr, "\r\033[K");
    std::fprintf(stderr, "bench all: %zu/%zu %s: %s\n", index + 1, count_, name.c_str(), outcome.c_str());
  }

 private:
  double total_;
  std::size_t count_;
  bool tty_;
};

struct ChildResult {
  std::string name;
  std::string command;
  int exit_code = -1;  ///< -1 when killed by a signal or not started
  int signal = 0;
  std::string error;   ///< could not start
  double wall_s = 0.0;
  fs::path json;
  fs::path log;
  bool json_written = false;
};

ChildResult run_child(const fs::path& self, const Child& child, const BenchAllOptions& options, const fs::path& out_dir, ProgressBar& bar,
                      std::size_t index, double done_weight, double weight) {
  ChildResult r;
  r.name = child.name;
  r.json = out_dir / (child.name + ".json");
  r.log = out_dir / "logs" / (child.name + ".log");
  std::vector<std::string> argv{self.string()};
  argv.insert(argv.end(), child.command.begin(), child.command.end());
  const std::vector<std::string>& extra = options.quick ? child.quick_options : child.full_options;
  argv.insert(argv.end(), extra.begin(), extra.end());
  argv.push_back("--json");
  argv.push_back(r.json.string());
  std::vector<std::string> shown = argv;
  shown[0] = "fissure";
  r.command = join_command(shown);
  std::error_code ec;
  fs::remove(r.json, ec);  // a stale JSON from an earlier run must not pass for this run's
  bar.start(index, child.name, r.command);

  const int log_fd = ::open(r.log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (log_fd < 0) {
    r.error = "cannot write the log '" + r.log.string() + "'";
    bar.finish(index, child.name, "NOT STARTED: " + r.error);
    return r;
  }
  std::vector<char*> cargv;
  for (std::string& a : argv) cargv.push_back(a.data());
  cargv.push_back(nullptr);
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = ::fork();
  if (pid == 0) {
    // Child: stdout and stderr into the log, stdin from /dev/null (nothing may wait for input).
    const int null_fd = ::open("/dev/null", O_RDONLY);
    if (null_fd >= 0) ::dup2(null_fd, STDIN_FILENO);
    ::dup2(log_fd, STDOUT_FILENO);
    ::dup2(log_fd, STDERR_FILENO);
    ::execv(cargv[0], cargv.data());
    std::fprintf(stderr, "bench all: exec %s failed\n", cargv[0]);
    ::_exit(127);
  }
  ::close(log_fd);
  if (pid < 0) {
    r.error = "fork failed";
    bar.finish(index, child.name, "NOT STARTED: fork failed");
    return r;
  }
  int status = 0;
  while (true) {
    const pid_t done = ::waitpid(pid, &status, WNOHANG);
    if (done == pid) break;
    if (done < 0 && errno != EINTR) {
      r.error = "waitpid failed";
      break;
    }
    const double elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double estimate = options.quick ? child.quick_estimate_s : child.estimate_s;
    // The bar moves with elapsed time against the estimate, never past 95 % of this child.
    const double partial = weight * std::min(0.95, elapsed_s / std::max(1.0, estimate));
    bar.draw(done_weight + partial, index, child.name, elapsed_s, last_log_line(r.log));
    std::this_thread::sleep_for(kPollPeriod);
  }
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (WIFEXITED(status)) r.exit_code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) r.signal = WTERMSIG(status);
  r.json_written = fs::is_regular_file(r.json, ec);
  char outcome[256];
  if (r.exit_code == 0) {
    std::snprintf(outcome, sizeof outcome, "ok, %.1f s", r.wall_s);
  } else if (r.signal != 0) {
    std::snprintf(outcome, sizeof outcome, "FAILED: killed by signal %d (%s) after %.1f s, %s; log %s", r.signal, strsignal(r.signal),
                  r.wall_s, r.json_written ? "JSON written" : "no JSON", r.log.c_str());
  } else {
    std::snprintf(outcome, sizeof outcome, "FAILED: exit %d after %.1f s, %s; log %s", r.exit_code, r.wall_s,
                  r.json_written ? "JSON written" : "no JSON", r.log.c_str());
  }
  bar.finish(index, child.name, outcome);
  return r;
}

nlohmann::json to_json(const ChildResult& r) {
  return {{"name", r.name},
          {"command", r.command},
          {"exit_code", r.exit_code},
          {"signal", r.signal},
          {"error", r.error},
          {"ok", r.exit_code == 0},
          {"wall_s", r.wall_s},
          {"json", r.json.filename().string()},
          {"json_written", r.json_written},
          {"log", (fs::path("logs") / r.log.filename()).string()}};
}

std::string utc_now() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%d %H:%M:%S UTC", &tm);
  return text;
}

/// make_report.py DIR --md MD --images IMAGES; throws with the script's own last words.
void make_report(const fs::path& script, const fs::path& in_dir, const fs::path& md, const fs::path& images) {
  const fs::path log = in_dir / "logs" / "report.log";
  const std::string command = shell_quote(python_executable()) + " " + shell_quote(script.string()) + " " + shell_quote(in_dir.string()) +
                              " --md " + shell_quote(md.string()) + " --images " + shell_quote(images.string()) + " >" +
                              shell_quote(log.string()) + " 2>&1";
  const int status = std::system(command.c_str());
  if (status != 0) {
    throw EvalError("bench all: the report generator failed (" + script.string() + ", exit status " + std::to_string(status) +
                       "): " + last_log_line(log) + " (full output: " + log.string() + ")");
  }
}

void run_all(const BenchAllOptions& options, const std::string& invocation) {
  const fs::path out_dir = fs::absolute(options.out_dir);
  std::error_code ec;
  fs::create_directories(out_dir / "logs", ec);
  if (ec) throw EvalError("bench all: cannot create '" + (out_dir / "logs").string() + "': " + ec.message());
  check_python();
  const fs::path script = find_report_script();
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw EvalError("bench all: cannot find this executable (/proc/self/exe): " + ec.message());

  std::vector<Child> selected;
  for (const Child& c : children(out_dir)) {
    const bool named = std::find(options.only.begin(), options.only.end(), c.name) != options.only.end();
    if (named || (options.only.empty() && (!c.opt_in || options.stress_full))) selected.push_back(c);
  }

  const fs::path record_path = out_dir / "bench_all.json";
  nlohmann::json record;
  // --only / --report-only keep the other children's records of an earlier run.
  if (std::ifstream previous(record_path); previous && (options.report_only || !options.only.empty())) {
    try {
      previous >> record;
    } catch (const std::exception&) {
      record = nlohmann::json::object();
    }
  }
  if (!options.report_only) {
    // A plain run without --stress-full must not report a full profile left by an earlier run.
    if (options.only.empty() && !options.stress_full) fs::remove(out_dir / "stress_full.json", ec);
    double total_weight = 0.0;
    for (const Child& c : selected) total_weight += options.quick ? c.quick_estimate_s : c.estimate_s;
    ProgressBar bar(total_weight, selected.size());
    const auto start = std::chrono::steady_clock::now();
    const std::string started = utc_now();
    double done_weight = 0.0;
    if (!record.contains("children") || !record["children"].is_object()) record["children"] = nlohmann::json::object();
    for (std::size_t i = 0; i < selected.size(); ++i) {
      const double weight = options.quick ? selected[i].quick_estimate_s : selected[i].estimate_s;
      const ChildResult r = run_child(self, selected[i], options, out_dir, bar, i, done_weight, weight);
      record["children"][r.name] = to_json(r);
      done_weight += weight;
    }
    record["order"] = nlohmann::json::array();
    for (const Child& c : children(out_dir)) record["order"].push_back(c.name);
    record["invocation"] = invocation;
    record["quick"] = options.quick;
    record["started_utc"] = started;
    record["finished_utc"] = utc_now();
    record["wall_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    record["machine"] = machine_info();
    record["source"] = source_tree(script);
    std::ifstream loadavg("/proc/loadavg");
    std::string load;
    std::getline(loadavg, load);
    record["loadavg_at_end"] = load;
    std::ofstream file(record_path);
    if (!file) throw EvalError("bench all: cannot write '" + record_path.string() + "'");
    file << record.dump(2) << '\n';
  } else if (!fs::is_regular_file(record_path, ec)) {
    throw EvalError("bench all --report-only: no '" + record_path.string() + "' (run 'fissure bench all --out DIR' first)");
  }

  std::fprintf(stderr, "bench all: writing the report (%s)\n", script.c_str());
  make_report(script, out_dir, out_dir / "report.md", out_dir);
  std::printf("wrote %s\n", (out_dir / "report.md").c_str());
  if (!options.docs_dir.empty()) {
    const fs::path docs = fs::absolute(options.docs_dir);
    fs::create_directories(docs / "images" / "bench", ec);
    if (ec) throw EvalError("bench all: cannot create '" + (docs / "images" / "bench").string() + "': " + ec.message());
    make_report(script, out_dir, docs / "benchmarks.md", docs / "images" / "bench");
    std::printf("wrote %s\n", (docs / "benchmarks.md").c_str());
  }

  std::vector<std::string> failed;
  if (record.contains("children")) {
    for (const auto& [name, child] : record["children"].items()) {
      if (!child.value("ok", false)) {
        const int signal = child.value("signal", 0);
        failed.push_back(name + (signal != 0 ? " (signal " + std::to_string(signal) + ")"
                                             : " (exit " + std::to_string(child.value("exit_code", -1)) + ")"));
      }
    }
  }
  if (!failed.empty()) {
    std::string list;
    for (const std::string& f : failed) list += (list.empty() ? "" : ", ") + f;
    throw EvalError("bench all: " + std::to_string(failed.size()) + " benchmark(s) failed: " + list + "; the report says which (" +
                       (out_dir / "report.md").string() + ", logs in " + (out_dir / "logs").string() + ")");
  }
}

}  // namespace

std::vector<std::string> bench_all_names() {
  std::vector<std::string> names;
  for (const Child& c : children(".")) names.push_back(c.name);
  return names;
}

void run_bench_all(const BenchAllOptions& options, const std::string& invocation) { run_all(options, invocation); }

}  // namespace fissure::eval
