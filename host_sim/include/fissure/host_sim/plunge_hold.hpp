#pragma once
// The plunge-and-hold cell of issue 5's tunnelling sweep, shared by `fissure bench collision`
// (which prints the table) and tests/host_sim/hold_jitter_test.cpp (which asserts on it), so
// the test checks exactly what the benchmark reports: the 128-face spatula-sphere ball with
// pose matching, settled, a tool started above its top, driven down at one speed, then held.
// Lockstep (simulated time): every figure but the step times is deterministic.
#include <array>
#include <functional>
#include <string_view>
#include <vector>

#include "fissure/host_sim/scene_description.hpp"
#include "fissure/host_sim/thin_tool.hpp"

namespace fissure::host {

class HostSimulation;

/// Where the tool's leading face starts above the settled soft surface [m]: 15 mm, clear of
/// the ball so the first steps are out of contact at every speed.
inline constexpr double kPlungeStartClearance_m = 0.015;
/// How far below the settled top the leading face is driven [m] (BRIEF §3's measurement: a
/// plate driven down into the sphere): 20 mm of a 50 mm radius.
inline constexpr double kPlungeDepth_m = 0.02;
/// Settling time of the ball under gravity before the plunge [s].
inline constexpr double kPlungeSettle_s = 0.3;
/// After the plunge stops, the hold's force is measured only after this window [s]: a fast
/// plunge hands the enforced nodes the tool's speed and they keep it for one step when the
/// tool stops (the light shell rings or is dented away from the plate) — the soft body's
/// response to the impact, not force noise of the contact at rest.
inline constexpr double kHoldSettle_s = 0.05;
/// Pose-matching coefficient (Bullet kMT) of the plunge ball: the collision unit tests'
/// springy ball (tests/host_sim/soft_scene_fixture.hpp). The paper's shell (edge links, no
/// pressure) has no restoring force: a plunge at ≥ 5 m/s snaps the cap into a dent that
/// stays, and the held plate measures nothing (every paired cell at ≥ 10 m/s ends
/// 'lost'). Pose matching pulls the cap back; collision and tunnelling are unchanged by it.
inline constexpr double kPlungeShapeMatchingRatio = 0.05;

/// One tool of the sweep.
struct PlungeTool {
  std::string_view name;
  ToolKind kind = ToolKind::kBox;
  Vec3 box_size_m{};          ///< box tools
  Vec3 orientation_rpy_deg{};
  double leading_half_m = 0.0;  ///< from the tool origin to its lowest point
};

/// Issue 5's four tools: 4 mm plate, 1 mm plate, a 1 mm blade moving edge-first (thin axis
/// turned to world x, the 40 mm edge leads downwards), the convex spatula of
/// convex-spatula-sphere.
[[nodiscard]] const std::array<PlungeTool, 4>& plunge_tools();

/// spatula-sphere with `tool` and the plunge ball's pose matching; with icosphere_faces > 0 the
/// ball is an icosphere of that many faces (issue 22's second mesh: 1280) instead of the
/// paper's 128-face shell. Loads shipped scenes (throws SceneError when they cannot be found;
/// std::invalid_argument for a face count no icosphere has).
[[nodiscard]] SceneDescription plunge_scene(const PlungeTool& tool, int icosphere_faces = 0);

/// The in-solver cells (contact_response = "in_solver", issue 22): the contact is then as stiff as
/// the body's own constraints, and a frictionless tool squeezing a free ball against the ground
/// pushes it out sideways (the ball's centre travelled 5–66 mm over a 0.5 s hold; docs/decisions.md,
/// "Contact inside the solver") — a bar of soap, not tissue. So the in-solver cells grip as tissue is
/// gripped: the tool's faces have Coulomb friction, and the ball lies on a bed (its nodes below
/// kPlungeBedTop_m above the ground tied to it), as a specimen is fixed in a dish.
/// Static and kinetic ratio 0.5 / 0.4: a firm grip, above the dynamic 0.09–0.20 measured for
/// porcine brain on metal platens (Rashid, Destrade & Gilchrist 2013, J. Mech. Behav. Biomed.
/// Mater.) — the benchmark's choice, not a tissue value. At 0.2 / 0.2 the cells measured 4 of 32
/// with a cut triangle and 10 of 32 with hold jitter ≤ 1 % (docs/decisions.md, 2026-12-04).
inline constexpr double kPlungeFrictionStaticRatio = 0.5;
inline constexpr double kPlungeFrictionKineticRatio = 0.4;
/// The bed: the ball's bottom cap, 15 mm high on the 100 mm ball (15 % of its surface).
inline constexpr double kPlungeBedTop_m = 0.015;
/// `scene` (a plunge scene) with the in-solver response, the tool's friction (none when
/// `tool_friction` is false: the frictionless cells issue 23 also holds the contact to) and the
/// ball on its bed.
[[nodiscard]] SceneDescription in_solver_plunge_scene(SceneDescription scene, bool tool_friction = true);
/// A sweep cell's scene (`fissure bench collision`, Python's plunge_scene): plunge_scene with
/// `response`; in_solver through in_solver_plunge_scene (friction unless switched off, the bed).
[[nodiscard]] SceneDescription plunge_cell_scene(const PlungeTool& tool, int icosphere_faces, ContactResponse response, bool tool_friction);

/// The volumetric sweep ball (`fissure bench collision --soft-model fem`): the shell's own
/// surface (the 128-face ball, or the 1280-face icosphere), vertex for vertex, filled with
/// tetrahedra by TetGen keeping that surface (tools/plunge_ball_surface.py gives the command;
/// scenes/meshes/plunge-ball-128.1.node: 81 nodes, 244 tetrahedra; plunge-ball-1280.1.node: 1,006
/// nodes, 4,015 tetrahedra), an FEM body in Bullet's deformable world on the in-solver cells' bed.
/// It asks whether what the shell cells miss (hold jitter after the shell's own settling,
/// docs/decisions.md) is the shell's: an elastic volume has a restoring force everywhere.
/// E 20 kPa: the box spatula's 1 cm press of spatula-sphere then holds 6.01 N on this ball, the
/// shell's 5.96 N (`fissure sim` on the scene with this body, after_step); within soft tissue's 1–100 kPa
/// (brain 1–3, liver 5–10, muscle 10–100 kPa; fem_material.hpp has the sources).
inline constexpr double kPlungeFemYoungsModulus_pa = 20000.0;
/// Mass damping [1/s]: spatula-fem-lobe's, which settles a body on its bed within ~0.3 s.
inline constexpr double kPlungeFemMassDamping_per_s = 10.0;
/// `scene` (a plunge scene) with the volumetric ball of `icosphere_faces` faces (0: 128, or 1280)
/// on the bed, with `response`; in_solver with the in-solver cells' tool friction unless
/// `tool_friction` is false (after_step has none). Throws std::invalid_argument for another face
/// count, MeshError when the shipped mesh cannot be read.
[[nodiscard]] SceneDescription volumetric_plunge_scene(SceneDescription scene, int icosphere_faces,
                                                       ContactResponse response = ContactResponse::kAfterStep, bool tool_friction = true);

/// Where a plunge starts: the tool kPlungeStartClearance_m above the settled soft surface, and
/// the height of its origin once the leading face is kPlungeDepth_m below that surface [m, world y].
struct PlungeStart {
  ToolPose pose;
  double end_y_m = 0.0;
};
/// Settles `sim` (kPlungeSettle_s, the tool well clear) and steps the tool to the start pose.
[[nodiscard]] PlungeStart settle_and_place_above(HostSimulation& sim, const SceneDescription& scene, double leading_half_m);

/// Statistics of |F(t)| over the hold, sampled every step and fitted by a least-squares line.
/// All fractions of the mean force; zero when no contact is left (in_contact false).
struct HoldForceStats {
  bool in_contact = false;
  double mean_n = 0.0;
  double jitter = 0.0;         ///< residual std about the line / mean: the "hold jitter ≤ 1 %" target
  double drift = 0.0;          ///< the line's change over the window / mean (the body relaxing)
  double std_over_mean = 0.0;  ///< plain sample std / mean (trend included)
  double step_noise = 0.0;     ///< std of the step-to-step change / √2 / mean (chatter, not ringing)
};
[[nodiscard]] HoldForceStats hold_force_stats(const std::vector<double>& force_n);

struct PlungeHoldResult {
  int crossed_nodes = 0, wrong_side_nodes = 0, inside_nodes = 0;  ///< worst step
  double max_penetration_m = 0.0;
  std::vector<double> hold_force_n;  ///< |F| per step of the measured hold window
  double hold_friction_mean_n = 0.0; ///< mean over the hold of |the friction part of F| (in_solver with friction)
  // What the diagnosis of a jittery cell needs (is the contact set chattering, or is the ball
  // moving?), over the measured hold window:
  int hold_contact_set_changes = 0;   ///< steps whose force-set triangle count differs from the step before's
  Vec3 ball_centre_hold_start_world_m{};  ///< mean of the soft nodes at the first hold step ...
  Vec3 ball_centre_hold_end_world_m{};    ///< ... and at the last
  // Soft triangles cut by the tool's interior deeper than kInsideToleranceM (triangles_cut_by_tool)
  // over the hold window; −1 unless asked for (count_cut_triangles: it reads every face each step).
  int hold_max_cut_triangles = -1;        ///< the most on any hold step
  int hold_steps_with_cut_triangles = -1; ///< hold steps with at least one
  std::vector<double> step_s;        ///< wall time of every step (plunge and hold)
  HoldForceStats hold;
  /// The soft body went non-finite (an FEM body whose elements the plunge inverted): the cell
  /// stops at that step, with every node counted crossed and the hold out of contact, instead of
  /// stepping the garbage to the end (Bullet's corotation then spends seconds per step).
  bool non_finite = false;
};

/// Called on every measured hold step with the simulation and that step's cut-triangle count
/// (count_cut_triangles only): a test checks the count against an independent ruler.
using HoldStepObserver = std::function<void(HostSimulation& sim, int cut_triangles)>;

/// Settles, plunges the tool kPlungeDepth_m into the ball at `speed_m_s`, holds it
/// kHoldSettle_s + hold_s, and measures (the cut triangles too when count_cut_triangles).
[[nodiscard]] PlungeHoldResult run_plunge_hold(const SceneDescription& scene, SceneCollisionMethod method, double speed_m_s,
                                               double leading_half_m, double hold_s, bool count_cut_triangles = false,
                                               const HoldStepObserver& on_hold_step = {});

}  // namespace fissure::host
