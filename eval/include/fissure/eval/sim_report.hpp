#pragma once
// Helpers shared by `fissure sim` and `fissure bench collision`: machine description for
// the JSON, order statistics, and a one-line progress bar on stderr.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace fissure::eval {

/// nproc, CPU model (/proc/cpuinfo), kernel (uname) — every benchmark JSON carries it.
[[nodiscard]] nlohmann::json sim_machine_info();

/// The q-quantile (0..1) of `samples` (nearest-rank on a sorted copy); 0 when empty.
[[nodiscard]] double sim_quantile(std::vector<double> samples, double q);

/// A progress bar redrawn in place on a terminal, or a line every 10 % otherwise.
class SimProgress {
 public:
  SimProgress(std::string label, long total);
  void update(long done, const std::string& status);
  void finish(const std::string& status);

 private:
  std::string label_;
  long total_;
  int last_decile_ = -1;
  bool tty_;
};

}  // namespace fissure::eval
