// Scene file → SceneDescription, with strict validation (every error names file, line and
// field). Keys carry their unit in the name; a key whose stem matches a known field but
// whose unit suffix does not is a "wrong unit", anything else unexpected is "unknown key".
#include "fissure/host_sim/scene_loader.hpp"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <utility>

#include <Eigen/Geometry>
#include <tiny_obj_loader.h>

#include <toml++/toml.h>

#include "fissure/config/session_tables.hpp"
#include "fissure/config/table_reader.hpp"

#include "fissure/host_sim/soft_bending_links.hpp"
#include "fissure/host_sim/soft_body_builder.hpp"
#include "fissure/host_sim/tet_mesh_checks.hpp"
#include "fissure/host_sim/tet_mesh_file.hpp"
#include "fissure/host_sim/tool_mesh_io.hpp"

namespace fissure::host {

const char* to_string(SceneCollisionMethod method) noexcept {
  switch (method) {
    case SceneCollisionMethod::kPaired: return "paired";
    case SceneCollisionMethod::kRay: return "ray";
    case SceneCollisionMethod::kBullet: return "bullet";
  }
  return "?";
}

std::optional<SceneCollisionMethod> parse_collision_method(std::string_view name) noexcept {
  for (const SceneCollisionMethod method : kCollisionMethods) {
    if (name == to_string(method)) return method;
  }
  return std::nullopt;
}

const char* to_string(ContactResponse response) noexcept {
  switch (response) {
    case ContactResponse::kAfterStep: return "after_step";
    case ContactResponse::kInSolver: return "in_solver";
  }
  return "?";
}

std::optional<ContactResponse> parse_contact_response(std::string_view name) noexcept {
  for (const ContactResponse response : {ContactResponse::kAfterStep, ContactResponse::kInSolver}) {
    if (name == to_string(response)) return response;
  }
  return std::nullopt;
}

namespace {

using config::child_path;
using config::line_of;
using config::read_device_mapping;
using config::read_hand;
using config::TableReader;

/// The longest host step a scene may ask for [s]: the largest measured at which every shipped
/// scene's soft body settles onto the ground and runs its session without turning inside out
/// (at 0.01 s the vessel and the organ lobe turn inside out, at 0.02 s nearly every body does, at
/// 0.06 s the ball falls through the ground; docs/decisions.md, issue 25). The after-settling
/// checks (session/scene_plausibility.hpp) stay as a second line for a scene this does not cover.
constexpr double kMaxTimeStep_s = 0.005;

void read_simulation(TableReader& t, SimulationDescription& sim) {
  sim.time_step_s = t.in_range("time_step", "s", 1e-6, kMaxTimeStep_s);
  sim.substeps_count = t.count("substeps", 1, 1000);
  sim.gravity_world_m_per_s2 = t.vec3("gravity_world", "m_per_s2");
  std::vector<std::pair<std::string, SceneCollisionMethod>> methods;
  for (const SceneCollisionMethod method : kCollisionMethods) methods.emplace_back(to_string(method), method);
  sim.collision_method = t.choice<SceneCollisionMethod>("collision_method", methods);
  sim.contact_response = t.choice<ContactResponse>(
      "contact_response", {{to_string(ContactResponse::kAfterStep), ContactResponse::kAfterStep}, {to_string(ContactResponse::kInSolver), ContactResponse::kInSolver}},
      ContactResponse::kAfterStep);
  t.finish();
}

void read_ground(TableReader& t, GroundDescription& ground) {
  ground.top_height_m = t.number("top_height", "m");
  ground.half_extents_m = t.vec3("half_extents", "m");
  for (double h : ground.half_extents_m) {
    if (!(h > 0.0)) t.fail(t.line_for("half_extents", "m"), "half_extents_m", "every half extent must be > 0");
  }
  ground.friction_ratio = t.in_range("friction", "ratio", 0.0, 10.0);
  t.finish();
}

// [[soft_body.anchor]]: world boxes, read into `soft`; returns each box's table line.
std::vector<int> read_anchors(const std::string& file, TableReader& t, SoftBodyDescription& soft) {
  std::vector<int> lines;
  const toml::array* boxes = t.array_of_tables("anchor");
  if (boxes == nullptr) return lines;
  for (std::size_t i = 0; i < boxes->size(); ++i) {
    const toml::table& table = *boxes->get(i)->as_table();
    TableReader a(file, table, child_path(t, "anchor[" + std::to_string(i) + "]"));
    SoftAnchorBox box;
    box.min_world_m = a.vec3("min_world", "m");
    box.max_world_m = a.vec3("max_world", "m");
    for (std::size_t k = 0; k < 3; ++k) {
      if (box.min_world_m[k] > box.max_world_m[k]) {
        a.fail(a.line_for("max_world", "m"), "max_world_m", "must be >= min_world_m in every axis (axis " + std::to_string(k) + ")");
      }
    }
    a.finish();
    soft.anchors.push_back(box);
    lines.push_back(a.table_line());
  }
  return lines;
}

// What only the built body tells: each anchor box selects at least one node of the rest mesh
// (an empty box is a typo in a coordinate, not a wish for no anchor), and pose matching has a
// pose matrix Bullet can decompose (kPoseMatchingMinNormProduct_m4 says why).
void check_rest_shape(const std::string& file, TableReader& t, const SoftBodyDescription& soft, const std::vector<int>& anchor_lines) {
  if (soft.anchors.empty() && !(soft.shape_matching_ratio > 0.0)) return;
  const SoftBodyRest rest = soft_body_rest(soft);
  for (std::size_t i = 0; i < soft.anchors.size(); ++i) {
    if (!nodes_in_anchor_box(rest.nodes_world_m, soft.anchors[i]).empty()) continue;
    Eigen::AlignedBox3d bounds;
    for (const Vec3& v : rest.nodes_world_m) bounds.extend(Eigen::Vector3d(v[0], v[1], v[2]));
    std::ostringstream msg;
    msg << "the box selects no soft node (the rest mesh's " << rest.nodes_world_m.size() << " nodes span [" << bounds.min().x() << ", "
        << bounds.min().y() << ", " << bounds.min().z() << "] .. [" << bounds.max().x() << ", " << bounds.max().y() << ", "
        << bounds.max().z() << "] m)";
    throw SceneError(file, anchor_lines[i], child_path(t, "anchor[" + std::to_string(i) + "]"), msg.str());
  }
  if (rest.pose_matrix_norm_product_m4 < kPoseMatchingMinNormProduct_m4) {
    std::ostringstream msg;
    msg << std::fixed << std::setprecision(1) << "this body is too small for Bullet's pose matching: its rest radius of gyration is "
        << rest.pose_radius_of_gyration_m * 1e3 << std::defaultfloat << std::setprecision(3)
        << " mm and its pose matrix's |A|_1*|A|_inf " << rest.pose_matrix_norm_product_m4 << " m^4, below " << kPoseMatchingMinNormProduct_m4
        << " m^4 (the single-precision bound under which Bullet's polar decomposition fails and the body collapses to its centre; a "
           "round body needs a radius of gyration of about 32 mm or more): set shape_matching_ratio = 0 or use a larger body";
    t.fail(t.line_for("shape_matching", "ratio"), "shape_matching_ratio", msg.str());
  }
}

// [soft_body] model = "fem": the SI material (fem_material.hpp's ranges and sources); a
// volumetric body only. The shell's Bullet ratios do not apply and are refused as unknown keys.
void read_fem_material(const std::string& file, TableReader& t, SoftBodyDescription& soft) {
  const auto* mesh = std::get_if<SoftMesh>(&soft.shape);
  if (mesh == nullptr || mesh->tetrahedra.empty()) {
    t.fail(t.line_for("model", ""), "model", "\"fem\" needs a volumetric body: shape = \"mesh\" with a tetrahedral mesh_path (.msh, .vtk, .node)");
  }
  FemMaterial& m = soft.fem;
  m.model = t.choice<FemModel>("elasticity",
                               {{to_string(FemModel::kCorotatedSmoothed), FemModel::kCorotatedSmoothed},
                                {to_string(FemModel::kCorotatedLinear), FemModel::kCorotatedLinear},
                                {to_string(FemModel::kNeoHookean), FemModel::kNeoHookean}},
                               FemModel::kCorotatedSmoothed);
  m.youngs_modulus_pa = t.in_range("youngs_modulus", "pa", kYoungsModulusMinPa, kYoungsModulusMaxPa);
  m.poisson_ratio = t.in_range("poisson", "ratio", kPoissonRatioMin, kPoissonRatioMax);
  m.density_kg_per_m3 = t.in_range("density", "kg_per_m3", kDensityMinKgPerM3, kDensityMaxKgPerM3);
  m.mass_damping_per_s = t.in_range("mass_damping", "per_s", 0.0, kMassDampingMaxPerS, 0.0);
  m.stiffness_damping_s = t.in_range("stiffness_damping", "s", 0.0, kStiffnessDampingMaxS, 0.0);
  soft.friction_ratio = t.in_range("friction", "ratio", 0.0, 1.0);
  soft.collision_margin_m = t.in_range("collision_margin", "m", 0.0, 0.1);
  TetMesh tet{"", mesh->vertices_world_m, mesh->tetrahedra, {}, 0};
  soft.mass_kg = m.density_kg_per_m3 * tet_mesh_volume_m3(tet);
  check_rest_shape(file, t, soft, read_anchors(file, t, soft));
  t.finish();
}

void read_soft_body(const std::string& file, TableReader& t, SoftBodyDescription& soft, const std::filesystem::path& base_dir) {
  const std::string shape = t.text("shape");
  if (shape == "sphere") {
    SoftSphere s;
    s.center_world_m = t.vec3("center_world", "m");
    s.radius_m = t.positive("radius", "m");
    s.tessellation = t.choice<SphereTessellation>(
        "tessellation", {{"bullet_ellipsoid", SphereTessellation::kBulletEllipsoid}, {"icosphere", SphereTessellation::kIcosphere}});
    s.faces_count = t.count("faces", 8, 400000);
    if (s.tessellation == SphereTessellation::kBulletEllipsoid && s.faces_count % 2 != 0) {
      t.fail(t.line_for("faces", "count"), "faces_count", "a bullet_ellipsoid has an even face count (2·res + 2)");
    }
    if (s.tessellation == SphereTessellation::kIcosphere) {
      if (!is_icosphere_face_count(s.faces_count)) t.fail(t.line_for("faces", "count"), "faces_count", "an icosphere has 20·4^k faces (20, 80, 320, 1280, 5120, 20480, …)");
    }
    soft.shape = s;
  } else if (shape == "cylinder") {
    SoftCylinder c;
    c.center_world_m = t.vec3("center_world", "m");
    c.radius_m = t.positive("radius", "m");
    c.length_m = t.positive("length", "m");
    c.segments_count = t.count("segments", 3, 1024);
    c.rings_count = t.count("rings", 2, 4096);
    soft.shape = c;
  } else if (shape == "slab") {
    SoftSlab s;
    s.center_world_m = t.vec3("center_world", "m");
    s.size_m = t.vec3("size", "m");
    for (double e : s.size_m) {
      if (!(e > 0.0)) t.fail(t.line_for("size", "m"), "size_m", "every extent must be > 0");
    }
    s.top_cells_count[0] = t.count("top_cells_x", 1, 1024);
    s.top_cells_count[1] = t.count("top_cells_z", 1, 1024);
    soft.shape = s;
  } else if (shape == "mesh") {
    SoftMesh m;
    const std::string rel = t.text("mesh_path");
    const std::filesystem::path full = std::filesystem::path(rel).is_absolute() ? std::filesystem::path(rel) : base_dir / rel;
    m.mesh_path = full.lexically_normal().string();
    m.offset_world_m = t.vec3("offset_world", "m", Vec3{0.0, 0.0, 0.0});
    try {
      // A tetrahedral file (.msh, .vtk, .node / .ele) makes a volumetric body, a surface file a shell.
      if (is_tet_mesh_path(m.mesh_path)) {
        VolumeMesh mesh = read_soft_body_tet_mesh(m.mesh_path);
        m.vertices_world_m = std::move(mesh.vertices_m);
        m.triangles = std::move(mesh.boundary_triangles);
        m.tetrahedra = std::move(mesh.tetrahedra);
      } else {
        SurfaceMesh mesh = read_soft_body_mesh(m.mesh_path);
        m.vertices_world_m = std::move(mesh.vertices_m);
        m.triangles = std::move(mesh.triangles);
      }
      for (Vec3& v : m.vertices_world_m) {
        for (std::size_t k = 0; k < 3; ++k) v[k] += m.offset_world_m[k];
      }
    } catch (const std::exception& e) {
      t.fail(t.line_for("mesh_path", ""), "mesh_path", std::string("unreadable mesh: ") + e.what());
    }
    soft.shape = std::move(m);
  } else {
    t.fail(t.line_for("shape", ""), "shape", "'" + shape + "' is not one of: sphere, cylinder, slab, mesh");
  }
  soft.model = t.choice<SoftBodyModel>("model", {{"shell", SoftBodyModel::kShell}, {"fem", SoftBodyModel::kFem}}, SoftBodyModel::kShell);
  if (soft.model == SoftBodyModel::kFem) {
    read_fem_material(file, t, soft);
    return;
  }
  soft.mass_kg = t.positive("mass", "kg");
  soft.linear_stiffness_ratio = t.in_range("linear_stiffness", "ratio", 1e-6, 1.0);
  soft.pressure_kpr = t.in_range("pressure", "kpr", 0.0, 1e9);
  soft.volume_conservation_kvc = t.in_range("volume_conservation", "kvc", 0.0, 1e9);
  soft.shape_matching_ratio = t.in_range("shape_matching", "ratio", 0.0, 1.0, 0.0);
  soft.bending_stiffness_ratio = t.in_range("bending_stiffness", "ratio", 0.0, 1.0, 0.0);
  soft.bending_distance_count = t.count("bending_distance", 2, kMaxBendingDistance, 2);
  if (soft.bending_stiffness_ratio == 0.0 && t.find("bending_distance", "count") != nullptr) {
    t.fail(t.line_for("bending_distance", "count"), "bending_distance_count", "has no effect without bending links: set bending_stiffness_ratio > 0 or remove it");
  }
  soft.damping_ratio = t.in_range("damping", "ratio", 0.0, 1.0);
  soft.friction_ratio = t.in_range("friction", "ratio", 0.0, 1.0);
  soft.position_iterations_count = t.count("position_iterations", 1, 1000);
  soft.collision_margin_m = t.in_range("collision_margin", "m", 0.0, 0.1);
  check_rest_shape(file, t, soft, read_anchors(file, t, soft));
  t.finish();
}

// [soft_body] for one body, [[soft_body]] for several (each table read as the single one, its
// anchors inside it as [[soft_body.anchor]]).
void read_soft_bodies(const std::string& file, const toml::table& root, TableReader& top, std::vector<SoftBodyDescription>& bodies,
                      const std::filesystem::path& base_dir) {
  const toml::node* node = root.get("soft_body");
  if (node == nullptr || !node->is_array()) {
    TableReader t(file, *top.subtable("soft_body", true), "soft_body");
    bodies.assign(1, SoftBodyDescription{});
    read_soft_body(file, t, bodies.front(), base_dir);
    return;
  }
  const toml::array& tables = *top.array_of_tables("soft_body");
  if (tables.empty() || static_cast<int>(tables.size()) > kMaxSoftBodies) {
    throw SceneError(file, std::max(1, line_of(*node)), "soft_body",
                     "a scene holds 1 to " + std::to_string(kMaxSoftBodies) + " soft bodies (got " + std::to_string(tables.size()) + ")");
  }
  bodies.assign(tables.size(), SoftBodyDescription{});
  for (std::size_t i = 0; i < tables.size(); ++i) {
    TableReader t(file, *tables.get(i)->as_table(), "soft_body[" + std::to_string(i) + "]");
    read_soft_body(file, t, bodies[i], base_dir);
  }
}

void read_clamp(TableReader& t, ClampDescription& clamp) {
  clamp.jaw_size_m = t.vec3("jaw_size", "m");
  clamp.handle_size_m = t.vec3("handle_size", "m");
  clamp.handle_offset_tool_m = t.vec3("handle_offset_tool", "m");
  for (const auto* field : {&clamp.jaw_size_m, &clamp.handle_size_m}) {
    for (double e : *field) {
      if (!(e > 0.0)) t.fail(t.table_line(), field == &clamp.jaw_size_m ? "jaw_size_m" : "handle_size_m", "every extent must be > 0");
    }
  }
  clamp.jaw_gap_open_m = t.positive("jaw_gap_open", "m");
  clamp.jaw_gap_min_m = t.in_range("jaw_gap_min", "m", 0.0, clamp.jaw_gap_open_m);
  t.finish();
}

void read_tool(const std::string& file, TableReader& t, ToolDescription& tool, const std::filesystem::path& base_dir) {
  tool.kind = t.choice<ToolKind>("kind", {{"box", ToolKind::kBox}, {"convex_mesh", ToolKind::kConvexMesh}, {"clamp", ToolKind::kClamp}});
  switch (tool.kind) {
    case ToolKind::kBox:
      tool.box_size_m = t.vec3("size", "m");
      for (double e : tool.box_size_m) {
        if (!(e > 0.0)) t.fail(t.line_for("size", "m"), "size_m", "every extent must be > 0");
      }
      if (tool.box_size_m[1] > std::min(tool.box_size_m[0], tool.box_size_m[2])) {
        t.fail(t.line_for("size", "m"), "size_m", "the thin axis is local y: size_m[1] must be the smallest extent");
      }
      break;
    case ToolKind::kConvexMesh: {
      const std::string rel = t.text("mesh_path");
      const std::filesystem::path full = std::filesystem::path(rel).is_absolute() ? std::filesystem::path(rel) : base_dir / rel;
      tool.mesh_path = full.lexically_normal().string();
      try {
        const ToolMesh mesh = read_tool_mesh(tool.mesh_path);
        tool.mesh_vertices_tool_m = mesh.vertices_m;
        tool.mesh_triangles = mesh.triangles;
      } catch (const std::exception& e) {
        t.fail(t.line_for("mesh_path", ""), "mesh_path", std::string("unreadable mesh: ") + e.what());
      }
      break;
    }
    case ToolKind::kClamp: {
      const toml::table* clamp = t.subtable("clamp", true);
      TableReader c(file, *clamp, child_path(t, "clamp"));
      read_clamp(c, tool.clamp);
      break;
    }
  }
  // Box faces get a node grid; a mesh gets one node per triangle, paired by a limited ray.
  if (tool.kind == ToolKind::kConvexMesh) {
    tool.pairing_ray_limit_m = t.positive("pairing_ray_limit", "m");
  } else {
    tool.node_spacing_m = t.positive("node_spacing", "m");
  }
  // Coulomb ratios above 2 are not a tool on wet tissue (steel on soft tissue measures 0.1–0.5;
  // docs/scenes.md); kinetic above static would make sliding grip harder than sticking.
  tool.friction_static_ratio = t.in_range("friction_static", "ratio", 0.0, 2.0, 0.0);
  tool.friction_kinetic_ratio = t.in_range("friction_kinetic", "ratio", 0.0, 2.0, tool.friction_static_ratio);
  if (tool.friction_kinetic_ratio > tool.friction_static_ratio)
    t.fail(t.line_for("friction_kinetic", "ratio"), "friction_kinetic_ratio",
           "must be <= friction_static_ratio (" + config::format_number(tool.friction_static_ratio) + ")");
  // A wet tool–tissue film's viscous shear: 0 (dry) up to a 1 Pa·s mucus-like film 1 µm thick.
  const bool damping_given = t.find("friction_shear_damping", "pa_s_per_m") != nullptr;
  tool.friction_shear_damping_pa_s_per_m =
      t.in_range("friction_shear_damping", "pa_s_per_m", 0.0, kMaxFilmShearDamping_pa_s_per_m, kTissueFilmShearDamping_pa_s_per_m);
  if (damping_given && tool.friction_shear_damping_pa_s_per_m > 0.0 && !(tool.friction_static_ratio > 0.0))
    t.fail(t.line_for("friction_shear_damping", "pa_s_per_m"), "friction_shear_damping_pa_s_per_m",
           "acts on sliding contacts only, so it needs friction (set friction_static_ratio > 0, or remove this key)");
  t.finish();
}

void read_hunt_crossley(TableReader& t, HuntCrossleyParams& hc) {
  hc.per_unit_area = t.choice<bool>("mode", {{"per_unit_area", true}, {"per_triangle", false}});
  hc.measure = t.choice<DeformationMeasure>(
      "deformation_measure",
      {{"normal_displacement", DeformationMeasure::kNormalDisplacement}, {"centroid_distance", DeformationMeasure::kCentroidDistance}},
      DeformationMeasure::kNormalDisplacement);
  hc.n = t.in_range("exponent", "n", 0.5, 3.0);
  if (hc.per_unit_area) {
    hc.k = t.in_range("stiffness", "pa_per_m_pow_n", 0.0, 1e30);
    hc.lambda = t.in_range("damping", "pa_s_per_m_pow_n_plus_1", 0.0, 1e30);
  } else {
    hc.k = t.in_range("stiffness", "n_per_m_pow_n", 0.0, 1e30);
    hc.lambda = t.in_range("damping", "n_s_per_m_pow_n_plus_1", 0.0, 1e30);
  }
  t.finish();
}

/// A clamp's optional jaw gap [m]: when the key is absent, -1 (the description's "fully open at
/// the start" / "unchanged on this leg"); when present, in [0, 10] m.
double optional_jaw_gap_m(TableReader& t, const std::string& stem) {
  if (t.find(stem, "m") == nullptr) return -1.0;
  return t.in_range(stem, "m", 0.0, 10.0);
}

void read_trajectory(const std::string& file, TableReader& t, TrajectoryDescription& traj, bool clamp) {
  traj.start.position_world_m = t.vec3("start_position_world", "m");
  traj.start.orientation_world = quat_from_rpy_deg(t.vec3("start_orientation_rpy", "deg", Vec3{0.0, 0.0, 0.0}));
  if (clamp) traj.start_jaw_gap_m = optional_jaw_gap_m(t, "start_jaw_gap");
  if (const toml::array* legs = t.array_of_tables("waypoint")) {
    for (std::size_t i = 0; i < legs->size(); ++i) {
      TableReader w(file, *legs->get(i)->as_table(), child_path(t, "waypoint[" + std::to_string(i) + "]"));
      TrajectoryWaypoint wp;
      wp.position_world_m = w.vec3("position_world", "m");
      wp.speed_m_per_s = w.positive("speed", "m_per_s");
      wp.hold_s = w.in_range("hold", "s", 0.0, 1e6, 0.0);
      if (clamp) wp.jaw_gap_m = optional_jaw_gap_m(w, "jaw_gap");
      w.finish();
      traj.waypoints.push_back(wp);
    }
  }
  if (traj.waypoints.empty()) t.fail(t.table_line(), "waypoint", "a trajectory needs at least one [[trajectory.waypoint]]");
  t.finish();
}

SceneDescription parse(const toml::table& root, const std::string& file, const std::filesystem::path& base_dir) {
  SceneDescription scene;
  scene.source_path = file;
  scene.name = std::filesystem::path(file).stem().string();
  TableReader top(file, root, "");
  {
    TableReader t(file, *top.subtable("scene", true), "scene");
    scene.description = t.text("description");
    t.finish();
  }
  {
    TableReader t(file, *top.subtable("simulation", true), "simulation");
    read_simulation(t, scene.simulation);
  }
  {
    TableReader t(file, *top.subtable("ground", true), "ground");
    read_ground(t, scene.ground);
  }
  read_soft_bodies(file, root, top, scene.soft_bodies, base_dir);
  {
    TableReader t(file, *top.subtable("tool", true), "tool");
    read_tool(file, t, scene.tool, base_dir);
  }
  {
    TableReader t(file, *top.subtable("hunt_crossley", true), "hunt_crossley");
    read_hunt_crossley(t, scene.hunt_crossley);
  }
  {
    TableReader t(file, *top.subtable("device_mapping", true), "device_mapping");
    read_device_mapping(t, scene.device_mapping);
  }
  {
    TableReader t(file, *top.subtable("hand", true), "hand");
    read_hand(file, t, scene.hand);
  }
  {
    TableReader t(file, *top.subtable("trajectory", true), "trajectory");
    read_trajectory(file, t, scene.trajectory, scene.tool.kind == ToolKind::kClamp);
  }
  top.finish();
  if (scene.tool.friction_static_ratio > 0.0 && scene.simulation.contact_response != ContactResponse::kInSolver) {
    const toml::node* key = root["tool"]["friction_static_ratio"].node();
    throw SceneError(file, key != nullptr ? line_of(*key) : 1, "tool.friction_static_ratio",
                     "friction is solved inside the soft-body solver: it needs [simulation] contact_response = \"in_solver\"");
  }
  if (scene.tool.kind == ToolKind::kClamp && !scene.device_mapping.clamp_mode) {
    const toml::node* flag = root["device_mapping"]["clamp_mode"].node();
    throw SceneError(file, flag != nullptr ? line_of(*flag) : 1, "device_mapping.clamp_mode",
                     "a clamp scene needs clamp_mode = true (one device axis closes the jaws)");
  }
  return scene;
}

}  // namespace

SceneDescription load_scene_text(std::string_view toml_text, const std::string& file_label, const std::filesystem::path& base_dir) {
  return parse(config::parse_toml(toml_text, file_label), file_label, base_dir);
}

SceneDescription load_scene(const std::filesystem::path& file) {
  return load_scene_text(config::read_config_file(file), file.string(), file.parent_path());
}

Quat quat_from_rpy_deg(const Vec3& rpy_deg) {
  // Rotation R = Rz(yaw)·Ry(pitch)·Rx(roll) (extrinsic x, then y, then z), as a unit quaternion.
  constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
  const double hr = 0.5 * rpy_deg[0] * kDegToRad, hp = 0.5 * rpy_deg[1] * kDegToRad, hy = 0.5 * rpy_deg[2] * kDegToRad;
  const double cr = std::cos(hr), sr = std::sin(hr), cp = std::cos(hp), sp = std::sin(hp), cy = std::cos(hy), sy = std::sin(hy);
  return {cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy};
}

}  // namespace fissure::host
