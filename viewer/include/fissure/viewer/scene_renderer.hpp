#pragma once
// The OpenGL 3.3 core renderer shared by the window and the frame writer: the soft body shaded
// with its displacement from rest colour-mapped (blue = at rest → red = deformation_full_scale_m),
// the tool or the clamp's jaws (+ handle), a checkered ground, the proxy's contact patches, the
// force on the tool as an arrow, and a text overlay in the built-in bitmap font.
//
// Needs a current GL 3.3 core context for its whole life (constructor, draw, destructor).
// Geometry is rebuilt on the CPU each frame into buffers reserved once (a few thousand
// triangles at most), so draw() does not allocate after the first frame.
#include <cstdint>
#include <string>
#include <vector>

#include "fissure/viewer/orbit_camera.hpp"
#include "fissure/viewer/render_snapshot.hpp"

namespace fissure::viewer {

/// 8-bit RGBA pixels, rows top to bottom.
struct RgbaImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;
  [[nodiscard]] const std::uint8_t* at(int x, int y) const noexcept {
    return &pixels[(static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) * 4];
  }
};

/// Colours the renderer uses (linear 0..1), exposed so image tests can classify pixels.
namespace palette {
inline constexpr float kBackground[3] = {0.13F, 0.14F, 0.17F};
inline constexpr float kSoftAtRest[3] = {0.22F, 0.45F, 0.95F};
inline constexpr float kSoftFullyDeformed[3] = {0.95F, 0.22F, 0.15F};
inline constexpr float kTool[3] = {0.98F, 0.68F, 0.12F};
inline constexpr float kHandle[3] = {0.55F, 0.5F, 0.45F};
inline constexpr float kGroundA[3] = {0.5F, 0.52F, 0.5F};
inline constexpr float kGroundB[3] = {0.42F, 0.44F, 0.42F};
inline constexpr float kPatch[3] = {0.15F, 0.9F, 0.35F};
inline constexpr float kForceArrow[3] = {0.95F, 0.25F, 0.85F};
}  // namespace palette

class SceneRenderer {
 public:
  /// Compiles the shaders and creates the buffers. Throws std::runtime_error with the GL
  /// compiler's log when a shader does not compile.
  explicit SceneRenderer(const RenderModel& model);
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  /// Draws one frame into the currently bound framebuffer (viewport width × height). `status`
  /// is an extra overlay line (e.g. "PAUSED"; may be empty).
  void draw(const RenderSnapshot& snapshot, const OrbitCamera& camera, int width_px, int height_px, const std::string& status);

  /// The overlay text for a snapshot (also what the frame writer prints): one string per line.
  [[nodiscard]] static std::vector<std::string> overlay_lines(const RenderModel& model, const RenderSnapshot& snapshot);

 private:
  void add_triangle(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c, const float* colour);
  void add_mesh(const DrawMesh& mesh, const SnapshotPose& pose, const Eigen::Vector3f& offset_local_m, const float* colour);
  void add_soft_body(const RenderSnapshot& snapshot);
  void add_ground();
  void add_patches(const RenderSnapshot& snapshot);
  void add_force_arrow(const RenderSnapshot& snapshot);
  void add_text(const std::string& text, float x_px, float y_px, float scale);

  const RenderModel& model_;
  unsigned scene_program_ = 0;
  unsigned overlay_program_ = 0;
  unsigned scene_vao_ = 0, scene_vbo_ = 0;
  unsigned overlay_vao_ = 0, overlay_vbo_ = 0;
  int scene_mvp_location_ = -1, scene_light_location_ = -1, scene_alpha_location_ = -1;
  int overlay_viewport_location_ = -1, overlay_colour_location_ = -1;
  std::vector<float> scene_vertices_;    // x y z | nx ny nz | r g b per vertex
  std::vector<float> overlay_vertices_;  // x y (pixels) per vertex
  std::vector<Eigen::Vector3f> soft_normals_;
  std::vector<Eigen::Vector3f> soft_positions_;
  std::vector<RigidMotion> soft_motions_;  // per soft body, this frame
};

}  // namespace fissure::viewer
