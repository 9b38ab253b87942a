#pragma once
// The Bullet world of a scene: btSoftRigidDynamicsWorld, box ground, the soft bodies, and the
// tool's kinematic rigid bodies (one per collidable part: the spatula, or the clamp's two
// jaws; the clamp handle never collides and has no body). The tool bodies collide with the
// soft body through Bullet ONLY for the `bullet` method; for paired/ray they are not in the
// world at all (thin_body_collision.hpp's call order) and the soft body meets just the ground.
// Several soft bodies meet each other through Bullet's vertex–face soft–soft contact (VF_SS:
// each body's nodes against the other's faces, solved in its position iterations).
//
// Bullet set-up (BRIEF §3): for the `bullet` method the sparse SDF's voxel is set to half the
// tool's thinnest extent AFTER Initialize() (which forces 0.25 m), then Reset(), and the tool
// shape's margin is 0.9 × its half thickness (soft_world.cpp says why); otherwise (only the
// flat ground in Bullet) a 1 cm voxel. Soft margin from the scene; kKHR = kCHR = 1.
#include <array>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include <LinearMath/btVector3.h>

#include "fissure/host_sim/bullet_collision.hpp"
#include "fissure/host_sim/node_bounds_solver.hpp"
#include "fissure/host_sim/scene_description.hpp"
#include "fissure/host_sim/thin_tool.hpp"

class btSoftRigidDynamicsWorld;
class btSoftBody;
class btRigidBody;
class btCollisionShape;
class btDefaultMotionState;
class btBroadphaseInterface;
class btCollisionDispatcher;
class btSequentialImpulseConstraintSolver;
class btSoftBodyRigidBodyCollisionConfiguration;

namespace fissure::host {

class FemWorld;

/// Half-extents of the tool's collidable parts in their own frames: the spatula box, the
/// clamp's jaw box (both jaws), or the convex mesh's bounds. Part frames: thin axis local y.
struct ToolPartGeometry {
  int part_count = 1;
  bool is_mesh = false;
  Eigen::Vector3d box_half_extents_m = Eigen::Vector3d::Zero();  ///< box / jaw
  double thickness_m = 0.0;                                      ///< thinnest extent (SDF voxel = half of it)
};
[[nodiscard]] ToolPartGeometry tool_part_geometry(const SceneDescription& scene);

/// Pose of each collidable part for a tool pose and jaw gap (clamp: jaw A at local
/// y = +(gap + jaw thickness)/2, jaw B at −(…); spatula: the tool pose itself).
void tool_part_poses(const SceneDescription& scene, const ToolPose& tool, double jaw_gap_m, std::array<ToolPose, kMaxToolParts>& parts) noexcept;

class SoftWorld {
 public:
  /// `tool_collides_in_bullet`: add the tool parts to the world (the `bullet` method) and
  /// measure their contacts with a ContactProbeSolver. Otherwise (paired / ray) the soft body is
  /// solved by a NodeBoundsSolver, which keeps the node bounds the thin-body broad phase reads.
  /// `instrumented_solver` false: Bullet's default soft body solver instead of either (the
  /// reference both reproduce exactly).
  SoftWorld(const SceneDescription& scene, bool tool_collides_in_bullet, bool instrumented_solver = true);
  ~SoftWorld();
  SoftWorld(const SoftWorld&) = delete;
  SoftWorld& operator=(const SoftWorld&) = delete;

