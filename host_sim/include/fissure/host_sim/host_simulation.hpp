#pragma once
// HostSimulation: one scene's host side. Owns the Bullet world (SoftWorld), the chosen
// thin-body collision (one instance per soft body and collidable tool part: the spatula, or each
// clamp jaw), and the method-independent metrics. Each step(): move the tool (and jaws) to the
// target over the scene's sub-steps, one Bullet step + one collision step + the metrics per
// sub-step (the crossing metric judges each node's straight relative path between two updates). Everything is preallocated at construction; step() does not allocate.
//
// Clamp: jaw logic (the one closing DoF) exists only when the scene's tool is a clamp;
// pairing only for thin tools (ToolNodes::is_thin decides inside the collision).
#include <array>
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "fissure/host_sim/contact_metrics.hpp"
#include "fissure/host_sim/scene_description.hpp"
#include "fissure/host_sim/soft_world.hpp"
#include "fissure/host_sim/thin_body_collision.hpp"
#include "fissure/host_sim/thin_tool.hpp"

namespace fissure::host {

/// Wall-clock time of one host step by stage [s].
struct HostStepTimes {
  double bullet_s = 0.0;     ///< btSoftRigidDynamicsWorld::stepSimulation (for `bullet`, includes its collision)
  double collision_s = 0.0;  ///< the method: paired/ray: broad+narrow+response+force; bullet: SDF_RS detection + rigid-contact pass
  double metrics_s = 0.0;    ///< crossed nodes / penetration (diagnostics, not part of the method)
  double total_s = 0.0;      ///< the whole step() without metrics_s
};

struct HostStepResult {
  double time_s = 0.0;                                   ///< simulated time at the end of the step
  Eigen::Vector3d force_on_tool_world_n = Eigen::Vector3d::Zero();  ///< sum over parts (last sub-step)
  std::array<Eigen::Vector3d, kMaxToolParts> part_force_world_n{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};  ///< per jaw (clamp: A = +y, B = −y)
  int part_count = 1;
  std::vector<ContactRecord> contacts;                   ///< all parts (last sub-step); capacity reserved once
  int contact_count = 0;
  CrossingSnapshot crossing;                             ///< summed over parts, the step's worst sub-step (rim passes: all); penetration = max
  std::array<CollisionStepResult, kMaxToolParts> part_results;  ///< the method's own report per part (summed over the soft bodies)
  HostStepTimes times;
  double jaw_gap_m = 0.0;                                ///< clamp: the gap actually applied
};

struct HostSimulationOptions {
  /// paired / ray: solve the soft body with a NodeBoundsSolver, whose node bounds let the broad
  /// phase skip the nodes far from the tool. false: Bullet's stock solver, and the broad phase
  /// reads every node (the same simulation, bit for bit: tests and the bench's A/B use it).
  bool solver_node_bounds = true;
};

class HostSimulation {
 public:
  /// `method` overrides the scene's collision method. Throws std::invalid_argument /
  /// std::runtime_error when the tool or soft body cannot be built.
  explicit HostSimulation(const SceneDescription& scene, std::optional<SceneCollisionMethod> method = std::nullopt,
                          const HostSimulationOptions& options = {});
  ~HostSimulation();
  HostSimulation(const HostSimulation&) = delete;
  HostSimulation& operator=(const HostSimulation&) = delete;

  /// Lets the soft body settle under gravity with the tool held at the trajectory start,
  /// then takes the settled shape as the Hunt-Crossley rest state, re-arms the side memory
  /// and restarts the clock at 0. Call once before stepping through contact.
  void settle(double seconds);

  /// One host step (scene.simulation.time_step_s) towards the tool target; jaw_gap_m is
  /// used by clamp scenes only (clamped to [jaw_gap_min, jaw_gap_open]).
  const HostStepResult& step(const ToolPose& tool_target, double jaw_gap_m = 0.0);

