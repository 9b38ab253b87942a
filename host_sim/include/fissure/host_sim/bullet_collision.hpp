#pragma once
// The `bullet` baseline: Bullet's own SDF_RS soft-vs-rigid collision, set up fairly
// (BRIEF §3: sparse SDF voxel ≈ half the tool thickness, soft margin a few mm, kKHR = 1 —
// see SoftWorld), wrapped in the ThinBodyCollision interface so every method is driven and
// measured the same way.
//
// Force: Bullet's contacts with a kinematic body push only the soft nodes (the impulse it
// "applies" to the infinite-mass tool is discarded), so the reaction is MEASURED from the
// nodes' momentum change caused by the tool contacts: ContactProbeSolver runs Bullet's own
// position solvers in Bullet's order, one solver at a time, and records each node's
// displacement Δx during the rigid-contact pass; F_on_tool = −Σ mᵢ·Δxᵢ / h² over the nodes
// touching the tool (h = Bullet step). Link/anchor passes conserve momentum and are not
// counted. A node touching the ground and the tool in the same step is attributed to the
// tool. The probe reproduces btSoftBody::solveConstraints exactly (tested).
#include <array>
#include <chrono>
#include <vector>

#include <BulletSoftBody/btDefaultSoftBodySolver.h>
#include <Eigen/Core>

#include "fissure/host_sim/thin_body_collision.hpp"

class btCollisionObject;
class btSoftBody;

namespace fissure::host {

inline constexpr int kMaxToolParts = 2;  ///< spatula: 1; clamp: 2 jaws

class ContactProbeSolver : public btDefaultSoftBodySolver {
 public:
  /// Measure the contacts of `soft` with these rigid objects (tool parts; index = part).
  void attach(btSoftBody* soft, const std::array<const btCollisionObject*, kMaxToolParts>& tool_parts);
  /// Zeroes the accumulated measurements (call before each Bullet step).
  void clear() noexcept;

  void solveConstraints(btScalar solver_dt) override;
  void processCollision(btSoftBody* soft, const btCollisionObjectWrapper* other) override;
  using btDefaultSoftBodySolver::processCollision;

  /// Σ mᵢ·Δxᵢ of the nodes touching part p since clear() [kg·m] (displacement-weighted).
  [[nodiscard]] const Eigen::Vector3d& momentum_displacement(int part) const noexcept { return mass_displacement_[static_cast<std::size_t>(part)]; }
  /// Per node: Σ m·Δx since clear() (zero for nodes not touching the tool).
  [[nodiscard]] const std::vector<Eigen::Vector3d>& node_mass_displacement() const noexcept { return node_mass_displacement_; }
  /// Per node: the tool part it touched in the last step, −1 none.
  [[nodiscard]] const std::vector<int>& node_part() const noexcept { return node_part_; }
  [[nodiscard]] double seconds_detection() const noexcept { return seconds_detection_; }
  [[nodiscard]] double seconds_response() const noexcept { return seconds_response_; }
  [[nodiscard]] double last_step_s() const noexcept { return last_step_s_; }

 private:
  int part_of(const btCollisionObject* object) const noexcept;

  btSoftBody* soft_ = nullptr;
  std::array<const btCollisionObject*, kMaxToolParts> parts_{};
  std::array<Eigen::Vector3d, kMaxToolParts> mass_displacement_{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  std::vector<Eigen::Vector3d> node_mass_displacement_;
  std::vector<Eigen::Vector3d> before_;
  std::vector<int> node_part_;
  std::vector<int> touched_;     // node indices touching a tool part this step
  std::vector<int> sequence_;    // Bullet's position-solver sequence, saved
  double seconds_detection_ = 0.0;
  double seconds_response_ = 0.0;
  double last_step_s_ = 0.0;
};

/// ThinBodyCollision over Bullet's SDF_RS contacts for tool part `part` (the world runs the
/// contacts inside stepSimulation; step() reads what the probe measured).
class BulletCollision final : public ThinBodyCollision {
 public:
  BulletCollision(const ContactProbeSolver& probe, const btCollisionObject& part_object, int part);
  void step(const ToolPose& previous, const ToolPose& current, double dt_s, btSoftBody& soft, CollisionStepResult& out) override;
  void reset_rest_state(const btSoftBody& soft) override;
  /// Nothing to forget and nothing to put out here: Bullet finds its soft-rigid contacts afresh
  /// each step (SDF_RS), and its contact pushes out nodes inside the part along the SDF gradient.
  int reseat(const ToolPose& /*previous*/, const ToolPose& /*current*/, btSoftBody& /*soft*/) override { return 0; }
  [[nodiscard]] SceneCollisionMethod method() const override { return SceneCollisionMethod::kBullet; }
  // Bullet's own contact is always solved inside its step: nothing to add or prepare.
  [[nodiscard]] SoftContactConstraint* solver_contact() noexcept override { return nullptr; }
  void prepare_step(const ToolPose& /*previous*/, const ToolPose& /*current*/, double /*dt_s*/) override {}

 private:
  const ContactProbeSolver& probe_;
  const btCollisionObject& part_object_;
  int part_;
};

}  // namespace fissure::host
