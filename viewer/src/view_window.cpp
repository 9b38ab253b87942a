// The GLFW window thread (see view_window.hpp).
#include "fissure/viewer/view_window.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>

#include "fissure/viewer/offscreen_context.hpp"
#include "fissure/viewer/scene_renderer.hpp"

#if defined(FISSURE_VIEWER_HAS_GLFW)
#define GLFW_INCLUDE_NONE
#include <GL/glcorearb.h>
#include <GLFW/glfw3.h>
#endif

namespace fissure::viewer {

ViewWindow::ViewWindow(const RenderModel& model, const ViewWindowOptions& options)
    : model_(model), options_(options), exchange_(std::make_unique<SnapshotExchange>()), camera_(default_camera(model_)) {}

std::filesystem::path ViewWindow::screenshot_path(std::uint64_t n) const {
  char name[32];
  std::snprintf(name, sizeof name, "view_%03llu.png", static_cast<unsigned long long>(n));
  return options_.screenshot_dir / name;
}

std::unique_ptr<ViewWindow> ViewWindow::open(const RenderModel& model, const ViewWindowOptions& options, std::string& why_not) {
#if !defined(FISSURE_VIEWER_HAS_GLFW)
  (void)model;
  (void)options;
  why_not = "--view: this build has no GLFW (install libglfw3-dev and reconfigure); running without the view";
  return nullptr;
#else
  const char* x11 = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  if ((x11 == nullptr || *x11 == '\0') && (wayland == nullptr || *wayland == '\0')) {
    why_not = "--view: no display (DISPLAY and WAYLAND_DISPLAY are unset); running without the view";
    return nullptr;
  }
  std::unique_ptr<ViewWindow> window(new ViewWindow(model, options));
  std::atomic<int> ready{0};
  std::string error;
  window->thread_ = std::thread([w = window.get(), &ready, &error] { w->run(ready, error); });
  ready.wait(0, std::memory_order_acquire);
  if (ready.load(std::memory_order_acquire) < 0) {
    window->thread_.join();
    why_not = "--view: " + error + "; running without the view";
    return nullptr;
  }
  return window;
#endif
}

ViewWindow::~ViewWindow() {
  stop_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
}

void ViewWindow::on_key(int key, int action) noexcept {
#if defined(FISSURE_VIEWER_HAS_GLFW)
  if (action != GLFW_PRESS) return;
  switch (key) {
    case GLFW_KEY_SPACE: paused_.store(!paused_.load(std::memory_order_relaxed), std::memory_order_relaxed); break;
    case GLFW_KEY_M: method_switches_.fetch_add(1, std::memory_order_relaxed); break;
    case GLFW_KEY_R: camera_ = default_camera(model_); break;
    case GLFW_KEY_F12: screenshot_requested_ = true; break;
    case GLFW_KEY_ESCAPE:
    case GLFW_KEY_Q: stop_.store(true, std::memory_order_release); break;
    default: break;
  }
#else
  (void)key;
  (void)action;
#endif
}

void ViewWindow::on_cursor(double x_px, double y_px) noexcept {
  if (dragging_) camera_.orbit(static_cast<float>(x_px - last_x_px_), static_cast<float>(y_px - last_y_px_));
  last_x_px_ = x_px;
  last_y_px_ = y_px;
}

void ViewWindow::on_button(int button, int action) noexcept {
#if defined(FISSURE_VIEWER_HAS_GLFW)
  if (button == GLFW_MOUSE_BUTTON_LEFT) dragging_ = action == GLFW_PRESS;
#else
  (void)button;
  (void)action;
#endif
}

void ViewWindow::on_scroll(double steps) noexcept { camera_.zoom(static_cast<float>(steps)); }

void ViewWindow::write_screenshot(int width_px, int height_px) noexcept {
#if defined(FISSURE_VIEWER_HAS_GLFW)
  // The back buffer still holds the frame just drawn (before the swap).
  const std::filesystem::path path = screenshot_path(screenshots_.load(std::memory_order_relaxed));
  try {
    std::filesystem::create_directories(options_.screenshot_dir);
    RgbaImage image;
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    glReadBuffer(GL_BACK);
    read_bound_framebuffer(width_px, height_px, image);
    write_png(image, path.string());
    screenshots_.fetch_add(1, std::memory_order_relaxed);
    std::fprintf(stderr, "view: wrote %s (%d x %d)\n", path.c_str(), width_px, height_px);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "view: F12 picture not written: %s\n", e.what());
  }
#else
  (void)width_px;
  (void)height_px;
#endif
}

