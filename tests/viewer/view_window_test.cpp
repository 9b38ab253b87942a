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
  EXPECT_EQ(ViewWindow::open(model, 640, 480, why_not), nullptr);
  EXPECT_NE(why_not.find("--view"), std::string::npos);
  EXPECT_NE(why_not.find("display"), std::string::npos);
  EXPECT_EQ(why_not.find('\n'), std::string::npos);
}

}  // namespace
}  // namespace fissure::viewer
