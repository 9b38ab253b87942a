#pragma once
// Issue 23's grasp experiments on the host simulation (no device): a clamp closes on the soft
// vessel and lifts it (grasp_lift.cpp), or pulls a gripped vessel whose far end is anchored out of
// its jaws (grasp_pull.cpp). `fissure bench grasp` runs them for its table; the tests run them at
// the shipped friction and at a slippery one.
#include <fissure/host_sim/scene_description.hpp>

#include <vector>

namespace fissure::eval {

struct GraspLiftOptions {
  /// The lift scene (default: scenes/clamp-vessel-lift.toml); its trajectory closes, lifts,
  /// holds, lowers and opens.
  host::SceneDescription scene;
  /// < 0: the scene's friction; else both ratios set to it (static = kinetic).
  double friction_ratio_override = -1.0;
  double settle_s = 0.5;
};

struct GraspLiftResult {
  double friction_static_ratio = 0.0;
  double friction_kinetic_ratio = 0.0;
  double vessel_mass_kg = 0.0;
  double jaw_rise_m = 0.0;            ///< how far the clamp rose from the end of closing to the end of the hold
  double centroid_rise_m = 0.0;       ///< how far the vessel's centre of mass rose over the same time
  double rise_shortfall_max_m = 0.0;  ///< max over the hold of (jaw rise − vessel rise) since the end of closing
  double hold_slide_max_m = 0.0;      ///< max tangential slide along its jaw face of a node on a jaw at the start of the hold
  int hold_contact_nodes = 0;         ///< nodes on a jaw face at the start of the hold
  double hold_grip_n = 0.0;           ///< mean over the hold of the jaws' normal force along the closing axis, per jaw
  double hold_friction_up_n = 0.0;    ///< mean over the hold of the jaws' friction force on the vessel, upwards (world +y)
  double release_delay_s = -1.0;      ///< from the step the jaws clear the vessel (gap > its width) to the first step of 0 N for good (< 0: never)
  double force_at_clear_n = 0.0;      ///< |normal| + |friction| of both jaws on the step the jaws cleared the vessel
  int crossed_nodes_max = 0;
  int cut_triangles_max = 0;          ///< triangles cut deeper than 0.1 mm on a step (every 10th step checked)
  bool finite = true;
  // The trace (one row per step): time, jaw gap, vessel centre of mass height, per-jaw normal
  // and friction force magnitude.
  std::vector<double> time_s, jaw_gap_m, centroid_height_m, jaw_a_normal_n, jaw_b_normal_n, jaw_a_friction_n, jaw_b_friction_n;
};

[[nodiscard]] host::SceneDescription grasp_lift_scene();
[[nodiscard]] GraspLiftResult run_grasp_lift(const GraspLiftOptions& options);

struct GraspPullOptions {
  /// The retraction scene (default: scenes/clamp-vessel-retract.toml): its far end anchored, the
  /// clamp closing near the free end. Its trajectory is replaced: close to jaw_gap_m, hold,
  /// pull pull_distance_m along pull_direction_world at pull_speed_m_per_s.
  host::SceneDescription scene;
  double jaw_gap_m = 0.018;
  double friction_ratio = 0.3;        ///< static = kinetic (Coulomb's law has one μ for the slope)
  double pull_distance_m = 0.02;
  double pull_speed_m_per_s = 0.01;
  double settle_s = 0.5;
};

struct GraspPullResult {
  double jaw_gap_m = 0.0;
  double friction_ratio = 0.0;
  double grip_n = 0.0;                ///< per-jaw normal force along the closing axis, mean over the pull's last quarter
  double pull_out_n = 0.0;            ///< the friction force on the vessel along the pull, mean over the pull's last quarter (sliding)
  double pull_peak_n = 0.0;           ///< its largest value during the pull
  double slip_m = 0.0;                ///< how far the jaws slid along the vessel (jaw travel − travel of the gripped nodes)
  int crossed_nodes_max = 0;
  bool finite = true;
};

[[nodiscard]] host::SceneDescription grasp_pull_scene();
[[nodiscard]] GraspPullResult run_grasp_pull(const GraspPullOptions& options);

/// The drag the hand feels (issue 23, "drag felt"): a closed-loop lockstep session — SimFalcon
/// with the scene's scripted hand, rt_core, the host at host_rate_hz — of
/// scenes/spatula-ball-drag.toml: the spatula pressed onto the ball's top with ~2 N and slid
/// across it at 5 cm/s. Per rt tick the force commanded to the device is split along the contact
/// normal rt_core evaluated (the direction of the proxy's elastic normal force on the tool): its
/// tangential part against its normal part is the friction coefficient the hand feels.
struct GraspDragOptions {
  host::SceneDescription scene;       ///< default: grasp_drag_scene()
  double host_rate_hz = 1000.0;
  double rt_rate_hz = 1000.0;
  double settle_s = 1.0;
  /// The slide: ticks where the tool moves along the surface at ≥ this share of the hand's
  /// scripted slide speed (5 cm/s), the normal force is ≥ 0.5 N and the host sees contact.
  double sliding_speed_share = 0.8;
};

struct GraspDragResult {
  double host_rate_hz = 0.0;
  double friction_static_ratio = 0.0;
  double friction_kinetic_ratio = 0.0;
  int slide_ticks = 0;                   ///< ticks in the slide window (see GraspDragOptions)
  double normal_median_n = 0.0;          ///< commanded force along the contact normal, median over the slide
  double tangential_median_n = 0.0;      ///< commanded force across it, median over the slide
  double ratio_median = 0.0;             ///< median over the slide of tangential / normal (per tick)
  double ratio_p10 = 0.0, ratio_p90 = 0.0;
  double host_friction_median_n = 0.0;   ///< the host's own friction force on the tool, median over the slide
  double host_normal_median_n = 0.0;     ///< the host's normal (Hunt-Crossley) force on the tool, median over the slide
  double sliding_tick_share = 0.0;       ///< share of the slide's ticks on which rt_core's cone slid
  double slide_speed_median_m_per_s = 0.0;
  double max_force_step_n = 0.0;         ///< max |ΔF| per tick of the commanded force over the whole session
  double energy_max_j = 0.0;             ///< passivity observer's largest value over the session
  int crossed_nodes_max = 0;
  bool finite = true;
};

[[nodiscard]] host::SceneDescription grasp_drag_scene();
[[nodiscard]] GraspDragResult run_grasp_drag(const GraspDragOptions& options);

}  // namespace fissure::eval
