#pragma once
// `--view`: a GLFW window (OpenGL 3.3 core) in its own thread, drawing at display rate (vsync)
// the newest RenderSnapshot the host published into exchange(). It only ever *fetches* from the
// wait-free exchange, so it cannot slow or block the host step or the rt tick.
//
// Mouse: left drag orbits, wheel zooms. Keys: SPACE pause (the picture freezes; `fissure
// render` also stops its simulation, a haptic session cannot stop and runs on), M switch
// collision method (the host loop reads method_switch_requests() and restarts with the next
// method, for side-by-side comparisons; only where ViewWindowOptions::method_switching says the
// host does that), R reset the camera, F12 write the window's picture to a PNG, ESC / Q close
// the window. The host's answers to these are its own business; the window just counts them.
//
// The window draws at most kMaxViewRateHz even where vsync is absent (Xvfb, some drivers) — a
// window spinning at thousands of frames per second would take a core from the host step.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>

#include "fissure/viewer/orbit_camera.hpp"
#include "fissure/viewer/render_snapshot.hpp"

namespace fissure::viewer {

/// Upper bound on the window's frame rate [Hz]: a display's usual refresh; the host publishes
/// at 1 kHz, so faster drawing would only burn CPU.
inline constexpr double kMaxViewRateHz = 60.0;

struct ViewWindowOptions {
  int width_px = 960;
  int height_px = 720;
  /// Does the host restart with the next method on M? (`fissure render` does; a `fissure run`
  /// session cannot swap its collision method under the hand.) Only changes the help line.
  bool method_switching = true;
  /// Where F12 writes view_NNN.png.
  std::filesystem::path screenshot_dir = ".";
  /// Added to the window thread's nice value (see FrameWriterOptions::nice_increment): the view
  /// yields to the host step and the rt tick. 5: below them, above the frame writer.
  int nice_increment = 5;
};

class ViewWindow {
 public:
  /// Opens the window and starts its thread; waits until the window exists. nullptr when there
  /// is no display or no GL 3.3 context; `why_not` then says so in one line.
  static std::unique_ptr<ViewWindow> open(const RenderModel& model, const ViewWindowOptions& options, std::string& why_not);
  /// Closes the window and joins the thread.
  ~ViewWindow();
  ViewWindow(const ViewWindow&) = delete;
  ViewWindow& operator=(const ViewWindow&) = delete;

  [[nodiscard]] SnapshotExchange& exchange() noexcept { return *exchange_; }
  [[nodiscard]] bool paused() const noexcept { return paused_.load(std::memory_order_relaxed); }
  [[nodiscard]] std::uint64_t method_switch_requests() const noexcept { return method_switches_.load(std::memory_order_relaxed); }
  /// The user closed the window (the session goes on without it).
  [[nodiscard]] bool closed() const noexcept { return closed_.load(std::memory_order_relaxed); }
  /// Frames drawn so far (display rate).
  [[nodiscard]] std::uint64_t frames_drawn() const noexcept { return frames_drawn_.load(std::memory_order_relaxed); }
  /// F12 presses turned into PNG files so far.
  [[nodiscard]] std::uint64_t screenshots_written() const noexcept { return screenshots_.load(std::memory_order_relaxed); }
  /// The PNG the n-th F12 writes (n from 0).
  [[nodiscard]] std::filesystem::path screenshot_path(std::uint64_t n) const;

  // Input, called from the window thread's GLFW callbacks.
  void on_key(int key, int action) noexcept;
  void on_cursor(double x_px, double y_px) noexcept;
  void on_button(int button, int action) noexcept;
  void on_scroll(double steps) noexcept;

 private:
  ViewWindow(const RenderModel& model, const ViewWindowOptions& options);
  void run(std::atomic<int>& ready, std::string& why_not) noexcept;
  void write_screenshot(int width_px, int height_px) noexcept;  // window thread, after drawing

  RenderModel model_;
  ViewWindowOptions options_;
  std::unique_ptr<SnapshotExchange> exchange_;
  OrbitCamera camera_;  // window thread only
  bool dragging_ = false;
  bool screenshot_requested_ = false;  // window thread only
  double last_x_px_ = 0.0, last_y_px_ = 0.0;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> paused_{false};
  std::atomic<bool> closed_{false};
  std::atomic<std::uint64_t> method_switches_{0};
  std::atomic<std::uint64_t> frames_drawn_{0};
  std::atomic<std::uint64_t> screenshots_{0};
};

}  // namespace fissure::viewer