  /// Re-seats the tool at `tool_pose` (and jaw_gap_m, as step() takes it) without moving it
  /// through the space between: for a pose that is not reached by motion — rt_core's position
  /// epoch changed (messages.hpp: an accepted encoder jump, the first sample after a device
  /// fault). step() sweeps the tool from its pose to the target (no tunnelling at any speed, by
  /// design), which carries every node it sweeps: a 10 cm jump would drag the soft body through
  /// itself. Here no time passes: the parts are placed with zero velocity, the collision forgets
  /// its contact memory and puts soft nodes that lie inside the tool at the new pose out onto a
  /// face (ThinBodyCollision::reseat says which; bullet: its own contact does, next step), and
  /// the crossing metric takes every node's side afresh. The next step(tool_pose) starts from rest
  /// at the new pose. Returns the number of soft nodes put out of the tool.
  int reseat_tool(const ToolPose& tool_pose, double jaw_gap_m = 0.0);

  /// The scripted trajectory's target at the current time (for `fissure sim`).
  [[nodiscard]] TrajectorySample scripted_target() const noexcept;

  [[nodiscard]] const SceneDescription& scene() const noexcept { return scene_; }
  [[nodiscard]] SceneCollisionMethod method() const noexcept { return method_; }
  [[nodiscard]] double time_s() const noexcept { return time_s_; }
  [[nodiscard]] const HostStepResult& last() const noexcept { return result_; }
  [[nodiscard]] SoftWorld& world() noexcept { return *world_; }
  [[nodiscard]] const SoftWorld& world() const noexcept { return *world_; }
  [[nodiscard]] const std::vector<Eigen::Vector3d>& node_positions_world_m() const noexcept { return nodes_; }
  /// The collision model of part p (nullptr for the bullet method).
  [[nodiscard]] const ToolNodes* tool_nodes(int part) const noexcept;
  /// Soft triangles and nodes over every body; node_positions_world_m() and soft_faces() hold them
  /// body after body (first_node).
  [[nodiscard]] int soft_face_count() const noexcept;
  [[nodiscard]] int soft_body_count() const noexcept { return world_->soft_body_count(); }
  /// Where body `body`'s nodes start in node_positions_world_m() (soft_body_count(): the total).
  [[nodiscard]] int first_node(int body) const noexcept { return world_->first_node(body); }
  /// Where body `body`'s triangles start in soft_faces() (soft_body_count(): the total).
  [[nodiscard]] int first_face(int body) const noexcept { return first_faces_[static_cast<std::size_t>(body)]; }
  /// Every body's triangles as indices into node_positions_world_m().
  [[nodiscard]] const std::vector<std::array<int, 3>>& soft_faces() const noexcept { return soft_faces_; }
  /// Soft triangles cut by the tool's interior now (triangles_cut_by_volume with the metrics'
  /// tool volume, summed over the parts): the failure the crossed count cannot see. Diagnostic
  /// cost; not part of step().
  [[nodiscard]] int triangles_cut_by_tool(double depth_tolerance_m) const;
  [[nodiscard]] int soft_node_count() const noexcept;
  [[nodiscard]] const ToolPose& tool_pose() const noexcept { return tool_pose_; }
  /// Pose of tool part p (the clamp's jaw A = 0, B = 1; a one-part tool: the tool) after the last step.
  [[nodiscard]] const ToolPose& part_pose(int part) const noexcept { return part_poses_[static_cast<std::size_t>(part)]; }
  /// Axis-aligned bounds of the soft nodes (world) as of the last step/settle.
  [[nodiscard]] Eigen::AlignedBox3d soft_bounds_world_m() const noexcept;

 private:
  void measure() noexcept;

  const SceneDescription scene_;
  SceneCollisionMethod method_;
  std::unique_ptr<SoftWorld> world_;
  std::vector<ToolNodes> tool_nodes_;  // per part (paired/ray)
  // One per soft body and part: collisions_[body · part_count + part].
  std::vector<std::unique_ptr<ThinBodyCollision>> collisions_;
  // Several bodies: each collision's report before they are summed into the part's.
  std::vector<CollisionStepResult> body_part_results_;
  std::vector<CrossingTracker> trackers_;
  std::vector<std::array<int, 3>> soft_faces_;  // node indices of each soft face (fixed topology; triangles_cut_by_tool)
  std::vector<int> first_faces_;  // per body, and the total last
  std::vector<Eigen::Vector3d> nodes_;
  ToolPose tool_pose_;
  double jaw_gap_m_ = 0.0;
  std::array<ToolPose, kMaxToolParts> part_poses_{};
  double time_s_ = 0.0;
  HostStepResult result_;
};

}  // namespace fissure::host
