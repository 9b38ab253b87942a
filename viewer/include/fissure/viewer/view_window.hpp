#pragma once
// `--view`: a GLFW window (OpenGL 3.3 core) in its own thread, drawing at display rate (vsync)
// the newest RenderSnapshot the host published into exchange(). It only ever *fetches* from the
// wait-free exchange, so it cannot slow or block the host step or the rt tick.
//
// Mouse: left drag orbits, wheel zooms. Keys: SPACE pause, M switch collision method (the host
// loop reads method_switch_requests() and restarts with the next method, for side-by-side
// comparisons), R reset the camera, ESC / Q close the window. The host's answers to these are
// its own business; the window just counts the requests.
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

#include "fissure/viewer/orbit_camera.hpp"
#include "fissure/viewer/render_snapshot.hpp"

namespace fissure::viewer {

class ViewWindow {
 public:
  /// Opens the window and starts its thread; waits until the window exists. nullptr when there
  /// is no display or no GL 3.3 context; `why_not` then says so in one line.
  static std::unique_ptr<ViewWindow> open(const RenderModel& model, int width_px, int height_px, std::string& why_not);
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

  // Input, called from the window thread's GLFW callbacks.
  void on_key(int key, int action) noexcept;
  void on_cursor(double x_px, double y_px) noexcept;
  void on_button(int button, int action) noexcept;
  void on_scroll(double steps) noexcept;

 private:
  ViewWindow(const RenderModel& model, int width_px, int height_px);
  void run(std::atomic<int>& ready, std::string& why_not) noexcept;

  RenderModel model_;
  int width_px_, height_px_;
  std::unique_ptr<SnapshotExchange> exchange_;
  OrbitCamera camera_;  // window thread only
  bool dragging_ = false;
  double last_x_px_ = 0.0, last_y_px_ = 0.0;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> paused_{false};
  std::atomic<bool> closed_{false};
  std::atomic<std::uint64_t> method_switches_{0};
  std::atomic<std::uint64_t> frames_drawn_{0};
};

}  // namespace fissure::viewer
