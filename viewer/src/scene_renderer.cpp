// OpenGL 3.3 core drawing of one RenderSnapshot (see scene_renderer.hpp).
#include "fissure/viewer/scene_renderer.hpp"

#include <GL/glcorearb.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

#include "fissure/viewer/bitmap_font.hpp"

namespace fissure::viewer {
namespace {

constexpr int kFloatsPerSceneVertex = 9;
// Vertices reserved up front: the vessel (768 faces) + ground + tool + arrow fit with room.
constexpr std::size_t kReservedSceneVertices = 3 * 16384;
// Ground: a checkerboard of this many cells each way around the subject, cells half its radius.
constexpr int kGroundCellsEachSide = 12;
// Patch squares: half-size as a fraction of the subject radius, lifted off the plane so they
// are not z-fighting the soft surface.
constexpr float kPatchHalfSizeFraction = 0.12F;
constexpr float kPatchLiftFraction = 0.004F;
// Force arrow: shaft radius and head size as fractions of the subject radius; longest arrow
// drawn = 1.5 subject radii (so a 50 N spike does not leave the picture).
constexpr float kArrowShaftRadiusFraction = 0.025F;
constexpr float kArrowHeadRadiusFraction = 0.07F;
constexpr float kArrowHeadLengthFraction = 0.18F;
constexpr float kArrowMaxLengthFraction = 1.5F;
constexpr int kArrowSegments = 12;
// Overlay text: font pixel → 2×2 screen pixels, 8 px margin.
constexpr float kTextScale = 2.0F;
constexpr float kTextMarginPx = 8.0F;

constexpr const char* kSceneVertexShader = R"(#version 330 core
layout(location = 0) in vec3 position_world;
layout(location = 1) in vec3 normal_world;
layout(location = 2) in vec3 colour;
uniform mat4 mvp;
out vec3 v_normal;
out vec3 v_colour;
void main() {
  gl_Position = mvp * vec4(position_world, 1.0);
  v_normal = normal_world;
  v_colour = colour;
}
)";

// Two-sided Lambert from a light near the camera plus ambient: every face reads, whatever its
// winding (soft triangles flip inside out when a method lets the tool through).
constexpr const char* kSceneFragmentShader = R"(#version 330 core
in vec3 v_normal;
in vec3 v_colour;
uniform vec3 light_dir_world;
uniform float alpha;
out vec4 frag_colour;
void main() {
  vec3 n = normalize(v_normal);
  if (!gl_FrontFacing) n = -n;
  float diffuse = abs(dot(n, light_dir_world));
  frag_colour = vec4(v_colour * (0.35 + 0.65 * diffuse), alpha);
}
)";

constexpr const char* kOverlayVertexShader = R"(#version 330 core
layout(location = 0) in vec2 position_px;
uniform vec2 viewport_px;
void main() {
  gl_Position = vec4(2.0 * position_px.x / viewport_px.x - 1.0, 1.0 - 2.0 * position_px.y / viewport_px.y, 0.0, 1.0);
}
)";

constexpr const char* kOverlayFragmentShader = R"(#version 330 core
uniform vec4 colour;
out vec4 frag_colour;
void main() { frag_colour = colour; }
)";

GLuint compile(GLenum type, const char* source) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok == 0) {
    char log[1024] = {};
    glGetShaderInfoLog(shader, sizeof log, nullptr, log);
    glDeleteShader(shader);
    throw std::runtime_error(std::string("viewer: shader does not compile: ") + log);
  }
  return shader;
}

GLuint link(const char* vertex_source, const char* fragment_source) {
  const GLuint vs = compile(GL_VERTEX_SHADER, vertex_source);
  const GLuint fs = compile(GL_FRAGMENT_SHADER, fragment_source);
  const GLuint program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (ok == 0) {
    char log[1024] = {};
    glGetProgramInfoLog(program, sizeof log, nullptr, log);
    glDeleteProgram(program);
    throw std::runtime_error(std::string("viewer: shader program does not link: ") + log);
  }
  return program;
}

Eigen::Quaternionf to_quaternion(const SnapshotPose& pose) {
  return Eigen::Quaternionf(pose.orientation_wxyz[0], pose.orientation_wxyz[1], pose.orientation_wxyz[2], pose.orientation_wxyz[3]).normalized();
}