void ViewWindow::run(std::atomic<int>& ready, std::string& why_not) noexcept {
#if defined(FISSURE_VIEWER_HAS_GLFW)
  if (options_.nice_increment > 0) {
    // Per-thread nice (Linux), set before GL starts any helper threads so they inherit it.
    const auto tid = static_cast<id_t>(::gettid());
    errno = 0;
    const int current = ::getpriority(PRIO_PROCESS, tid);
    if (errno == 0) (void)::setpriority(PRIO_PROCESS, tid, current + options_.nice_increment);
  }
  auto fail = [&](const std::string& reason) {
    why_not = reason;
    ready.store(-1, std::memory_order_release);
    ready.notify_all();
  };
  glfwSetErrorCallback(nullptr);
  if (glfwInit() != GLFW_TRUE) {
    const char* description = nullptr;
    glfwGetError(&description);
    fail(std::string("cannot open the display (") + (description != nullptr ? description : "glfwInit failed") + ")");
    return;
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_SAMPLES, 4);
  const std::string title = "fissure - " + model_.scene_name;
  GLFWwindow* window = glfwCreateWindow(options_.width_px, options_.height_px, title.c_str(), nullptr, nullptr);
  if (window == nullptr) {
    const char* description = nullptr;
    glfwGetError(&description);
    fail(std::string("no OpenGL 3.3 core window (") + (description != nullptr ? description : "glfwCreateWindow failed") + ")");
    glfwTerminate();
    return;
  }
  glfwMakeContextCurrent(window);
  glfwSwapInterval(1);  // display rate
  glfwSetWindowUserPointer(window, this);
  glfwSetKeyCallback(window, [](GLFWwindow* w, int key, int, int action, int) {
    static_cast<ViewWindow*>(glfwGetWindowUserPointer(w))->on_key(key, action);
  });
  glfwSetCursorPosCallback(window, [](GLFWwindow* w, double x, double y) { static_cast<ViewWindow*>(glfwGetWindowUserPointer(w))->on_cursor(x, y); });
  glfwSetMouseButtonCallback(window, [](GLFWwindow* w, int button, int action, int) {
    static_cast<ViewWindow*>(glfwGetWindowUserPointer(w))->on_button(button, action);
  });
  glfwSetScrollCallback(window, [](GLFWwindow* w, double, double y) { static_cast<ViewWindow*>(glfwGetWindowUserPointer(w))->on_scroll(y); });
  std::unique_ptr<SceneRenderer> renderer;
  try {
    renderer = std::make_unique<SceneRenderer>(model_);
  } catch (const std::exception& e) {
    fail(e.what());
    glfwDestroyWindow(window);
    glfwTerminate();
    return;
  }
  ready.store(1, std::memory_order_release);
  ready.notify_all();

  auto snapshot = std::make_unique<RenderSnapshot>();
  const char* help = options_.method_switching ? "SPACE PAUSE | M METHOD | DRAG ORBIT | WHEEL ZOOM | F12 PNG"
                                               : "SPACE FREEZE | DRAG ORBIT | WHEEL ZOOM | F12 PNG";
  const char* paused_help = options_.method_switching ? "PAUSED - SPACE RESUMES | M SWITCHES METHOD" : "FROZEN (SESSION RUNS ON) - SPACE RESUMES";
  const auto frame_period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(1.0 / kMaxViewRateHz));
  auto next_frame = std::chrono::steady_clock::now();
  while (!stop_.load(std::memory_order_acquire) && glfwWindowShouldClose(window) == GLFW_FALSE) {
    glfwPollEvents();
    // Paused: keep drawing the frozen snapshot (the camera still moves).
    if (!paused()) (void)exchange_->try_fetch(*snapshot);  // keep the last one when nothing new came
    int width = 0, height = 0;
    glfwGetFramebufferSize(window, &width, &height);
    if (width > 0 && height > 0) {
      glBindFramebuffer(GL_FRAMEBUFFER, 0);
      renderer->draw(*snapshot, camera_, width, height, paused() ? paused_help : help);
      if (screenshot_requested_) write_screenshot(width, height);
    }
    screenshot_requested_ = false;
    glfwSwapBuffers(window);
    frames_drawn_.fetch_add(1, std::memory_order_relaxed);
    next_frame += frame_period;
    const auto now = std::chrono::steady_clock::now();
    if (next_frame > now) {
      std::this_thread::sleep_until(next_frame);
    } else {
      next_frame = now;  // behind (slow draw): no burst of catch-up frames
    }
  }
  closed_.store(true, std::memory_order_relaxed);
  renderer.reset();
  glfwDestroyWindow(window);
  glfwTerminate();
#else
  why_not = "no GLFW";
  ready.store(-1, std::memory_order_release);
  ready.notify_all();
#endif
}

}  // namespace fissure::viewer
