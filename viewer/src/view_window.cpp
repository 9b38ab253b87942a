// The GLFW window thread (see view_window.hpp).
#include "fissure/viewer/view_window.hpp"

#include <cstdlib>
#include <exception>

#include "fissure/viewer/scene_renderer.hpp"

#if defined(FISSURE_VIEWER_HAS_GLFW)
#define GLFW_INCLUDE_NONE
#include <GL/glcorearb.h>
#include <GLFW/glfw3.h>
#endif

namespace fissure::viewer {

ViewWindow::ViewWindow(const RenderModel& model, int width_px, int height_px)
    : model_(model), width_px_(width_px), height_px_(height_px), exchange_(std::make_unique<SnapshotExchange>()),
      camera_(default_camera(model_)) {}

std::unique_ptr<ViewWindow> ViewWindow::open(const RenderModel& model, int width_px, int height_px, std::string& why_not) {
#if !defined(FISSURE_VIEWER_HAS_GLFW)
  (void)model;
  (void)width_px;
  (void)height_px;
  why_not = "--view: this build has no GLFW (install libglfw3-dev and reconfigure); running without the view";
  return nullptr;
#else
  const char* x11 = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  if ((x11 == nullptr || *x11 == '\0') && (wayland == nullptr || *wayland == '\0')) {
    why_not = "--view: no display (DISPLAY and WAYLAND_DISPLAY are unset); running without the view";
    return nullptr;
  }
  std::unique_ptr<ViewWindow> window(new ViewWindow(model, width_px, height_px));
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

void ViewWindow::run(std::atomic<int>& ready, std::string& why_not) noexcept {
#if defined(FISSURE_VIEWER_HAS_GLFW)
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
  GLFWwindow* window = glfwCreateWindow(width_px_, height_px_, title.c_str(), nullptr, nullptr);
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
  while (!stop_.load(std::memory_order_acquire) && glfwWindowShouldClose(window) == GLFW_FALSE) {
    glfwPollEvents();
    (void)exchange_->try_fetch(*snapshot);  // keep the last one when nothing new came
    int width = 0, height = 0;
    glfwGetFramebufferSize(window, &width, &height);
    if (width > 0 && height > 0) {
      glBindFramebuffer(GL_FRAMEBUFFER, 0);
      renderer->draw(*snapshot, camera_, width, height,
                     paused() ? "PAUSED - SPACE RESUMES | M SWITCHES METHOD" : "SPACE PAUSE | M METHOD | DRAG ORBIT | WHEEL ZOOM");
    }
    glfwSwapBuffers(window);
    frames_drawn_.fetch_add(1, std::memory_order_relaxed);
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
