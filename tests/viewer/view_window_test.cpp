// --view without a display: one line saying so, no window, no thread left behind.
#include "fissure/viewer/view_window.hpp"

#include <gtest/gtest.h>

#include <cstdlib>

namespace fissure::viewer {
namespace {

TEST(ViewWindow, NoDisplaySaysSoInOneLine) {
  ::unsetenv("DISPLAY");
  ::unsetenv("WAYLAND_DISPLAY");
  RenderModel model;
  std::string why_not;
  ViewWindowOptions options;
  options.width_px = 640;
  options.height_px = 480;
  EXPECT_EQ(ViewWindow::open(model, options, why_not), nullptr);
  EXPECT_NE(why_not.find("--view"), std::string::npos);
  EXPECT_NE(why_not.find("display"), std::string::npos);
  EXPECT_EQ(why_not.find('\n'), std::string::npos);
}

}  // namespace
}  // namespace fissure::viewer
