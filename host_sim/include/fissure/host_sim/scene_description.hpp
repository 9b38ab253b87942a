#pragma once
// A scene as loaded from its TOML file (docs/scenes.md): the const *model* of one host
// simulation. Built once by load_scene() (or by hand in tests/benchmarks), never mutated
// while a simulation runs. SI units everywhere; the unit is in every field name.
//
// Frames: *_world is the Bullet world (y up, ground top at ground.top_height_m). The tool
// frame has its thin axis along local +y: a box tool is size_m = {width x, thickness y,
// length z}; a convex mesh tool is authored with its thin direction along y; the clamp's
// jaws face each other across local y.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "fissure/host_sim/fem_material.hpp"
#include "fissure/shared/messages.hpp"
#include "fissure/shared/session_config.hpp"

namespace fissure::host {

/// Which thin-body collision answers soft-vs-tool contact (BRIEF §3).
enum class SceneCollisionMethod : std::uint8_t { kPaired, kRay, kBullet };

/// Every method, in the order their names are listed to a user.
inline constexpr std::array<SceneCollisionMethod, 3> kCollisionMethods{SceneCollisionMethod::kPaired, SceneCollisionMethod::kRay,
                                                                       SceneCollisionMethod::kBullet};

/// The method's name in scene files and on the command line: "paired", "ray", "bullet".
[[nodiscard]] const char* to_string(SceneCollisionMethod method) noexcept;
/// The method whose to_string() is `name`; nullopt for any other text (the caller says where it came from).
[[nodiscard]] std::optional<SceneCollisionMethod> parse_collision_method(std::string_view name) noexcept;

/// Where the paired / ray response acts (issue 22): after Bullet's step, overwriting the node
/// positions it solved ("after_step", the paper's order), or as constraints projected inside the
/// soft-body solver's position iterations, so the contact and the body's links converge together
/// ("in_solver"; docs/decisions.md, "Contact inside the solver").
enum class ContactResponse : std::uint8_t { kAfterStep, kInSolver };

/// Its name in scene files and on the command line: "after_step", "in_solver".
[[nodiscard]] const char* to_string(ContactResponse response) noexcept;
/// The response whose to_string() is `name`; nullopt for any other text.
[[nodiscard]] std::optional<ContactResponse> parse_contact_response(std::string_view name) noexcept;

/// A rigid pose: position of the tool frame origin and its orientation, world frame.
struct Pose {
  Vec3 position_world_m{0.0, 0.0, 0.0};
  Quat orientation_world{1.0, 0.0, 0.0, 0.0};  ///< unit quaternion (w, x, y, z)
};

/// Sphere tessellations: Bullet's own ellipsoid (convex hull of res+3 points: the paper's
/// 128-face sphere is res 63) or a geodesic icosphere (20·4^k faces, near-uniform triangles,
/// used for mesh convergence and scaling).
enum class SphereTessellation : std::uint8_t { kBulletEllipsoid, kIcosphere };

struct SoftSphere {
  Vec3 center_world_m{0.0, 0.05, 0.0};
  double radius_m = 0.05;
  SphereTessellation tessellation = SphereTessellation::kBulletEllipsoid;
  int faces_count = 128;
};

/// A closed cylinder (the paper's "vessel") lying with its axis along world x.
struct SoftCylinder {
  Vec3 center_world_m{0.0, 0.015, 0.0};
  double radius_m = 0.015;
  double length_m = 0.12;
  int segments_count = 16;  ///< vertices around the circumference
  int rings_count = 24;     ///< vertex rings along the axis (≥ 2)
};

/// A rectangular soft slab (closed box surface): flat top, bottom nodes pinned to the
/// ground. The force–indentation benchmark's "flat contact set" specimen.
struct SoftSlab {
  Vec3 center_world_m{0.0, 0.01, 0.0};   ///< centre of the box
  Vec3 size_m{0.08, 0.02, 0.08};         ///< full extents x, y (thickness), z
  std::array<int, 2> top_cells_count{16, 16};  ///< grid cells of the top face along x, z
};

/// A soft body from a mesh file (docs/scenes.md "Mesh files"): a closed surface (OBJ or STL), or
/// a tetrahedral volume (Gmsh .msh, VTK .vtk, TetGen .node/.ele: read_soft_body_tet_mesh, a
/// volumetric body whose triangles are the volume's boundary). The
/// file's vertices in metres, moved by offset_world_m, counter-clockwise seen from outside; the
/// loader reads it and refuses a mesh that is open, non-manifold, inconsistently or inward
/// oriented, degenerate, several surfaces or too large (read_soft_body_mesh). Built like the
/// other shapes: btSoftBodyHelpers::CreateFromTriMesh, one link per edge.
struct SoftMesh {
  std::string mesh_path;                      ///< absolute path of the file (resolved at load)
  Vec3 offset_world_m{0.0, 0.0, 0.0};         ///< where the file's origin goes in the world
  std::vector<Vec3> vertices_world_m;         ///< the file's vertices + offset_world_m (loaded and checked at load)
  std::vector<std::array<int, 3>> triangles;  ///< counter-clockwise seen from outside
  /// A volume mesh's tetrahedra (positive, corners into vertices_world_m); empty for a surface mesh.
  std::vector<std::array<int, 4>> tetrahedra;
};

/// Soft-body anchoring (tissue attached to its bed): every node whose REST position (the
/// shape as built, before settling) lies in this world box, bounds included, is tied to the
/// ground by a Bullet anchor (btSoftBody::appendAnchor). Anchored nodes keep their mass, so
/// the thin-body collision still moves them and Bullet pulls them back to where they were.
struct SoftAnchorBox {
  Vec3 min_world_m{0.0, 0.0, 0.0};
  Vec3 max_world_m{0.0, 0.0, 0.0};
};

/// What simulates the soft body ([soft_body] model): Bullet's classic soft body (edge links,
/// kLST; the paper's shell) or FEM in Bullet's deformable world with an SI material (fem_world.hpp).
enum class SoftBodyModel : std::uint8_t { kShell, kFem };

struct SoftBodyDescription {
  std::variant<SoftSphere, SoftCylinder, SoftSlab, SoftMesh> shape{SoftSphere{}};
  SoftBodyModel model = SoftBodyModel::kShell;
  /// model = kFem: the SI material (the shell keys kLST … piterations are then not read);
  /// mass_kg is then density × the mesh's volume.
  FemMaterial fem{};
  double mass_kg = 0.1;
  double linear_stiffness_ratio = 0.5;     ///< Bullet material kLST ∈ (0, 1]
  double pressure_kpr = 0.0;               ///< Bullet config kPR (pressure coefficient), ≥ 0
  double volume_conservation_kvc = 0.0;    ///< Bullet config kVC, ≥ 0
  /// Bullet config kMT ∈ [0, 1]: pose (shape) matching towards the rest shape, the only
  /// restoring force a pressure-less edge-link shell has against being dented (0: off).
  double shape_matching_ratio = 0.0;
  /// Bending links (soft_bending_links.hpp): Bullet kLST ∈ [0, 1] of links between nodes
  /// bending_distance_count edges apart, which resist the folding an edge-link shell has none
  /// against (0: no bending links, the paper's shell).
  double bending_stiffness_ratio = 0.0;
  int bending_distance_count = 2;          ///< graph distance of the bending links' nodes, ≥ 2
  double damping_ratio = 0.01;             ///< Bullet config kDP ∈ [0, 1]
  double friction_ratio = 0.2;             ///< Bullet config kDF ∈ [0, 1]
  int position_iterations_count = 4;       ///< Bullet config piterations
  double collision_margin_m = 0.002;       ///< soft body collision margin (bullet method)
  std::vector<SoftAnchorBox> anchors;      ///< [[soft_body.anchor]]; none by default (a free body)
};

struct GroundDescription {
  double top_height_m = 0.0;               ///< world y of the ground's top face
  Vec3 half_extents_m{0.5, 0.05, 0.5};     ///< box ground
  double friction_ratio = 0.5;
};

enum class ToolKind : std::uint8_t { kBox, kConvexMesh, kClamp };

/// Clamp: two box jaws facing each other across the tool's local y, centred at local
/// y = ±(gap/2 + jaw thickness/2); a handle box that is drawn but never collides.
struct ClampDescription {
  Vec3 jaw_size_m{0.008, 0.003, 0.04};
  Vec3 handle_size_m{0.006, 0.006, 0.12};
  Vec3 handle_offset_tool_m{0.0, 0.0, -0.08};   ///< handle centre in the tool frame
  double jaw_gap_open_m = 0.04;                 ///< gap between the jaws' inner faces when fully open
  double jaw_gap_min_m = 0.0;                   ///< the jaws never close past this gap
};

/// Default viscous shear of a tool on wet tissue [Pa·s/m]: viscosity 1e-3 Pa·s over a 1e-6 m film
/// (ToolDescription::friction_shear_damping_pa_s_per_m; docs/scenes.md).
inline constexpr double kTissueFilmShearDamping_pa_s_per_m = 1.0e3;
/// The loader's upper bound: a 1 Pa·s (mucus-like) film 1 µm thick.
inline constexpr double kMaxFilmShearDamping_pa_s_per_m = 1.0e6;

struct ToolDescription {
  ToolKind kind = ToolKind::kBox;
  Vec3 box_size_m{0.04, 0.004, 0.04};      ///< box tool: full extents (x width, y thickness, z length)
  std::string mesh_path;                   ///< convex mesh tool: absolute path of the OBJ (resolved at load)
  std::vector<Vec3> mesh_vertices_tool_m;  ///< convex mesh tool: vertices, tool frame (loaded and checked at load)
  std::vector<std::array<int, 3>> mesh_triangles;  ///< convex mesh tool: CCW seen from outside
  ClampDescription clamp{};
  double node_spacing_m = 0.004;           ///< box / clamp jaws: collision node grid spacing on the large faces
  double pairing_ray_limit_m = 0.006;      ///< convex mesh: the pairing ray's length limit (paper Fig. 2); node per triangle
  /// Coulomb friction between the tool's faces and the tissue (in_solver response only): a held
  /// node sticks while its tangential correction stays within static × its normal correction,
  /// else slides against kinetic × it. 0 / 0: frictionless (the paper's contact).
  double friction_static_ratio = 0.0;
  double friction_kinetic_ratio = 0.0;
  /// With friction: viscous shear of the wet contact per unit contact area [Pa·s/m = N·s/m³],
  /// acting on a sliding node's slip beyond the kinetic cone (ThinBodyCollisionParams). The
  /// default is a Couette film estimate, viscosity / film thickness: a serous film of ~1 mPa·s
  /// (water-like; water is 0.69 mPa·s at 37 °C) ~1 µm thick (docs/scenes.md). It adds
  /// b·A·v, 0.1 mN per cm² of contact at 1 mm/s.
  double friction_shear_damping_pa_s_per_m = kTissueFilmShearDamping_pa_s_per_m;
};

// What the Hunt-Crossley deformation x of a contacted triangle measures (docs/scenes.md,
// [hunt_crossley] deformation_measure).
enum class DeformationMeasure : std::uint8_t {
  // Default. Per colliding soft node v of the triangle: x_v = max(0, n·(q − p_v,rest)), how far
  // the tool face (a point q on it, outward normal n) has advanced along n past the node's rest
  // position — for a node held on the face, its displacement from rest along n. Sliding along the
  // face, wrapping round the rim and sag add no force, and x follows the tool pose exactly (no
  // node noise); a node that enters contact where the face meets its rest position starts at
  // x ≈ 0, and a held node's share of the force ramps down over release_distance as it
  // separates, so taking or releasing one node changes the force continuously instead of by a
  // whole triangle's worth.
  kNormalDisplacement,
  // The paper's: x = |centroid − rest centroid| per triangle (fidelity; counts tangential motion
  // of the triangle as indentation, and the contacted share changes in thirds of a triangle).
  kCentroidDistance,
};

// F = k·xⁿ + λ·xⁿ·ẋ for x ≥ 0, clamped to F ≥ 0 (BRIEF §4; Hunt & Crossley 1975), for every
// deformed triangle with at least one colliding node; x per `measure`. A scene's [hunt_crossley]
// table (docs/scenes.md) sets every field.
struct HuntCrossleyParams {
  double k = 2.0e5;       // per_unit_area: N/m^(n+2) (× rest area m² → N/mⁿ); else N/mⁿ per triangle
  double lambda = 50.0;   // per_unit_area: N·s/m^(n+3); else N·s/m^(n+1) per triangle
  double n = 1.5;         // exponent (1 flat punch, 3/2 Hertz)
  // true (default, mode = "per_unit_area"): k and λ per unit area, each triangle weighted by its
  // contacted share of its rest area (rest area × colliding vertices / 3), so refining the mesh
  // converges the force; false (mode = "per_triangle"): the paper's plain per-triangle sum.
  bool per_unit_area = true;
  DeformationMeasure measure = DeformationMeasure::kNormalDisplacement;
};

struct SimulationDescription {
  double time_step_s = 0.001;       ///< host step
  int substeps_count = 1;           ///< Bullet internal steps per host step
  Vec3 gravity_world_m_per_s2{0.0, -9.81, 0.0};
  SceneCollisionMethod collision_method = SceneCollisionMethod::kPaired;
  ContactResponse contact_response = ContactResponse::kAfterStep;  ///< paired / ray only
};

/// The scripted tool trajectory used by `fissure sim`: straight legs at constant speed; a
/// clamp's jaw gap changes linearly over the leg, at most at the leg's speed.
struct TrajectoryWaypoint {
  Vec3 position_world_m{};
  double speed_m_per_s = 0.05;
  double hold_s = 0.0;
  double jaw_gap_m = -1.0;          ///< clamp only: target jaw gap at the end of the leg; < 0 keeps the gap
};

struct TrajectoryDescription {
  Pose start{};                     ///< the tool's pose at t = 0 (orientation kept throughout)
  double start_jaw_gap_m = -1.0;    ///< clamp only: gap at t = 0; < 0 means fully open
  std::vector<TrajectoryWaypoint> waypoints;
};

/// The most soft bodies a scene may hold: Bullet tests every pair of bodies for soft–soft contact
/// each step, and the host step carries one thin-body collision per body and tool part; eight
/// covers a fissure's two lobes with the vessels and membranes around them.
inline constexpr int kMaxSoftBodies = 8;

struct SceneDescription {
  std::string name;                 ///< scene name (file stem)
  std::string source_path;          ///< the file it came from ("" when built in code)
  std::string description;
  SimulationDescription simulation{};
  GroundDescription ground{};
  /// [soft_body] (one body) or [[soft_body]] (several, each with its anchors): never empty. The
  /// first is the body the benchmarks and the single-body figures study; the tool meets every
  /// body through the thin-body collision, and the bodies meet each other through Bullet's
  /// vertex–face soft–soft collision (soft_world.hpp).
  std::vector<SoftBodyDescription> soft_bodies{SoftBodyDescription{}};
  ToolDescription tool{};
  HuntCrossleyParams hunt_crossley{};
  DeviceMapping device_mapping{};
  HandScript hand{};
  TrajectoryDescription trajectory{};
};

/// The tool pose and jaw gap the scripted trajectory prescribes at time t_s (piecewise
/// linear legs, holds; after the last leg the tool stays put).
struct TrajectorySample {
  Pose pose{};
  double jaw_gap_m = 0.0;
};
[[nodiscard]] TrajectorySample sample_trajectory(const SceneDescription& scene, double t_s) noexcept;
/// Total scripted duration (all legs and holds) [s].
[[nodiscard]] double trajectory_duration_s(const SceneDescription& scene) noexcept;

}  // namespace fissure::host
