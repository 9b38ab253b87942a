#pragma once
// The view's hook into a running session (`fissure run SCENE --view --frames DIR`, `fissure
// sim SCENE --frames DIR`): the host thread calls on_host_step() after each step; it captures
// the simulation into a preallocated RenderSnapshot and publishes it through the wait-free
// exchanges of the window (every step) and of the frame writer (every frame_every_steps-th
// step). Nothing here blocks the host step or touches the rt tick — unless the caller asks to
// wait for each frame (wait_for_frames: lockstep and offline runs, where a deterministic set of
// frames matters more than wall time).
//
// The rt loop's numbers (tick rate, force, proxy age, overruns) live on another thread in real
// time: whoever drains the rt telemetry publishes them into rt_figures() (a second wait-free
// exchange) and the host thread folds the newest into its snapshot.
#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "fissure/host_sim/host_simulation.hpp"
#include "fissure/shared/latest_value_exchange.hpp"
#include "fissure/shared/messages.hpp"
#include "fissure/viewer/frame_writer.hpp"
#include "fissure/viewer/orbit_camera.hpp"
#include "fissure/viewer/render_snapshot.hpp"
#include "fissure/viewer/view_window.hpp"

namespace fissure::viewer {

struct SessionViewOptions {
  bool window = false;             ///< --view
  ViewWindowOptions window_options{};
  std::filesystem::path frames_dir;  ///< --frames DIR (empty: no frames)
  int frame_every_steps = 10;        ///< host steps between frames (the first step is frame 0)
  int frame_width_px = 960;
  int frame_height_px = 720;
  /// Block the host thread until each frame is written (lockstep / offline: every Nth step
  /// becomes a frame, none dropped). Real time: false — frames the writer had no time for are
  /// dropped and counted.
  bool wait_for_frames = false;
  /// Host steps whose capture + publish time is recorded (preallocated; later ones uncounted).
  std::size_t expected_host_steps = 0;
};

/// The rt loop's side of the overlay. NaN / negative: unknown (shown as "-").
struct RtFigures {
  double tick_rate_hz = std::numeric_limits<double>::quiet_NaN();
  double force_n = std::numeric_limits<double>::quiet_NaN();  ///< |commanded device force|
  double proxy_age_ms = std::numeric_limits<double>::quiet_NaN();
  std::int64_t overruns = -1;
};
using RtFiguresExchange = LatestValueExchange<RtFigures>;

struct SessionViewStats {
  bool window_open = false;
  std::uint64_t window_frames = 0;
  std::uint64_t frames_written = 0;
  std::uint64_t frames_dropped = 0;   ///< published to the writer, superseded before it got to them
  std::uint64_t frames_published = 0;
  std::vector<double> frame_s;        ///< writer: render + read back + PNG per frame
  std::vector<double> capture_publish_s;  ///< host thread: capture + publish per step
  std::string frames_error;           ///< the writer's error (it stops writing after one)
  std::string gl_description;
};

class SessionView {
 public:
  /// Starts what `options` asks for, for the scene `model` describes. nullptr with `error` when
  /// frames were asked for and the writer cannot start (no headless GL, unwritable directory).
  /// A window that cannot open is not an error: `notice` gets one line and the session runs
  /// on without it (with frames, or with nothing: then this still returns a SessionView that
  /// does nothing, so the caller's loop needs no special case).
  static std::unique_ptr<SessionView> start(const RenderModel& model, const SessionViewOptions& options, std::string& error,
                                            std::string& notice);
  ~SessionView();
  SessionView(const SessionView&) = delete;
  SessionView& operator=(const SessionView&) = delete;

  /// Host thread, after each host step: capture + publish (no allocation, no lock, no wait
  /// unless wait_for_frames). `proxy`: the proxy just built (its patches are drawn), or null.
  void on_host_step(const host::HostSimulation& sim, const ContactProxy* proxy) noexcept;

  /// The rt side's numbers; one producer (the telemetry drain), the host thread consumes.
  [[nodiscard]] RtFiguresExchange& rt_figures() noexcept { return *rt_figures_; }

  /// Any sink running (window or frames)?
  [[nodiscard]] bool active() const noexcept { return window_ != nullptr || frames_ != nullptr; }
  [[nodiscard]] const ViewWindow* window() const noexcept { return window_.get(); }
  [[nodiscard]] const FrameWriter* frames() const noexcept { return frames_.get(); }
  [[nodiscard]] const OrbitCamera& frame_camera() const noexcept { return frame_camera_; }
  /// The newest snapshot captured (host thread; for tests and diagnostics).
  [[nodiscard]] const RenderSnapshot& last_snapshot() const noexcept { return *snapshot_; }
  /// Host steps seen so far.
  [[nodiscard]] std::uint64_t host_steps() const noexcept { return host_steps_; }

  /// Writes the frames still pending, joins the writer and closes the window; then the stats.
  SessionViewStats finish();

 private:
  SessionView(const RenderModel& model, const SessionViewOptions& options);

  RenderModel model_;
  SessionViewOptions options_;
  OrbitCamera frame_camera_;
  std::unique_ptr<FrameWriter> frames_;
  std::unique_ptr<ViewWindow> window_;
  std::unique_ptr<RtFiguresExchange> rt_figures_;
  std::unique_ptr<RenderSnapshot> snapshot_;  // host thread only
  RtFigures rt_{};                            // host thread only: newest fetched
  std::uint64_t host_steps_ = 0;              // host thread only
  std::vector<double> capture_publish_s_;     // host thread only, reserved once
  bool finished_ = false;
};

}  // namespace fissure::viewer
