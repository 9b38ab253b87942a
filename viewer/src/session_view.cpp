// The view's hook into a session (see session_view.hpp).
#include "fissure/viewer/session_view.hpp"

#include <chrono>
#include <cmath>

namespace fissure::viewer {

SessionView::SessionView(const RenderModel& model, const SessionViewOptions& options)
    : model_(model),
      options_(options),
      frame_camera_(default_camera(model_)),
      rt_figures_(std::make_unique<RtFiguresExchange>()),
      snapshot_(std::make_unique<RenderSnapshot>()) {
  capture_publish_s_.reserve(options.expected_host_steps);
}

std::unique_ptr<SessionView> SessionView::start(const RenderModel& model, const SessionViewOptions& options, std::string& error,
                                                std::string& notice) {
  std::unique_ptr<SessionView> view(new SessionView(model, options));
  if (!options.frames_dir.empty()) {
    if (options.frame_every_steps < 1) {
      error = "--frame-every must be at least 1 host step";
      return nullptr;
    }
    FrameWriterOptions fo;
    fo.directory = options.frames_dir;
    fo.width_px = options.frame_width_px;
    fo.height_px = options.frame_height_px;
    fo.camera = view->frame_camera_;
    view->frames_ = FrameWriter::start(view->model_, fo, error);
    if (!view->frames_) return nullptr;
  }
  if (options.window) {
    std::string why_not;
    view->window_ = ViewWindow::open(view->model_, options.window_options, why_not);
    if (!view->window_) notice = why_not;
  }
  return view;
}

SessionView::~SessionView() { (void)finish(); }

void SessionView::on_host_step(const host::HostSimulation& sim, const ContactProxy* proxy) noexcept {
  const std::uint64_t step = host_steps_++;
  const bool frame_due = frames_ != nullptr && step % static_cast<std::uint64_t>(options_.frame_every_steps) == 0;
  if (!frame_due && window_ == nullptr) return;

  const auto t0 = std::chrono::steady_clock::now();
  (void)rt_figures_->try_fetch(rt_);  // keeps the previous figures when nothing new came
  RenderSnapshot& s = *snapshot_;
  if (proxy != nullptr) {
    capture_patches(*proxy, s);
  } else {
    s.patch_count = 0;
  }
  capture_snapshot(sim, s);
  s.overlay.tick_rate_hz = rt_.tick_rate_hz;
  s.overlay.proxy_age_ms = rt_.proxy_age_ms;
  s.overlay.overruns = rt_.overruns;
  // The overlay's F is what the hand feels when an rt loop runs; the host's force otherwise.
  if (std::isfinite(rt_.force_n)) s.overlay.force_n = rt_.force_n;
  if (window_ != nullptr) {
    s.overlay.paused = window_->paused();
    window_->exchange().publish(s);
  }
  if (frame_due) {
    frames_->publish(s);
  }
  if (capture_publish_s_.size() < capture_publish_s_.capacity()) {
    capture_publish_s_.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  // Waiting is outside the timed span: it is the caller's choice (lockstep), not the hand-off's cost.
  if (frame_due && options_.wait_for_frames) frames_->wait_until_written(s.sequence);
}

SessionViewStats SessionView::finish() {
  SessionViewStats stats;
  if (!finished_) {
    finished_ = true;
    if (frames_) frames_->finish();
  }
  if (frames_) {
    stats.frames_written = frames_->frames_written();
    stats.frames_dropped = frames_->frames_dropped();
    stats.frame_s = frames_->frame_times_s();
    stats.frames_error = frames_->error();
    stats.gl_description = frames_->gl_description();
    stats.frames_published = frames_->frames_published();
  }
  if (window_) {
    stats.window_open = true;
    stats.window_frames = window_->frames_drawn();
  }
  window_.reset();
  stats.capture_publish_s = capture_publish_s_;
  return stats;
}

}  // namespace fissure::viewer
