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

}  // namespace fissure::eval
