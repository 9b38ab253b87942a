#pragma once
// Issue 22's two motion cells beside the plunge sweep (plunge_hold.hpp), shared by `fissure bench
// collision` (which prints them) and the tests (which assert on them): the spatula's levering
// motion in a fissure, and a clamp that closes on the ball and lets go. Lockstep (simulated
// time): every figure but the step times is deterministic.
#include <vector>

#include "fissure/host_sim/plunge_hold.hpp"
#include "fissure/host_sim/scene_description.hpp"

namespace fissure::host {

struct HostStepResult;

/// Levering: the 1 mm blade (plunge_tools()[2]) inserted edge-first kPlungeDepth_m into the ball
/// at this speed [m/s] (quasi-static: the cell is about the turn, not the impact) ...
inline constexpr double kLeverInsertSpeed_m_s = 0.1;
/// ... then turned this far [rad] (30°) about its leading edge's direction through the tool
/// origin (the blade's centre, 20 mm above the edge: the edge sweeps ~10 mm sideways, pushing
/// one side of the incision open) ...
inline constexpr double kLeverAngle_rad = 0.5235987755982988;
/// ... at this rate [rad/s] (issue 22: 1 rad/s), then held kHoldSettle_s + the hold.
inline constexpr double kLeverRate_rad_s = 1.0;

/// What both cells count on every step they run: the paired guarantees and the step's wall time.
struct CellStepCounts {
  int crossed_nodes = 0, inside_nodes = 0;  ///< worst step, whole cell
  double max_penetration_m = 0.0;           ///< whole cell
  int max_cut_triangles = 0;                ///< triangles_cut_by_tool(kInsideToleranceM): most on a step
  int steps_with_cut_triangles = 0;         ///< steps with at least one
  std::vector<double> step_s;               ///< wall time of every step

  /// Takes in one step's result and the triangles the tool cuts after it.
  void take(const HostStepResult& step, int cut_triangles);
};

struct LeverResult : CellStepCounts {
  int steps = 0;                            ///< steps of the cell (insert, turn and hold)
  std::vector<double> hold_force_n;         ///< |F| per step of the measured hold
  HoldForceStats hold;
};

/// Settles `scene` (a plunge_scene of the blade), inserts, turns and holds `hold_s`.
[[nodiscard]] LeverResult run_lever_hold(const SceneDescription& scene, SceneCollisionMethod method, double hold_s);

/// The clamp cell: clamp-sphere's script (close on the ball, hold, open fully) after the ball
/// settled `settle_s` [s]. An opened jaw must let go: the force is judged from the 5th step on
/// which the jaws are fully open (issue 22: 0 N within 5 ms at 1 kHz).
inline constexpr int kClampOpenGraceSteps = 5;

struct ClampReleaseResult : CellStepCounts {
  double settle_s = 0.0;
  double script_max_force_n = 0.0;  ///< the larger jaw's |F|, most over the script (did it grab?)
  int open_steps = 0;               ///< steps with the jaws fully open
  double open_force_max_n = 0.0;   ///< the larger jaw's |F|, most after the grace steps
};

[[nodiscard]] ClampReleaseResult run_clamp_release(const SceneDescription& clamp_scene, SceneCollisionMethod method, double settle_s);

/// The clamp cell's scene: clamp-sphere with its ball's bottom tied to a bed and jaw friction
/// 0.5 / 0.4, as the in-solver sweep cells (in_solver_plunge_scene), and `response`. Friction acts
/// only inside the solver, so after_step and an in-solver run without `tool_friction` get
/// frictionless jaws. The shipped scene keeps its free ball (docs/decisions.md says why).
[[nodiscard]] SceneDescription clamp_cell_scene(ContactResponse response, bool tool_friction);

}  // namespace fissure::host
