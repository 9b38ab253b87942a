// Headless EGL context + framebuffer objects (see offscreen_context.hpp).
#include "fissure/viewer/offscreen_context.hpp"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/glcorearb.h>

#include <cstdio>
#include <cstring>
#include <string>

namespace fissure::viewer {
namespace {

// 4× multisampling: llvmpipe supports it, and thin tools (2 mm) stay visible at a distance.
constexpr int kSamples = 4;

std::string egl_error(const char* step) {
  char text[96];
  std::snprintf(text, sizeof text, "%s failed (EGL error 0x%04X)", step, static_cast<unsigned>(eglGetError()));
  return text;
}

bool has_extension(const char* extensions, const char* name) {
  if (extensions == nullptr) return false;
  const std::size_t n = std::strlen(name);
  for (const char* p = std::strstr(extensions, name); p != nullptr; p = std::strstr(p + 1, name)) {
    if ((p == extensions || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  }
  return false;
}

// Surfaceless first (Mesa: no display, no GPU), then an EGL device, then the default display.
EGLDisplay open_display(std::string& platform) {
  const char* client_extensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (has_extension(client_extensions, "EGL_MESA_platform_surfaceless")) {
    EGLDisplay d = eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (d != EGL_NO_DISPLAY && eglInitialize(d, nullptr, nullptr) == EGL_TRUE) {
      platform = "EGL surfaceless";
      return d;
    }
  }
  if (has_extension(client_extensions, "EGL_EXT_platform_device")) {
    auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    EGLDeviceEXT devices[4];
    EGLint count = 0;
    if (query_devices != nullptr && query_devices(4, devices, &count) == EGL_TRUE) {
      for (EGLint i = 0; i < count; ++i) {
        EGLDisplay d = eglGetPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
        if (d != EGL_NO_DISPLAY && eglInitialize(d, nullptr, nullptr) == EGL_TRUE) {
          platform = "EGL device";
          return d;
        }
      }
    }
  }
  EGLDisplay d = eglGetDisplay(EGL_DEFAULT_DISPLAY);
  if (d != EGL_NO_DISPLAY && eglInitialize(d, nullptr, nullptr) == EGL_TRUE) {
    platform = "EGL default display";
    return d;
  }
  return EGL_NO_DISPLAY;
}

}  // namespace

std::unique_ptr<OffscreenContext> OffscreenContext::create(int width_px, int height_px, std::string& error) {
  std::string platform;
  EGLDisplay display = open_display(platform);
  if (display == EGL_NO_DISPLAY) {
    error = "no headless OpenGL: no EGL display could be initialised (surfaceless, device or default; install libegl-mesa0 and libgl1-mesa-dri)";
    return nullptr;
  }
  if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE) {
    error = "no headless OpenGL: " + egl_error("eglBindAPI(EGL_OPENGL_API)");
    eglTerminate(display);
    return nullptr;
  }
  const bool surfaceless = has_extension(eglQueryString(display, EGL_EXTENSIONS), "EGL_KHR_surfaceless_context");
  const EGLint config_attributes[] = {EGL_SURFACE_TYPE, surfaceless ? 0 : EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                                      EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8, EGL_NONE};
  EGLConfig config = nullptr;
  EGLint config_count = 0;
  if (eglChooseConfig(display, config_attributes, &config, 1, &config_count) != EGL_TRUE || config_count < 1) {
    error = "no headless OpenGL: " + egl_error("eglChooseConfig (desktop GL, RGB8)");
    eglTerminate(display);
    return nullptr;
  }
  const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3, EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                       EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
  EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attributes);
  if (context == EGL_NO_CONTEXT) {
    error = "no headless OpenGL: " + egl_error("eglCreateContext (OpenGL 3.3 core)");
    eglTerminate(display);
    return nullptr;
  }
  EGLSurface surface = EGL_NO_SURFACE;
  if (!surfaceless) {
    const EGLint pbuffer_attributes[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
    surface = eglCreatePbufferSurface(display, config, pbuffer_attributes);
    if (surface == EGL_NO_SURFACE) {
      error = "no headless OpenGL: " + egl_error("eglCreatePbufferSurface");
      eglDestroyContext(display, context);
      eglTerminate(display);
      return nullptr;
    }
  }
  if (eglMakeCurrent(display, surface, surface, context) != EGL_TRUE) {
    error = "no headless OpenGL: " + egl_error("eglMakeCurrent");
    if (surface != EGL_NO_SURFACE) eglDestroySurface(display, surface);
    eglDestroyContext(display, context);
    eglTerminate(display);
    return nullptr;
  }
  std::unique_ptr<OffscreenContext> out(new OffscreenContext());
  out->display_ = display;
  out->context_ = context;
  out->surface_ = surface;
  out->width_ = width_px;
  out->height_ = height_px;
  out->description_ = platform + ": " + reinterpret_cast<const char*>(glGetString(GL_RENDERER)) + " / " +
                      reinterpret_cast<const char*>(glGetString(GL_VERSION));

  glGenRenderbuffers(1, &out->msaa_colour_);
  glBindRenderbuffer(GL_RENDERBUFFER, out->msaa_colour_);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, kSamples, GL_RGBA8, width_px, height_px);
  glGenRenderbuffers(1, &out->msaa_depth_);
  glBindRenderbuffer(GL_RENDERBUFFER, out->msaa_depth_);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, kSamples, GL_DEPTH_COMPONENT24, width_px, height_px);
  glGenFramebuffers(1, &out->msaa_fbo_);
  glBindFramebuffer(GL_FRAMEBUFFER, out->msaa_fbo_);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, out->msaa_colour_);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, out->msaa_depth_);
  const GLenum msaa_status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  glGenRenderbuffers(1, &out->resolve_colour_);
  glBindRenderbuffer(GL_RENDERBUFFER, out->resolve_colour_);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width_px, height_px);
  glGenFramebuffers(1, &out->resolve_fbo_);
  glBindFramebuffer(GL_FRAMEBUFFER, out->resolve_fbo_);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, out->resolve_colour_);
  const GLenum resolve_status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (msaa_status != GL_FRAMEBUFFER_COMPLETE || resolve_status != GL_FRAMEBUFFER_COMPLETE) {
    char text[128];
    std::snprintf(text, sizeof text, "no headless OpenGL: framebuffer incomplete (0x%04X / 0x%04X)", msaa_status, resolve_status);
    error = text;
    return nullptr;  // the destructor releases what was made
  }
  return out;
}