Eigen::Vector3f to_vector(const std::array<float, 3>& v) { return Eigen::Vector3f(v[0], v[1], v[2]); }

std::string number_or_dash(double value, const char* format) {
  if (!std::isfinite(value) || value < 0.0) return "-";
  char text[32];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

}  // namespace

SceneRenderer::SceneRenderer(const RenderModel& model) : model_(model) {
  scene_program_ = link(kSceneVertexShader, kSceneFragmentShader);
  overlay_program_ = link(kOverlayVertexShader, kOverlayFragmentShader);
  scene_mvp_location_ = glGetUniformLocation(scene_program_, "mvp");
  scene_light_location_ = glGetUniformLocation(scene_program_, "light_dir_world");
  scene_alpha_location_ = glGetUniformLocation(scene_program_, "alpha");
  overlay_viewport_location_ = glGetUniformLocation(overlay_program_, "viewport_px");
  overlay_colour_location_ = glGetUniformLocation(overlay_program_, "colour");

  glGenVertexArrays(1, &scene_vao_);
  glGenBuffers(1, &scene_vbo_);
  glBindVertexArray(scene_vao_);
  glBindBuffer(GL_ARRAY_BUFFER, scene_vbo_);
  const GLsizei stride = kFloatsPerSceneVertex * sizeof(float);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<const void*>(0));
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<const void*>(3 * sizeof(float)));
  glVertexAttribPointer(2, 3, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<const void*>(6 * sizeof(float)));
  glEnableVertexAttribArray(0);
  glEnableVertexAttribArray(1);
  glEnableVertexAttribArray(2);

  glGenVertexArrays(1, &overlay_vao_);
  glGenBuffers(1, &overlay_vbo_);
  glBindVertexArray(overlay_vao_);
  glBindBuffer(GL_ARRAY_BUFFER, overlay_vbo_);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 2 * sizeof(float), reinterpret_cast<const void*>(0));
  glEnableVertexAttribArray(0);
  glBindVertexArray(0);

  scene_vertices_.reserve(kReservedSceneVertices * kFloatsPerSceneVertex);
  overlay_vertices_.reserve(6 * 4096);
  soft_normals_.resize(model_.soft_rest_world_m.size());
  soft_positions_.resize(model_.soft_rest_world_m.size());
}

SceneRenderer::~SceneRenderer() {
  glDeleteBuffers(1, &scene_vbo_);
  glDeleteBuffers(1, &overlay_vbo_);
  glDeleteVertexArrays(1, &scene_vao_);
  glDeleteVertexArrays(1, &overlay_vao_);
  glDeleteProgram(scene_program_);
  glDeleteProgram(overlay_program_);
}

void SceneRenderer::add_triangle(const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c, const float* colour) {
  const Eigen::Vector3f n = (b - a).cross(c - a).normalized();
  for (const Eigen::Vector3f* p : {&a, &b, &c}) {
    scene_vertices_.insert(scene_vertices_.end(), {p->x(), p->y(), p->z(), n.x(), n.y(), n.z(), colour[0], colour[1], colour[2]});
  }
}

void SceneRenderer::add_mesh(const DrawMesh& mesh, const SnapshotPose& pose, const Eigen::Vector3f& offset_local_m, const float* colour) {
  const Eigen::Quaternionf q = to_quaternion(pose);
  const Eigen::Vector3f t = to_vector(pose.position_world_m);
  for (const auto& tri : mesh.triangles) {
    const auto world = [&](int i) -> Eigen::Vector3f { return q * (mesh.vertices[static_cast<std::size_t>(i)] + offset_local_m) + t; };
    add_triangle(world(tri[0]), world(tri[1]), world(tri[2]), colour);
  }
}

