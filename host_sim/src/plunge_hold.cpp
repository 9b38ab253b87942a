#include "fissure/host_sim/plunge_hold.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <variant>

#include "fissure/host_sim/host_simulation.hpp"
#include "fissure/host_sim/scene_loader.hpp"
#include "fissure/host_sim/soft_body_builder.hpp"
#include "fissure/host_sim/tet_mesh_checks.hpp"

namespace fissure::host {

const std::array<PlungeTool, 4>& plunge_tools() {
  static const std::array<PlungeTool, 4> tools = {{
      {"plate_4mm", ToolKind::kBox, {0.04, 0.004, 0.04}, {0, 0, 0}, 0.002},
      {"plate_1mm", ToolKind::kBox, {0.04, 0.001, 0.04}, {0, 0, 0}, 0.0005},
      {"blade_edge_first", ToolKind::kBox, {0.04, 0.001, 0.04}, {0, 0, -90}, 0.02},
      {"convex_spatula", ToolKind::kConvexMesh, {0, 0, 0}, {0, 0, 0}, 0.001},
  }};
  return tools;
}

SceneDescription plunge_scene(const PlungeTool& tool, int icosphere_faces) {
  if (icosphere_faces != 0 && !is_icosphere_face_count(icosphere_faces))
    throw std::invalid_argument("icosphere_faces must be 0 (the paper's 128-face shell) or an icosphere's 20·4^k faces (20 … 20480; the "
                                "sweep's fine ball has 1280), got " + std::to_string(icosphere_faces));
  SceneDescription s = load_scene(resolve_scene_path("spatula-sphere"));
  if (tool.kind == ToolKind::kConvexMesh) {
    s.tool = load_scene(resolve_scene_path("convex-spatula-sphere")).tool;
  } else {
    s.tool.kind = ToolKind::kBox;
    s.tool.box_size_m = tool.box_size_m;
  }
  s.trajectory.start.orientation_world = quat_from_rpy_deg(tool.orientation_rpy_deg);
  s.soft_bodies.front().shape_matching_ratio = kPlungeShapeMatchingRatio;
  if (icosphere_faces > 0) {
    SoftSphere sphere = std::get<SoftSphere>(s.soft_bodies.front().shape);
    sphere.faces_count = icosphere_faces;
    sphere.tessellation = SphereTessellation::kIcosphere;
    s.soft_bodies.front().shape = sphere;
  }
  return s;
}

SceneDescription plunge_cell_scene(const PlungeTool& tool, int icosphere_faces, ContactResponse response, bool tool_friction) {
  SceneDescription scene = plunge_scene(tool, icosphere_faces);
  if (response == ContactResponse::kInSolver) return in_solver_plunge_scene(scene, tool_friction);
  scene.simulation.contact_response = response;
  return scene;
}

namespace {

// The plunge ball's bed: every node within kPlungeBedTop_m of the ground tied to it.
SoftAnchorBox plunge_bed(const GroundDescription& ground) {
  SoftAnchorBox bed;
  bed.min_world_m = {-1.0, ground.top_height_m - 1.0, -1.0};
  bed.max_world_m = {1.0, ground.top_height_m + kPlungeBedTop_m, 1.0};
  return bed;
}

// The in-solver cells' tool friction, or none.
void set_plunge_friction(ToolDescription& tool, bool friction) {
  tool.friction_static_ratio = friction ? kPlungeFrictionStaticRatio : 0.0;
  tool.friction_kinetic_ratio = friction ? kPlungeFrictionKineticRatio : 0.0;
}

}  // namespace

SceneDescription volumetric_plunge_scene(SceneDescription scene, int icosphere_faces, ContactResponse response, bool tool_friction) {
  if (icosphere_faces != 0 && icosphere_faces != 1280)
    throw std::invalid_argument("the volumetric sweep ball is the 128-face shell's (icosphere_faces 0) or the 1280-face icosphere's, got " +
                                std::to_string(icosphere_faces));
  const std::string file = icosphere_faces == 0 ? "plunge-ball-128.1.node" : "plunge-ball-1280.1.node";
  const std::filesystem::path path = find_scenes_dir() / "meshes" / file;
  VolumeMesh volume = read_soft_body_tet_mesh(path.string());
  SoftBodyDescription soft;
  SoftMesh mesh;
  mesh.mesh_path = path.lexically_normal().string();
  mesh.vertices_world_m = std::move(volume.vertices_m);
  mesh.triangles = std::move(volume.boundary_triangles);
  mesh.tetrahedra = std::move(volume.tetrahedra);
  soft.model = SoftBodyModel::kFem;
  soft.fem.model = FemModel::kCorotatedSmoothed;
  soft.fem.youngs_modulus_pa = kPlungeFemYoungsModulus_pa;
  soft.fem.poisson_ratio = kTissuePoissonRatio;
  soft.fem.density_kg_per_m3 = kTissueDensityKgPerM3;
  soft.fem.mass_damping_per_s = kPlungeFemMassDamping_per_s;
  soft.mass_kg = soft.fem.density_kg_per_m3 * tet_mesh_volume_m3(TetMesh{"", mesh.vertices_world_m, mesh.tetrahedra, {}, 0});
  soft.shape = std::move(mesh);
  const SoftBodyDescription& shell = scene.soft_bodies.front();
  soft.friction_ratio = shell.friction_ratio;
  soft.collision_margin_m = shell.collision_margin_m;
  soft.anchors.push_back(plunge_bed(scene.ground));
  scene.soft_bodies = {std::move(soft)};
  scene.simulation.contact_response = response;
  set_plunge_friction(scene.tool, response == ContactResponse::kInSolver && tool_friction);
  return scene;
}

SceneDescription in_solver_plunge_scene(SceneDescription scene, bool tool_friction) {
  scene.simulation.contact_response = ContactResponse::kInSolver;
  set_plunge_friction(scene.tool, tool_friction);
  scene.soft_bodies.front().anchors.push_back(plunge_bed(scene.ground));
  return scene;
}

HoldForceStats hold_force_stats(const std::vector<double>& force_n) {
  HoldForceStats stats;
  if (force_n.empty()) return stats;
  const auto n = static_cast<double>(force_n.size());
  for (double f : force_n) stats.mean_n += f;
  stats.mean_n /= n;
  stats.in_contact = stats.mean_n > 0.0;
  if (!stats.in_contact || force_n.size() < 3) return stats;
  // Least-squares line through |F| against the sample index; residual std with n − 2 dof.
  const double i_mean = 0.5 * (n - 1.0);
  double sii = 0.0, siy = 0.0, sum_sq = 0.0;
  for (std::size_t i = 0; i < force_n.size(); ++i) {
    const double di = static_cast<double>(i) - i_mean;
    sii += di * di;
    siy += di * (force_n[i] - stats.mean_n);
    sum_sq += (force_n[i] - stats.mean_n) * (force_n[i] - stats.mean_n);
  }
  const double slope_per_sample = siy / sii;
  double residual_sq = 0.0;
  for (std::size_t i = 0; i < force_n.size(); ++i) {
    const double r = force_n[i] - stats.mean_n - slope_per_sample * (static_cast<double>(i) - i_mean);
    residual_sq += r * r;
  }
  stats.jitter = std::sqrt(residual_sq / (n - 2.0)) / stats.mean_n;
  stats.drift = slope_per_sample * n / stats.mean_n;
  stats.std_over_mean = std::sqrt(sum_sq / (n - 1.0)) / stats.mean_n;
  double change_mean = 0.0, change_sq = 0.0;
  for (std::size_t i = 1; i < force_n.size(); ++i) change_mean += force_n[i] - force_n[i - 1];
  change_mean /= n - 1.0;
  for (std::size_t i = 1; i < force_n.size(); ++i) {
    const double d = force_n[i] - force_n[i - 1] - change_mean;
    change_sq += d * d;
  }
  stats.step_noise = std::sqrt(change_sq / (n - 2.0)) / std::sqrt(2.0) / stats.mean_n;
  return stats;
}

PlungeStart settle_and_place_above(HostSimulation& sim, const SceneDescription& scene, double leading_half_m) {
  // Start well clear, settle, then find the soft surface's top.
  PlungeStart start;
  start.pose = to_tool_pose(scene.trajectory.start);
  start.pose.position_world_m.y() = 0.2;
  (void)sim.step(start.pose);
  sim.settle(kPlungeSettle_s);
  const double top_m = sim.soft_bounds_world_m().max().y();
  start.pose.position_world_m.y() = top_m + kPlungeStartClearance_m + leading_half_m;
  start.end_y_m = top_m - kPlungeDepth_m + leading_half_m;
  // Put the tool at the start pose first (out of contact): plunging straight from the settle
  // pose (0.2 m) would make the first plunge step a ~0.12 m jump, well above the nominal speed.
  (void)sim.step(start.pose);
  return start;
}

PlungeHoldResult run_plunge_hold(const SceneDescription& scene, SceneCollisionMethod method, double speed_m_s, double leading_half_m,
                                 double hold_s, bool count_cut_triangles, const HoldStepObserver& on_hold_step) {
  HostSimulation sim(scene, method);
  const double dt = scene.simulation.time_step_s;
  const PlungeStart start = settle_and_place_above(sim, scene, leading_half_m);
  ToolPose pose = start.pose;
  const double end_y = start.end_y_m;
  PlungeHoldResult result;
  auto record = [&](const HostStepResult& r) {
    result.crossed_nodes = std::max(result.crossed_nodes, r.crossing.crossed_nodes);
    result.wrong_side_nodes = std::max(result.wrong_side_nodes, r.crossing.wrong_side_nodes);
    result.inside_nodes = std::max(result.inside_nodes, r.crossing.inside_nodes);
    result.max_penetration_m = std::max(result.max_penetration_m, r.crossing.max_penetration_m);
    result.step_s.push_back(r.times.total_s);
  };
  auto ball_centre = [&sim] {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& p : sim.node_positions_world_m()) sum += p;
    sum /= static_cast<double>(std::max<std::size_t>(1, sim.node_positions_world_m().size()));
    return Vec3{sum.x(), sum.y(), sum.z()};
  };
  auto contacted_triangles = [](const HostStepResult& r) {
    int count = 0;
    for (int p = 0; p < r.part_count; ++p) count += r.part_results[static_cast<std::size_t>(p)].contacted_triangles;
    return count;
  };
  auto body_finite = [&sim] {
    for (const Eigen::Vector3d& p : sim.node_positions_world_m()) {
      if (!p.allFinite()) return false;
    }
    return true;
  };
  auto stop_non_finite = [&] {
    result.non_finite = true;
    result.crossed_nodes = result.inside_nodes = static_cast<int>(sim.node_positions_world_m().size());
    result.hold_force_n.clear();
    result.hold = hold_force_stats(result.hold_force_n);
    return result;
  };
  while (pose.position_world_m.y() > end_y) {
    pose.position_world_m.y() = std::max(end_y, pose.position_world_m.y() - speed_m_s * dt);
    record(sim.step(pose));
    if (!body_finite()) return stop_non_finite();
  }
  const long settle_steps = std::lround(kHoldSettle_s / dt);
  const long hold_steps = std::lround(hold_s / dt);
  result.hold_force_n.reserve(static_cast<std::size_t>(hold_steps));
  int previous_triangles = -1;
  if (count_cut_triangles) result.hold_max_cut_triangles = result.hold_steps_with_cut_triangles = 0;
  for (long i = 0; i < settle_steps + hold_steps; ++i) {
    const HostStepResult& r = sim.step(pose);
    record(r);
    if (!body_finite()) return stop_non_finite();
    if (i < settle_steps) continue;
    result.hold_force_n.push_back(r.force_on_tool_world_n.norm());
    Eigen::Vector3d friction = Eigen::Vector3d::Zero();
    for (int part = 0; part < r.part_count; ++part) friction += r.part_results[static_cast<std::size_t>(part)].friction_force_on_tool_world_n;
    result.hold_friction_mean_n += friction.norm() / static_cast<double>(hold_steps);
    const int triangles = contacted_triangles(r);
    if (i == settle_steps) result.ball_centre_hold_start_world_m = ball_centre();
    else if (triangles != previous_triangles) ++result.hold_contact_set_changes;
    previous_triangles = triangles;
    if (count_cut_triangles) {
      const int cut = sim.triangles_cut_by_tool(kInsideToleranceM);
      result.hold_max_cut_triangles = std::max(result.hold_max_cut_triangles, cut);
      if (cut > 0) ++result.hold_steps_with_cut_triangles;
      if (on_hold_step) on_hold_step(sim, cut);
    }
  }
  result.ball_centre_hold_end_world_m = ball_centre();
  result.hold = hold_force_stats(result.hold_force_n);
  return result;
}

}  // namespace fissure::host
