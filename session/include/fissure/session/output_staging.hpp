#pragma once
// A run's outputs (trace, summary, plot, frames) are written under hidden temporary names beside
// their final ones and moved into place by commit() only when the run is complete, so:
//   * a run that fails or is killed never leaves a half-written file where a complete one was;
//   * a run that fails before it starts (no device, a rate that does not divide) leaves an
//     earlier run's files exactly as they were;
//   * each final file is either the old complete one or the new complete one (rename(2) within
//     one directory is atomic), never a mixture.
// Whatever was staged and not committed is removed when the OutputStaging goes away.
#include <filesystem>
#include <string>
#include <vector>

namespace fissure::session {

class OutputStaging {
 public:
  OutputStaging() = default;
  ~OutputStaging();
  OutputStaging(const OutputStaging&) = delete;
  OutputStaging& operator=(const OutputStaging&) = delete;

  /// The temporary path to write instead of `final_path`: same directory (created if missing),
  /// name ".STEM.incomplete-PID.EXT" (the extension is kept: the plotter picks its format by
  /// it). Throws SessionError naming the directory when it cannot be created.
  std::filesystem::path file(const std::filesystem::path& final_path);

  /// A hidden directory inside `final_dir` (created) to write a set of files into, e.g. frames.
  /// On commit each file moves into `final_dir`, and the files of `final_dir` whose names start
  /// with `stale_prefix` and end with `stale_suffix` that this run did not write (an earlier,
  /// longer run's frames) are removed; no other file of `final_dir` is touched.
  std::filesystem::path directory(const std::filesystem::path& final_dir, std::string stale_prefix, std::string stale_suffix);

  /// Moves everything staged into place, in the order it was staged (stage the file that marks
  /// a complete run, the summary, last). Throws SessionError naming the file when a move fails.
  void commit();

  /// The temporary name `file()` uses for `final_path` in this process.
  [[nodiscard]] static std::filesystem::path temporary_name(const std::filesystem::path& final_path);

 private:
  struct Staged {
    std::filesystem::path temporary;
    std::filesystem::path final_path;
    bool is_directory = false;
    std::string stale_prefix;
    std::string stale_suffix;
  };
  std::vector<Staged> staged_;
};

}  // namespace fissure::session