void SceneRenderer::add_soft_body(const RenderSnapshot& snapshot) {
  const int n = std::min(snapshot.node_count, static_cast<int>(soft_positions_.size()));
  for (int i = 0; i < n; ++i) {
    soft_positions_[static_cast<std::size_t>(i)] = to_vector(snapshot.nodes_world_m[static_cast<std::size_t>(i)]);
    soft_normals_[static_cast<std::size_t>(i)].setZero();
  }
  // Smooth shading: area-weighted vertex normals from the current (deformed) triangles.
  for (const auto& tri : model_.soft_triangles) {
    if (tri[0] >= n || tri[1] >= n || tri[2] >= n) continue;
    const Eigen::Vector3f& a = soft_positions_[static_cast<std::size_t>(tri[0])];
    const Eigen::Vector3f face = (soft_positions_[static_cast<std::size_t>(tri[1])] - a).cross(soft_positions_[static_cast<std::size_t>(tri[2])] - a);
    for (int k = 0; k < 3; ++k) soft_normals_[static_cast<std::size_t>(tri[static_cast<std::size_t>(k)])] += face;
  }
  // Each body's rigid motion; a triangle's three nodes belong to one body.
  const std::size_t bodies = model_.soft_body_first_node.size() - 1;
  soft_motions_.resize(bodies);
  for (std::size_t b = 0; b < bodies; ++b) {
    soft_motions_[b] = fit_rigid_motion(model_, soft_positions_.data(), static_cast<std::size_t>(model_.soft_body_first_node[b]),
                                        static_cast<std::size_t>(std::min(n, model_.soft_body_first_node[b + 1])));
  }
  for (const auto& tri : model_.soft_triangles) {
    if (tri[0] >= n || tri[1] >= n || tri[2] >= n) continue;
    const auto body = static_cast<std::size_t>(
        std::upper_bound(model_.soft_body_first_node.begin() + 1, model_.soft_body_first_node.end() - 1, tri[0]) - (model_.soft_body_first_node.begin() + 1));
    const RigidMotion& motion = soft_motions_[body];
    for (int k = 0; k < 3; ++k) {
      const auto i = static_cast<std::size_t>(tri[static_cast<std::size_t>(k)]);
      const Eigen::Vector3f& p = soft_positions_[i];
      const Eigen::Vector3f normal = soft_normals_[i].normalized();
      const float t = deformation_fraction(model_, motion, i, p);
      float colour[3];
      for (int c = 0; c < 3; ++c) colour[c] = (1.0F - t) * palette::kSoftAtRest[c] + t * palette::kSoftFullyDeformed[c];
      scene_vertices_.insert(scene_vertices_.end(), {p.x(), p.y(), p.z(), normal.x(), normal.y(), normal.z(), colour[0], colour[1], colour[2]});
    }
  }
}

void SceneRenderer::add_ground() {
  const float cell = 0.5F * model_.focus_radius_m;
  const float y = model_.ground_top_y_m;
  const float cx = model_.focus_world_m.x(), cz = model_.focus_world_m.z();
  for (int i = -kGroundCellsEachSide; i < kGroundCellsEachSide; ++i) {
    for (int j = -kGroundCellsEachSide; j < kGroundCellsEachSide; ++j) {
      const float x0 = std::clamp(cx + static_cast<float>(i) * cell, -model_.ground_half_extents_m.x(), model_.ground_half_extents_m.x());
      const float x1 = std::clamp(x0 + cell, -model_.ground_half_extents_m.x(), model_.ground_half_extents_m.x());
      const float z0 = std::clamp(cz + static_cast<float>(j) * cell, -model_.ground_half_extents_m.y(), model_.ground_half_extents_m.y());
      const float z1 = std::clamp(z0 + cell, -model_.ground_half_extents_m.y(), model_.ground_half_extents_m.y());
      if (x1 <= x0 || z1 <= z0) continue;
      const float* colour = ((i + j) & 1) != 0 ? palette::kGroundA : palette::kGroundB;
      add_triangle({x0, y, z0}, {x0, y, z1}, {x1, y, z1}, colour);
      add_triangle({x0, y, z0}, {x1, y, z1}, {x1, y, z0}, colour);
    }
  }
}

void SceneRenderer::add_patches(const RenderSnapshot& snapshot) {
  const float half = kPatchHalfSizeFraction * model_.focus_radius_m;
  const float lift = kPatchLiftFraction * model_.focus_radius_m;
  for (int i = 0; i < snapshot.patch_count && i < static_cast<int>(snapshot.patches.size()); ++i) {
    const SnapshotPatch& patch = snapshot.patches[static_cast<std::size_t>(i)];
    const Eigen::Vector3f n = to_vector(patch.normal_world).normalized();
    if (!n.allFinite()) continue;
    const Eigen::Vector3f u = n.unitOrthogonal() * half;
    const Eigen::Vector3f v = n.cross(u);
    // The patch normal is the force direction on the tool: draw the square on the tool's side.
    const Eigen::Vector3f c = to_vector(patch.point_world_m) + lift * n;
    add_triangle(c - u - v, c + u - v, c + u + v, palette::kPatch);
    add_triangle(c - u - v, c + u + v, c - u + v, palette::kPatch);
  }
}

