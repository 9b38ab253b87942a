// The picture's model (once, after settling) and the per-step capture of the host's state.
// The only viewer file that reads Bullet: the soft body's triangles, once, at model time.
#include "fissure/viewer/render_snapshot.hpp"

#include <algorithm>
#include <cstddef>
#include <stdexcept>
#include <string>

#include <Eigen/SVD>

#include <BulletSoftBody/btSoftBody.h>

#include "fissure/host_sim/soft_world.hpp"

namespace fissure::viewer {
namespace {

// The subject's displacement that reads fully red: 0.12 of its smallest half-size (see
// RenderModel::deformation_full_scale_m).
constexpr float kDeformationFullScaleFraction = 0.12F;
// Force arrow: 20 N (the top of the paper scenes' forces) is drawn one subject radius long.
constexpr float kForceArrowRadiusFractionPerNewton = 0.05F;

DrawMesh box_mesh(const Eigen::Vector3f& half_m, const Eigen::Vector3f& centre_m) {
  DrawMesh mesh;
  for (int i = 0; i < 8; ++i) {
    mesh.vertices.emplace_back(centre_m + Eigen::Vector3f((i & 1) ? half_m.x() : -half_m.x(), (i & 2) ? half_m.y() : -half_m.y(),
                                                          (i & 4) ? half_m.z() : -half_m.z()));
  }
  // Two CCW (outward) triangles per face; corner index bits: x = 1, y = 2, z = 4.
  mesh.triangles = {{0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5},   // −x, +x
                    {0, 1, 5}, {0, 5, 4}, {2, 6, 7}, {2, 7, 3},   // −y, +y
                    {0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}};  // −z, +z
  return mesh;
}

Eigen::Vector3f to_f(const Vec3& v) { return Eigen::Vector3f(static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2])); }

SnapshotPose to_snapshot(const host::ToolPose& pose) noexcept {
  SnapshotPose out;
  for (int i = 0; i < 3; ++i) out.position_world_m[static_cast<std::size_t>(i)] = static_cast<float>(pose.position_world_m[i]);
  out.orientation_wxyz = {static_cast<float>(pose.orientation_world.w()), static_cast<float>(pose.orientation_world.x()),
                          static_cast<float>(pose.orientation_world.y()), static_cast<float>(pose.orientation_world.z())};
  return out;
}

}  // namespace

RenderModel make_render_model(host::HostSimulation& sim) {
  const host::SceneDescription& scene = sim.scene();
  const std::vector<Eigen::Vector3d>& nodes = sim.node_positions_world_m();
  if (static_cast<int>(nodes.size()) > kMaxSnapshotNodes) {
    throw std::invalid_argument("scene '" + scene.name + "': the soft body has " + std::to_string(nodes.size()) +
                                " nodes, the view holds at most " + std::to_string(kMaxSnapshotNodes));
  }
  RenderModel model;
  model.scene_name = scene.name;
  model.soft_triangles = sim.soft_faces();
  model.soft_body_first_node.clear();
  for (int b = 0; b <= sim.soft_body_count(); ++b) model.soft_body_first_node.push_back(sim.first_node(b));
  model.soft_rest_world_m.reserve(nodes.size());
  for (const Eigen::Vector3d& p : nodes) model.soft_rest_world_m.push_back(p.cast<float>());

  const host::ToolPartGeometry geometry = host::tool_part_geometry(scene);
  if (scene.tool.kind == host::ToolKind::kConvexMesh) {
    for (const Vec3& v : scene.tool.mesh_vertices_tool_m) model.part_mesh.vertices.push_back(to_f(v));
    model.part_mesh.triangles = scene.tool.mesh_triangles;
  } else {
    model.part_mesh = box_mesh(geometry.box_half_extents_m.cast<float>(), Eigen::Vector3f::Zero());
  }
  if (scene.tool.kind == host::ToolKind::kClamp) {
    model.has_handle = true;
    model.handle_mesh = box_mesh(0.5F * to_f(scene.tool.clamp.handle_size_m), to_f(scene.tool.clamp.handle_offset_tool_m));
  }
  model.ground_top_y_m = static_cast<float>(scene.ground.top_height_m);
  model.ground_half_extents_m = {static_cast<float>(scene.ground.half_extents_m[0]), static_cast<float>(scene.ground.half_extents_m[2])};

  const Eigen::AlignedBox3d bounds = sim.soft_bounds_world_m();
  model.focus_world_m = bounds.center().cast<float>();
  const Eigen::Vector3f half = (0.5 * bounds.sizes()).cast<float>();
  model.focus_radius_m = std::max(half.maxCoeff(), 1e-3F);
  model.deformation_full_scale_m = kDeformationFullScaleFraction * std::max(half.minCoeff(), 1e-3F);
  model.force_arrow_m_per_n = kForceArrowRadiusFractionPerNewton * model.focus_radius_m;
  return model;
}