OffscreenContext::~OffscreenContext() {
  if (display_ == nullptr) return;
  if (msaa_fbo_ != 0) glDeleteFramebuffers(1, &msaa_fbo_);
  if (resolve_fbo_ != 0) glDeleteFramebuffers(1, &resolve_fbo_);
  if (msaa_colour_ != 0) glDeleteRenderbuffers(1, &msaa_colour_);
  if (msaa_depth_ != 0) glDeleteRenderbuffers(1, &msaa_depth_);
  if (resolve_colour_ != 0) glDeleteRenderbuffers(1, &resolve_colour_);
  eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  if (surface_ != nullptr) eglDestroySurface(display_, surface_);
  eglDestroyContext(display_, context_);
  eglTerminate(display_);
}

void OffscreenContext::begin_frame() noexcept { glBindFramebuffer(GL_FRAMEBUFFER, msaa_fbo_); }

void OffscreenContext::read_frame(RgbaImage& out) {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, msaa_fbo_);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_fbo_);
  glBlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, resolve_fbo_);
  read_bound_framebuffer(width_, height_, out);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

void read_bound_framebuffer(int width_px, int height_px, RgbaImage& out) {
  out.width = width_px;
  out.height = height_px;
  out.pixels.resize(static_cast<std::size_t>(width_px) * static_cast<std::size_t>(height_px) * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width_px, height_px, GL_RGBA, GL_UNSIGNED_BYTE, out.pixels.data());
  // GL's rows run bottom to top; images run top to bottom.
  const std::size_t row = static_cast<std::size_t>(width_px) * 4;
  std::vector<std::uint8_t> swap(row);
  for (int y = 0; y < height_px / 2; ++y) {
    std::uint8_t* a = &out.pixels[static_cast<std::size_t>(y) * row];
    std::uint8_t* b = &out.pixels[static_cast<std::size_t>(height_px - 1 - y) * row];
    std::memcpy(swap.data(), a, row);
    std::memcpy(a, b, row);
    std::memcpy(b, swap.data(), row);
  }
}

}  // namespace fissure::viewer