void SceneRenderer::add_force_arrow(const RenderSnapshot& snapshot) {
  const Eigen::Vector3f force = to_vector(snapshot.force_on_tool_world_n);
  const float magnitude = force.norm();
  if (!(magnitude > 1e-4F)) return;
  const float length = std::min(magnitude * model_.force_arrow_m_per_n, kArrowMaxLengthFraction * model_.focus_radius_m);
  const Eigen::Vector3f axis = force / magnitude;
  const Eigen::Vector3f u = axis.unitOrthogonal(), v = axis.cross(u);
  const Eigen::Vector3f base = to_vector(snapshot.tool_pose.position_world_m);
  const float shaft_r = kArrowShaftRadiusFraction * model_.focus_radius_m;
  const float head_r = kArrowHeadRadiusFraction * model_.focus_radius_m;
  const float head_len = std::min(kArrowHeadLengthFraction * model_.focus_radius_m, 0.5F * length);
  const Eigen::Vector3f shaft_end = base + (length - head_len) * axis, tip = base + length * axis;
  constexpr float kTwoPi = 6.28318530718F;
  for (int s = 0; s < kArrowSegments; ++s) {
    const float a0 = kTwoPi * static_cast<float>(s) / kArrowSegments, a1 = kTwoPi * static_cast<float>(s + 1) / kArrowSegments;
    const Eigen::Vector3f r0 = std::cos(a0) * u + std::sin(a0) * v, r1 = std::cos(a1) * u + std::sin(a1) * v;
    add_triangle(base + shaft_r * r0, base + shaft_r * r1, shaft_end + shaft_r * r1, palette::kForceArrow);
    add_triangle(base + shaft_r * r0, shaft_end + shaft_r * r1, shaft_end + shaft_r * r0, palette::kForceArrow);
    add_triangle(shaft_end + head_r * r0, shaft_end + head_r * r1, tip, palette::kForceArrow);
    add_triangle(shaft_end + head_r * r1, shaft_end + head_r * r0, shaft_end, palette::kForceArrow);
  }
}

void SceneRenderer::add_text(const std::string& text, float x_px, float y_px, float scale) {
  float x = x_px;
  for (char ch : text) {
    const auto& rows = glyph_rows(ch);
    for (int row = 0; row < kGlyphHeightPx; ++row) {
      for (int col = 0; col < kGlyphWidthPx; ++col) {
        if ((rows[static_cast<std::size_t>(row)] & (0x10 >> col)) == 0) continue;
        const float x0 = x + static_cast<float>(col) * scale, y0 = y_px + static_cast<float>(row) * scale;
        const float x1 = x0 + scale, y1 = y0 + scale;
        overlay_vertices_.insert(overlay_vertices_.end(), {x0, y0, x1, y0, x1, y1, x0, y0, x1, y1, x0, y1});
      }
    }
    x += static_cast<float>(kGlyphAdvancePx) * scale;
  }
}

std::vector<std::string> SceneRenderer::overlay_lines(const RenderModel& model, const RenderSnapshot& snapshot) {
  const OverlayNumbers& o = snapshot.overlay;
  char line1[160], line2[160], line3[160];
  std::snprintf(line1, sizeof line1, "%s | %s | T %.3f S", model.scene_name.c_str(), host::to_string(o.method), o.time_s);
  std::snprintf(line2, sizeof line2, "TICK %s HZ | F %.2f N | PROXY AGE %s MS | OVERRUNS %s", number_or_dash(o.tick_rate_hz, "%.0f").c_str(),
                o.force_n, number_or_dash(o.proxy_age_ms, "%.2f").c_str(),
                o.overruns < 0 ? "-" : std::to_string(o.overruns).c_str());
  std::snprintf(line3, sizeof line3, "CROSSED %d | CONTACTS %d | PATCHES %d | STEP %.2f MS", o.crossed_nodes, o.contacts, snapshot.patch_count,
                o.host_step_ms);
  char line4[96];
  std::snprintf(line4, sizeof line4, "COLOUR: DEFORMATION (RIGID MOTION TAKEN OUT) 0 (BLUE) - %.1f MM (RED)", model.deformation_full_scale_m * 1e3);
  return {line1, line2, line3, line4};
}