RigidMotion fit_rigid_motion(const RenderModel& model, const Eigen::Vector3f* nodes_world_m, std::size_t count) noexcept {
  return fit_rigid_motion(model, nodes_world_m, 0, count);
}

RigidMotion fit_rigid_motion(const RenderModel& model, const Eigen::Vector3f* nodes_world_m, std::size_t first, std::size_t end) noexcept {
  RigidMotion motion;
  end = std::min(end, model.soft_rest_world_m.size());
  if (end < first + 3) return motion;
  const std::size_t n = end - first;
  Eigen::Vector3d rest_centre = Eigen::Vector3d::Zero(), centre = Eigen::Vector3d::Zero();
  for (std::size_t i = first; i < end; ++i) {
    rest_centre += model.soft_rest_world_m[i].cast<double>();
    centre += nodes_world_m[i].cast<double>();
  }
  rest_centre /= static_cast<double>(n);
  centre /= static_cast<double>(n);
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (std::size_t i = first; i < end; ++i) {
    covariance += (nodes_world_m[i].cast<double>() - centre) * (model.soft_rest_world_m[i].cast<double>() - rest_centre).transpose();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance, Eigen::ComputeFullU | Eigen::ComputeFullV);
  // The nearest proper rotation: a reflection would turn the body inside out.
  Eigen::Matrix3d sign = Eigen::Matrix3d::Identity();
  sign(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  const Eigen::Matrix3d rotation = svd.matrixU() * sign * svd.matrixV().transpose();
  motion.rotation = rotation.cast<float>();
  motion.translation = (centre - rotation * rest_centre).cast<float>();
  return motion;
}

float deformation_fraction(const RenderModel& model, const RigidMotion& motion, std::size_t node, const Eigen::Vector3f& p_world_m) noexcept {
  if (node >= model.soft_rest_world_m.size()) return 0.0F;
  const Eigen::Vector3f carried = motion.rotation * model.soft_rest_world_m[node] + motion.translation;
  return std::clamp((p_world_m - carried).norm() / model.deformation_full_scale_m, 0.0F, 1.0F);
}

void capture_snapshot(const host::HostSimulation& sim, RenderSnapshot& out) noexcept {
  const std::vector<Eigen::Vector3d>& nodes = sim.node_positions_world_m();
  const int count = std::min(static_cast<int>(nodes.size()), kMaxSnapshotNodes);
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d& p = nodes[static_cast<std::size_t>(i)];
    out.nodes_world_m[static_cast<std::size_t>(i)] = {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())};
  }
  out.node_count = count;
  const host::HostStepResult& last = sim.last();
  out.tool_pose = to_snapshot(sim.tool_pose());
  std::array<host::ToolPose, host::kMaxToolParts> parts{};
  host::tool_part_poses(sim.scene(), sim.tool_pose(), last.jaw_gap_m, parts);
  out.part_count = std::clamp(last.part_count, 0, kMaxSnapshotParts);
  for (int p = 0; p < out.part_count; ++p) out.part_poses[static_cast<std::size_t>(p)] = to_snapshot(parts[static_cast<std::size_t>(p)]);
  const Eigen::Vector3d& f = last.force_on_tool_world_n;
  out.force_on_tool_world_n = {static_cast<float>(f.x()), static_cast<float>(f.y()), static_cast<float>(f.z())};
  out.overlay.time_s = sim.time_s();
  out.overlay.force_n = f.norm();
  out.overlay.crossed_nodes = last.crossing.crossed_nodes;
  out.overlay.contacts = last.contact_count;
  out.overlay.host_step_ms = last.times.total_s * 1e3;
  out.overlay.method = sim.method();
  out.sequence += 1;
}

void capture_patches(const ContactProxy& proxy, RenderSnapshot& out) noexcept {
  const int count = std::min(static_cast<int>(proxy.patch_count), static_cast<int>(kMaxContactPatches));
  for (int i = 0; i < count; ++i) {
    const ContactPatch& patch = proxy.patches[static_cast<std::size_t>(i)];
    SnapshotPatch& drawn = out.patches[static_cast<std::size_t>(i)];
    for (std::size_t k = 0; k < 3; ++k) {
      drawn.point_world_m[k] = static_cast<float>(patch.plane_point_world_m[k]);
      drawn.normal_world[k] = static_cast<float>(patch.normal_world[k]);
    }
  }
  out.patch_count = count;
}

}  // namespace fissure::viewer
