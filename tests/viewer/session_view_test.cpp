// SessionView, the view's hook into a session: which host steps become frames, that waiting
// loses none and not waiting accounts for every one (written or dropped), the rt figures in the
// overlay, and a window without a display being one line, not a failure.
#include "fissure/viewer/session_view.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "fissure/host_sim/scene_loader.hpp"

namespace fissure::viewer {
namespace {

class SessionViewTest : public ::testing::Test {
 public:
  SessionViewTest() : sim_(host::load_scene(host::resolve_scene_path("spatula-sphere"))) {
    sim_.settle(0.01);
    model_ = make_render_model(sim_);
  }

  void step() { (void)sim_.step(host::to_tool_pose(sim_.scene().trajectory.start)); }

  static std::filesystem::path fresh_dir(const char* name) {
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / name;
    std::filesystem::remove_all(dir);
    return dir;
  }

  host::HostSimulation sim_;
  RenderModel model_;
};

TEST_F(SessionViewTest, WaitingWritesEveryKthStepAndIndexesIt) {
  SessionViewOptions options;
  options.frames_dir = fresh_dir("fissure_session_view_wait");
  options.frame_every_steps = 3;
  options.frame_width_px = 160;
  options.frame_height_px = 120;
  options.wait_for_frames = true;
  options.expected_host_steps = 10;
  std::string error, notice;
  auto view = SessionView::start(model_, options, error, notice);
  ASSERT_NE(view, nullptr) << error;
  EXPECT_TRUE(notice.empty());
  for (int i = 0; i < 10; ++i) {
    step();
    view->on_host_step(sim_, nullptr);
  }
  const SessionViewStats stats = view->finish();
  // Steps 0, 3, 6, 9.
  EXPECT_EQ(stats.frames_published, 4U);
  EXPECT_EQ(stats.frames_written, 4U);
  EXPECT_EQ(stats.frames_dropped, 0U);
  EXPECT_EQ(stats.capture_publish_s.size(), 4U);  // only steps that publish are timed (no window)
  EXPECT_TRUE(stats.frames_error.empty());
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(std::filesystem::exists(view->frames()->frame_path(static_cast<std::uint64_t>(i))));
  EXPECT_FALSE(std::filesystem::exists(view->frames()->frame_path(4)));
  const auto records = view->frames()->frame_records();
  ASSERT_EQ(records.size(), 4U);
  const double dt = sim_.scene().simulation.time_step_s;
  const double settled_s = records[0].time_s - dt;  // the first frame is the first step after settling
  for (std::size_t i = 0; i < records.size(); ++i) EXPECT_NEAR(records[i].time_s, settled_s + static_cast<double>(3 * i + 1) * dt, 1e-9);
  std::ifstream index(options.frames_dir / "frames.json");
  ASSERT_TRUE(index);
  std::stringstream text;
  text << index.rdbuf();
  EXPECT_NE(text.str().find("\"frame_000003.png\""), std::string::npos);
  EXPECT_NE(text.str().find("\"subject_px\""), std::string::npos);
}

TEST_F(SessionViewTest, NotWaitingAccountsForEveryPublishedFrame) {
  SessionViewOptions options;
  options.frames_dir = fresh_dir("fissure_session_view_drop");
  options.frame_every_steps = 1;
  options.frame_width_px = 160;
  options.frame_height_px = 120;
  options.wait_for_frames = false;
  std::string error, notice;
  auto view = SessionView::start(model_, options, error, notice);
  ASSERT_NE(view, nullptr) << error;
  constexpr int kSteps = 40;
  for (int i = 0; i < kSteps; ++i) {
    step();
    view->on_host_step(sim_, nullptr);
  }
  const SessionViewStats stats = view->finish();
  EXPECT_EQ(stats.frames_published, static_cast<std::uint64_t>(kSteps));
  // However fast the writer was: each published frame was either written or dropped, and the
  // last one is always written (finish drains it).
  EXPECT_EQ(stats.frames_written + stats.frames_dropped, static_cast<std::uint64_t>(kSteps));
  EXPECT_GE(stats.frames_written, 1U);
  const auto records = view->frames()->frame_records();
  ASSERT_FALSE(records.empty());
  EXPECT_EQ(records.back().sequence, view->last_snapshot().sequence);
}

TEST_F(SessionViewTest, RtFiguresReachTheOverlay) {
  SessionViewOptions options;
  options.frames_dir = fresh_dir("fissure_session_view_overlay");
  options.frame_every_steps = 1;
  options.frame_width_px = 160;
  options.frame_height_px = 120;
  options.wait_for_frames = true;
  std::string error, notice;
  auto view = SessionView::start(model_, options, error, notice);
  ASSERT_NE(view, nullptr) << error;
  step();
  view->on_host_step(sim_, nullptr);
  // Nothing from rt yet: unknown, shown as "-".
  EXPECT_TRUE(std::isnan(view->last_snapshot().overlay.tick_rate_hz));
  EXPECT_EQ(view->last_snapshot().overlay.overruns, -1);
  RtFigures rt;
  rt.tick_rate_hz = 1000.0;
  rt.force_n = 2.5;
  rt.proxy_age_ms = 1.25;
  rt.overruns = 3;
  view->rt_figures().publish(rt);
  step();
  view->on_host_step(sim_, nullptr);
  const OverlayNumbers& o = view->last_snapshot().overlay;
  EXPECT_EQ(o.tick_rate_hz, 1000.0);
  EXPECT_EQ(o.force_n, 2.5);  // the force the hand feels, not the host's
  EXPECT_EQ(o.proxy_age_ms, 1.25);
  EXPECT_EQ(o.overruns, 3);
  // Nothing new published: the figures stay.
  step();
  view->on_host_step(sim_, nullptr);
  EXPECT_EQ(view->last_snapshot().overlay.overruns, 3);
  (void)view->finish();
}

TEST_F(SessionViewTest, WindowWithoutADisplayIsOneLineAndNoFailure) {
  ::unsetenv("DISPLAY");
  ::unsetenv("WAYLAND_DISPLAY");
  SessionViewOptions options;
  options.window = true;
  std::string error, notice;
  auto view = SessionView::start(model_, options, error, notice);
  ASSERT_NE(view, nullptr);
  EXPECT_TRUE(error.empty());
  EXPECT_NE(notice.find("no display"), std::string::npos);
  EXPECT_EQ(notice.find('\n'), std::string::npos);
  EXPECT_FALSE(view->active());
  step();
  view->on_host_step(sim_, nullptr);  // no sink: nothing captured
  EXPECT_EQ(view->last_snapshot().sequence, 0U);
  const SessionViewStats stats = view->finish();
  EXPECT_FALSE(stats.window_open);
  EXPECT_EQ(stats.frames_published, 0U);
}

TEST_F(SessionViewTest, FramesIntoAnUnwritableDirectoryIsAClearError) {
  SessionViewOptions options;
  options.frames_dir = "/proc/fissure-no-frames-here";
  std::string error, notice;
  EXPECT_EQ(SessionView::start(model_, options, error, notice), nullptr);
  EXPECT_NE(error.find("/proc/fissure-no-frames-here"), std::string::npos);
}

}  // namespace
}  // namespace fissure::viewer
