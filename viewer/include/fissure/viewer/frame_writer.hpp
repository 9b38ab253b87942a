#pragma once
// Offscreen PNG frames in their own thread (`--frames DIR --frame-every N`). The host publishes
// a RenderSnapshot into exchange() (wait-free: one memcpy and one atomic exchange); the writer
// thread fetches the newest, renders it headlessly (offscreen_context.hpp) and writes
// DIR/frame_NNNNNN.png. A slow writer never slows the host: snapshots it had no time for are
// replaced by newer ones and counted as dropped — unless the caller asks to wait for each frame
// (wait_until_written, for offline tools like `fissure render` that want every Nth step).
// finish() also writes DIR/frames.json: the camera, where it puts the subject in the image, and
// each frame's snapshot sequence and simulated time (so a report or a test can read the frames
// without knowing how they were made).
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "fissure/viewer/orbit_camera.hpp"
#include "fissure/viewer/render_snapshot.hpp"

namespace fissure::viewer {

struct FrameWriterOptions {
  std::filesystem::path directory;
  int width_px = 960;
  int height_px = 720;
  OrbitCamera camera{};  ///< set it (e.g. default_camera(model)); the writer does not move it
  /// Added to the writer thread's nice value before it creates its GL context, so it and the
  /// llvmpipe render threads Mesa starts from it (threads inherit nice on Linux) yield the CPU
  /// to the host step and the rt tick on a small machine. 10: well below normal, still runs.
  int nice_increment = 10;
};

/// One written frame: which snapshot it shows.
struct FrameRecord {
  std::uint64_t sequence = 0;
  double time_s = 0.0;  ///< the snapshot's simulated time
};

class FrameWriter {
 public:
  /// Starts the writer thread and waits for it to create its headless GL context. nullptr when
  /// it cannot (`error` says why in one line) or when the directory cannot be created.
  static std::unique_ptr<FrameWriter> start(const RenderModel& model, const FrameWriterOptions& options, std::string& error);
  /// finish()es.
  ~FrameWriter();
  /// Writes whatever was published last and not yet written, joins the thread and writes
  /// DIR/frames.json (a failure to write it shows in error()).
  void finish() noexcept;
  FrameWriter(const FrameWriter&) = delete;
  FrameWriter& operator=(const FrameWriter&) = delete;

  /// The host's side (single producer): hands the snapshot over through the wait-free exchange
  /// (one memcpy, one atomic exchange) and counts it. Never blocks.
  void publish(const RenderSnapshot& snapshot) noexcept {
    exchange_->publish(snapshot);
    frames_published_.fetch_add(1, std::memory_order_relaxed);
  }
  /// Blocks the caller until the snapshot with this sequence (or a newer one) has been written.
  void wait_until_written(std::uint64_t sequence) const noexcept;

  [[nodiscard]] std::uint64_t frames_written() const noexcept { return frames_written_.load(std::memory_order_acquire); }
  [[nodiscard]] std::uint64_t frames_published() const noexcept { return frames_published_.load(std::memory_order_relaxed); }
  /// Published snapshots that were superseded before the writer fetched them (exact after
  /// finish(); while running, one just published and not yet fetched counts too).
  [[nodiscard]] std::uint64_t frames_dropped() const noexcept {
    const std::uint64_t published = frames_published_.load(std::memory_order_relaxed);
    const std::uint64_t fetched = frames_fetched_.load(std::memory_order_acquire);
    return published > fetched ? published - fetched : 0;
  }
  /// Wall time per frame (render + read back + PNG encode) [s], one entry per written frame;
  /// empty until finish().
  [[nodiscard]] std::vector<double> frame_times_s() const;
  /// Per written frame, in order; empty until finish().
  [[nodiscard]] std::vector<FrameRecord> frame_records() const;
  /// The write error (empty if none); the writer stops writing after one.
  [[nodiscard]] std::string error() const;
  [[nodiscard]] const std::string& gl_description() const noexcept { return gl_description_; }
  [[nodiscard]] std::filesystem::path frame_path(std::uint64_t index) const;

 private:
  FrameWriter(const RenderModel& model, const FrameWriterOptions& options);
  void run(std::atomic<int>& ready, std::string& error) noexcept;
  void write_index() noexcept;

  RenderModel model_;
  FrameWriterOptions options_;
  std::unique_ptr<SnapshotExchange> exchange_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> written_sequence_{0};
  std::atomic<std::uint64_t> frames_written_{0};
  std::atomic<std::uint64_t> frames_published_{0};
  std::atomic<std::uint64_t> frames_fetched_{0};
  std::atomic<bool> failed_{false};
  std::vector<double> frame_times_s_;  // writer thread only until joined
  std::vector<FrameRecord> records_;   // writer thread only until joined
  bool started_ = false;   // the thread got its GL context: finish() writes the index
  bool finished_ = false;
  std::string error_;                  // writer thread only until joined
  std::string gl_description_;
};

}  // namespace fissure::viewer
