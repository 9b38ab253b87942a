#pragma once
// A headless OpenGL 3.3 core context: EGL on Mesa's surfaceless platform (llvmpipe renders on
// the CPU, so no GPU and no display are needed), falling back to EGL's device platform and then
// the default display. It renders into its own multisampled framebuffer object and reads the
// resolved pixels back.
//
// A context is current on ONE thread: create, render and destroy it on the same thread.
#include <memory>
#include <string>

#include "fissure/viewer/scene_renderer.hpp"

namespace fissure::viewer {

class OffscreenContext {
 public:
  /// Creates the context and a width × height framebuffer, and makes it current on the calling
  /// thread. nullptr when no headless GL 3.3 core context can be had; `error` then says why in
  /// one line (which EGL step failed, with its error code).
  static std::unique_ptr<OffscreenContext> create(int width_px, int height_px, std::string& error);
  ~OffscreenContext();
  OffscreenContext(const OffscreenContext&) = delete;
  OffscreenContext& operator=(const OffscreenContext&) = delete;

  [[nodiscard]] int width() const noexcept { return width_; }
  [[nodiscard]] int height() const noexcept { return height_; }
  /// "EGL surfaceless: llvmpipe (LLVM 15.0.6, 256 bits) / 4.5 (Core Profile) Mesa 22.3.6" etc.
  [[nodiscard]] const std::string& description() const noexcept { return description_; }

  /// Binds the multisampled framebuffer: draw into it after this.
  void begin_frame() noexcept;
  /// Resolves the multisampling and reads the frame (rows top to bottom) into `out`.
  void read_frame(RgbaImage& out);

 private:
  OffscreenContext() = default;
  void* display_ = nullptr;
  void* context_ = nullptr;
  void* surface_ = nullptr;  // a 1×1 pbuffer when surfaceless contexts are not supported
  int width_ = 0, height_ = 0;
  unsigned msaa_fbo_ = 0, msaa_colour_ = 0, msaa_depth_ = 0;
  unsigned resolve_fbo_ = 0, resolve_colour_ = 0;
  std::string description_;
};

/// Reads width × height pixels from the current context's bound read framebuffer (and read
/// buffer) into `out`, rows top to bottom (GL's run bottom to top). Used for the offscreen
/// frames and for the window's F12 picture of its back buffer.
void read_bound_framebuffer(int width_px, int height_px, RgbaImage& out);

/// Writes an RGBA image as an 8-bit RGB PNG. Throws std::runtime_error naming the file.
void write_png(const RgbaImage& image, const std::string& path);
/// Reads a PNG into RGBA. Throws std::runtime_error naming the file.
[[nodiscard]] RgbaImage read_png(const std::string& path);

}  // namespace fissure::viewer