void SceneRenderer::draw(const RenderSnapshot& snapshot, const OrbitCamera& camera, int width_px, int height_px, const std::string& status) {
  scene_vertices_.clear();
  add_ground();
  add_soft_body(snapshot);
  for (int p = 0; p < snapshot.part_count; ++p) {
    add_mesh(model_.part_mesh, snapshot.part_poses[static_cast<std::size_t>(p)], Eigen::Vector3f::Zero(), palette::kTool);
  }
  if (model_.has_handle) add_mesh(model_.handle_mesh, snapshot.tool_pose, Eigen::Vector3f::Zero(), palette::kHandle);
  add_force_arrow(snapshot);
  const std::size_t opaque_floats = scene_vertices_.size();
  add_patches(snapshot);

  glViewport(0, 0, width_px, height_px);
  glClearColor(palette::kBackground[0], palette::kBackground[1], palette::kBackground[2], 1.0F);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glUseProgram(scene_program_);
  const Eigen::Matrix4f mvp = camera.projection(width_px, height_px) * camera.view();
  glUniformMatrix4fv(scene_mvp_location_, 1, GL_FALSE, mvp.data());  // Eigen is column-major, as GL wants
  // Light from above and from the camera's side, so faces towards the viewer are lit.
  const Eigen::Vector3f light = ((camera.eye_world_m() - camera.target_world_m).normalized() + Eigen::Vector3f(0.0F, 1.0F, 0.0F)).normalized();
  glUniform3f(scene_light_location_, light.x(), light.y(), light.z());
  glBindVertexArray(scene_vao_);
  glBindBuffer(GL_ARRAY_BUFFER, scene_vbo_);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(scene_vertices_.size() * sizeof(float)), scene_vertices_.data(), GL_STREAM_DRAW);
  glUniform1f(scene_alpha_location_, 1.0F);
  glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(opaque_floats / kFloatsPerSceneVertex));
  // Patches lie on the soft surface under the tool: draw them see-through, over everything.
  glDisable(GL_DEPTH_TEST);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glUniform1f(scene_alpha_location_, 0.6F);
  glDrawArrays(GL_TRIANGLES, static_cast<GLint>(opaque_floats / kFloatsPerSceneVertex),
               static_cast<GLsizei>((scene_vertices_.size() - opaque_floats) / kFloatsPerSceneVertex));

  // Overlay: a translucent box, then the text.
  std::vector<std::string> lines = overlay_lines(model_, snapshot);
  if (!status.empty()) lines.push_back(status);
  std::size_t longest = 0;
  for (const auto& l : lines) longest = std::max(longest, l.size());
  overlay_vertices_.clear();
  const float box_w = 2.0F * kTextMarginPx + static_cast<float>(longest * kGlyphAdvancePx) * kTextScale;
  const float box_h = 2.0F * kTextMarginPx + static_cast<float>(lines.size() * kLineAdvancePx) * kTextScale;
  overlay_vertices_.insert(overlay_vertices_.end(), {0.0F, 0.0F, box_w, 0.0F, box_w, box_h, 0.0F, 0.0F, box_w, box_h, 0.0F, box_h});
  for (std::size_t i = 0; i < lines.size(); ++i) {
    add_text(lines[i], kTextMarginPx, kTextMarginPx + static_cast<float>(i * kLineAdvancePx) * kTextScale, kTextScale);
  }
  glDisable(GL_DEPTH_TEST);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glUseProgram(overlay_program_);
  glUniform2f(overlay_viewport_location_, static_cast<float>(width_px), static_cast<float>(height_px));
  glBindVertexArray(overlay_vao_);
  glBindBuffer(GL_ARRAY_BUFFER, overlay_vbo_);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(overlay_vertices_.size() * sizeof(float)), overlay_vertices_.data(), GL_STREAM_DRAW);
  glUniform4f(overlay_colour_location_, 0.0F, 0.0F, 0.0F, 0.55F);
  glDrawArrays(GL_TRIANGLES, 0, 6);
  glUniform4f(overlay_colour_location_, 0.95F, 0.95F, 0.95F, 1.0F);
  glDrawArrays(GL_TRIANGLES, 6, static_cast<GLsizei>(overlay_vertices_.size() / 2) - 6);
  glBindVertexArray(0);
  glDisable(GL_BLEND);
}

}  // namespace fissure::viewer
