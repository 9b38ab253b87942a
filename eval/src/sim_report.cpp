// Machine info, quantiles and progress output for the host-sim commands (sim_report.hpp).
#include "fissure/eval/sim_report.hpp"

#include "fissure/session/machine_info.hpp"

#include <sys/utsname.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <thread>

namespace fissure::eval {
using namespace fissure::session;  // the session library: SessionHost, run_session, LinkBridge, …

nlohmann::json sim_machine_info() { return machine_info(); }

double sim_quantile(std::vector<double> samples, double q) {
  if (samples.empty()) return 0.0;
  std::sort(samples.begin(), samples.end());
  const auto rank = static_cast<std::size_t>(std::ceil(q * static_cast<double>(samples.size())));
  return samples[std::min(samples.size() - 1, rank == 0 ? 0 : rank - 1)];
}

SimProgress::SimProgress(std::string label, long total) : label_(std::move(label)), total_(std::max(1L, total)), tty_(isatty(STDERR_FILENO) != 0) {}

void SimProgress::update(long done, const std::string& status) {
  const double fraction = std::clamp(static_cast<double>(done) / static_cast<double>(total_), 0.0, 1.0);
  const int decile = static_cast<int>(fraction * 10.0);
  if (tty_) {
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(fraction * kWidth);
    std::fprintf(stderr, "\r%s [%s%s] %3.0f%% %s\033[K", label_.c_str(), std::string(static_cast<std::size_t>(filled), '#').c_str(),
                 std::string(static_cast<std::size_t>(kWidth - filled), '.').c_str(), 100.0 * fraction, status.c_str());
  } else if (decile != last_decile_) {
    std::fprintf(stderr, "%s %3.0f%% %s\n", label_.c_str(), 100.0 * fraction, status.c_str());
  }
  last_decile_ = decile;
}

void SimProgress::finish(const std::string& status) {
  if (tty_) {
    std::fprintf(stderr, "\r%s [done] %s\033[K\n", label_.c_str(), status.c_str());
  } else {
    std::fprintf(stderr, "%s done %s\n", label_.c_str(), status.c_str());
  }
}

}  // namespace fissure::eval