  /// Soft body `body` of the scene's [[soft_body]] list (0: the first, the only one of most scenes).
  [[nodiscard]] btSoftBody& soft(int body = 0) noexcept { return *bodies_[static_cast<std::size_t>(body)]; }
  [[nodiscard]] const btSoftBody& soft(int body = 0) const noexcept { return *bodies_[static_cast<std::size_t>(body)]; }
  [[nodiscard]] int soft_body_count() const noexcept { return static_cast<int>(bodies_.size()); }
  /// FEM bodies (model = "fem"): their world, and the symplectic substeps of each host step;
  /// null and 1 for shells.
  [[nodiscard]] const FemWorld* fem_world() const noexcept { return fem_.get(); }
  [[nodiscard]] int fem_substeps() const noexcept { return fem_substeps_; }
  /// Where body `body`'s nodes start in copy_node_positions' concatenation (body_count: the total).
  [[nodiscard]] int first_node(int body) const noexcept { return first_nodes_[static_cast<std::size_t>(body)]; }
  [[nodiscard]] int part_count() const noexcept { return geometry_.part_count; }
  [[nodiscard]] const ToolPartGeometry& geometry() const noexcept { return geometry_; }
  /// The part's rigid body (kinematic; in the world only when the tool collides in Bullet).
  [[nodiscard]] const btRigidBody& part_body(int part) const noexcept { return *parts_[static_cast<std::size_t>(part)]; }
  /// Non-null only when the tool collides in Bullet.
  [[nodiscard]] ContactProbeSolver* probe() noexcept { return probe_; }
  /// Non-null only when the tool does not collide in Bullet (and the solver is not the stock one).
  [[nodiscard]] SoftNodeBounds* node_bounds(int body = 0) noexcept { return bounding_solver_ != nullptr ? &bounding_solver_->bounds(body) : nullptr; }
  /// The solver behind node_bounds() (it also solves the in-solver contacts); null as above.
  [[nodiscard]] NodeBoundsSolver* node_bounds_solver() noexcept { return bounding_solver_; }
  /// Solve `contact` inside body `body`'s step (contact_response = "in_solver"): in the
  /// NodeBoundsSolver's position iterations for a shell, in the implicit step's Newton iterations
  /// for an FEM body. Throws std::invalid_argument for a world that cannot host it.
  void add_solver_contact(SoftContactConstraint* contact, int body);
  [[nodiscard]] double sdf_voxel_m() const noexcept { return sdf_voxel_m_; }
  /// Soft nodes tied to the ground by [[soft_body.anchor]], over every body (0: free bodies).
  [[nodiscard]] int anchored_nodes_count() const noexcept { return anchored_nodes_count_; }

  /// Places a tool part (kinematic: Bullet derives its velocity from the previous pose).
  void set_part_pose(int part, const ToolPose& pose) noexcept;
  /// Places a tool part with no motion from its previous pose: Bullet derives zero velocity
  /// for the next step (HostSimulation::reseat_tool; a kinematic body moved by set_part_pose
  /// would carry jump / dt into its contacts with the soft body).
  void teleport_part(int part, const ToolPose& pose) noexcept;
  /// One Bullet step of h seconds (exactly one internal substep; FEM: fem_substeps() equal ones).
  /// Every node's m_q is then where it was when the step began (Bullet's classic solver leaves it
  /// so; the FEM world is made to), which the thin-body sweep reads as the node's start.
  void step(double h_s) noexcept;
  /// After the contact response of a step: FEM bodies get m_q = m_x back, which Bullet's next
  /// deformable step reads as the node's position (no-op for shells).
  void end_step() noexcept;
  /// Copies every soft body's node positions (world, metres), body after body (first_node), into
  /// `out` (resized once).
  void copy_node_positions(std::vector<Eigen::Vector3d>& out) const;

 private:
  void make_tool_parts(const SceneDescription& scene);
  void build_fem_world(const SceneDescription& scene);

  ToolPartGeometry geometry_;
  double sdf_voxel_m_ = 0.0;
  std::unique_ptr<btSoftBodyRigidBodyCollisionConfiguration> configuration_;
  std::unique_ptr<btCollisionDispatcher> dispatcher_;
  std::unique_ptr<btBroadphaseInterface> broadphase_;
  std::unique_ptr<btSequentialImpulseConstraintSolver> solver_;
  std::unique_ptr<btDefaultSoftBodySolver> soft_solver_;
  ContactProbeSolver* probe_ = nullptr;  // = soft_solver_ when probing
  NodeBoundsSolver* bounding_solver_ = nullptr;  // = soft_solver_ for the paired / ray methods
  std::unique_ptr<btSoftRigidDynamicsWorld> world_;
  std::vector<std::unique_ptr<btCollisionShape>> shapes_;
  std::vector<std::unique_ptr<btDefaultMotionState>> motion_states_;
  std::unique_ptr<btRigidBody> ground_;
  std::array<std::unique_ptr<btRigidBody>, kMaxToolParts> parts_;
  std::vector<std::unique_ptr<btSoftBody>> softs_;  // shells (the FEM world owns its bodies)
  std::vector<btSoftBody*> bodies_;                 // every body, shell or FEM, in scene order
  std::unique_ptr<FemWorld> fem_;
  int fem_substeps_ = 1;
  std::vector<btVector3> fem_start_x_;  // FEM: every node's position when the host step began (step())
  std::vector<int> first_nodes_;  // per body, and the total last
  bool parts_in_world_ = false;
  int anchored_nodes_count_ = 0;
};

[[nodiscard]] ToolPose to_tool_pose(const Pose& pose) noexcept;
[[nodiscard]] Eigen::Isometry3d to_isometry(const ToolPose& pose) noexcept;

}  // namespace fissure::host
