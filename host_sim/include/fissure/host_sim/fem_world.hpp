#pragma once
// Bullet's deformable world with FEM soft bodies (issue 24): btDeformableMultiBodyDynamicsWorld,
// btDeformableBodySolver, one elasticity force per body (fem_material.hpp says which and with
// which parameters), an optional static ground and kinematic boxes (plates, punches).
//
// Time stepping (btDeformableBodySolver, read in bullet3 3.24's source):
// * symplectic (the default, `implicit = false`): the elastic force at x_n is applied
//   explicitly, damping implicitly by a conjugate-gradient solve, and the contacts and fixed nodes
//   as velocity projections in that solve. Stable while h < ~h_min / c_p (the P-wave's transit
//   of the smallest element, fem_material.hpp p_wave_speed_m_per_s);
// * implicit: backward Euler, `newton_iterations` Newton steps of a CG solve on
//   M − h D − h² K; stable at any h for fixed-node problems (a large h is a quasi-static solve),
//   but measured here to blow up (NaN) with rigid contacts at h = 10 ms: contact runs use the
//   symplectic stepping.
//
// Boundary conditions through Bullet: a node given zero mass is a Dirichlet node (Bullet adds a
// static constraint for every node with inverse mass 0, its velocity change projected to zero);
// move_fixed_node prescribes where it is (kinematic). Reaction forces: elastic_forces evaluates
// the body's own Bullet force at the current positions (the same code the step applies), so at
// equilibrium the sum over the fixed nodes is minus the load they carry.
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "fissure/host_sim/fem_body.hpp"
#include "fissure/host_sim/fem_material.hpp"
#include "fissure/host_sim/soft_body_builder.hpp"

class btDeformableMultiBodyDynamicsWorld;
class btDeformableBodySolver;
class btDeformableMultiBodyConstraintSolver;
class btDeformableLagrangianForce;
class btSoftBody;
class btRigidBody;
class btCollisionShape;
class btDefaultMotionState;
class btBroadphaseInterface;
class btCollisionDispatcher;
class btSoftBodyRigidBodyCollisionConfiguration;

namespace fissure::host {

class SoftContactConstraint;
class FemBodySolver;

struct FemWorldConfig {
  Eigen::Vector3d gravity_world_m_per_s2 = Eigen::Vector3d::Zero();
  bool has_ground = false;            ///< a static box whose top face is y = ground_top_y_m
  double ground_top_y_m = 0.0;
  double ground_friction_ratio = 0.0;
  bool implicit = false;              ///< see the file comment
  int newton_iterations = 1;          ///< implicit only
  /// Cap on the conjugate-gradient iterations of each linear solve (Bullet's default 300): a
  /// quasi-static solve (implicit, a step far above the body's periods) needs the CG to finish.
  int cg_max_iterations = 300;
  /// The CG stops when rᵀz falls below this × its start (capped at 1) — Bullet's default is
  /// SIMD_EPSILON, 1.2e-7 in single precision, which rounding rarely lets it reach: it then runs
  /// all its iterations every step.
  double cg_tolerance = 1.2e-7;
  /// Sparse SDF voxel of the rigid shapes: flat box faces are exact at any voxel (trilinear), so
  /// a coarse one keeps the lazily built cells few (soft_world.cpp measured the same).
  double sdf_voxel_m = 0.01;
};

/// The mesh's thinnest tetrahedron [m]: the smallest altitude over its largest face, 3V / A_max
/// (+inf for a mesh without tetrahedra). A sliver (four nearly coplanar corners) has short
/// altitudes with no short edge, and its stiffness is what limits the explicit step.
[[nodiscard]] double thinnest_tetrahedron_m(const VolumeMesh& mesh) noexcept;

/// The symplectic step's stable size [s]: a fraction (Courant number) of the P-wave's transit of
/// the thinnest tetrahedron. 0.3·√2 gives a Kuhn grid of cubes (altitude a/√2) 0.3 × its edge,
/// the step the tissue bench validated there; measured on TetGen's fill of the organ lobe
/// (docs/decisions.md), where a shortest-edge criterion let slivers blow the body up.
inline constexpr double kFemCourantRatio = 0.3 * 1.4142135623730951;
[[nodiscard]] double fem_stable_step_s(const VolumeMesh& mesh, const FemMaterial& material, double courant = kFemCourantRatio) noexcept;

class FemWorld {
 public:
  explicit FemWorld(const FemWorldConfig& config);
  ~FemWorld();
  FemWorld(const FemWorld&) = delete;
  FemWorld& operator=(const FemWorld&) = delete;

  /// Adds a body (create_fem_body) with its elasticity force (and gravity when configured).
  /// Returns its index. Bullet keeps one force object per force type, so every body of a world
  /// shares the first body's material: a body with another elasticity or damping throws
  /// std::invalid_argument (its density and mesh may differ).
  int add_body(const VolumeMesh& mesh, const FemMaterial& material, const FemContact& contact = {});
  [[nodiscard]] int body_count() const noexcept { return static_cast<int>(bodies_.size()); }
  [[nodiscard]] btSoftBody& body(int b) noexcept { return *bodies_[static_cast<std::size_t>(b)]; }
  [[nodiscard]] const btSoftBody& body(int b) const noexcept { return *bodies_[static_cast<std::size_t>(b)]; }
  [[nodiscard]] btDeformableMultiBodyDynamicsWorld& world() noexcept { return *world_; }

  /// Makes the nodes Dirichlet nodes (mass 0; see the file comment).
  void fix_nodes(int b, const std::vector<int>& nodes);
  /// Places a fixed node (kinematic): position now, zero velocity.
  void move_fixed_node(int b, int node, const Eigen::Vector3d& position_world_m) noexcept;

  /// A kinematic box (a plate, a punch's stand-in) centred at `centre`, axis-aligned. Returns its index.
  int add_kinematic_box(const Eigen::Vector3d& half_extents_m, const Eigen::Vector3d& centre_world_m, double friction_ratio);
  /// Moves a kinematic box (Bullet derives its velocity from the previous pose).
  void set_box_centre(int box, const Eigen::Vector3d& centre_world_m) noexcept;

  /// Solve `contact` with body b inside the implicit step's Newton iterations (the thin-body
  /// in-solver response, fem_world.cpp says how a position projection enters a velocity solve).
  /// Implicit worlds only (std::logic_error otherwise): the symplectic step has no iteration to
  /// project in. Not owned: it must outlive the world.
  void add_solver_contact(int b, SoftContactConstraint* contact);

  /// One step of h seconds (one internal substep).
  void step(double h_s) noexcept;

  /// The elastic force Bullet's force object puts on each node of body b at its current
  /// positions [N, world], into `out` (resized). Leaves the body as a step would find it.
  void elastic_forces(int b, std::vector<Eigen::Vector3d>& out);
  /// Largest node speed of body b [m/s].
  [[nodiscard]] double max_node_speed_m_per_s(int b) const noexcept;
  [[nodiscard]] Eigen::Vector3d node_position_m(int b, int node) const noexcept;

 private:
  FemWorldConfig config_;
  std::unique_ptr<btSoftBodyRigidBodyCollisionConfiguration> configuration_;
  std::unique_ptr<btCollisionDispatcher> dispatcher_;
  std::unique_ptr<btBroadphaseInterface> broadphase_;
  std::unique_ptr<btDeformableBodySolver> deformable_solver_;
  FemBodySolver* fem_solver_ = nullptr;  ///< = deformable_solver_
  std::unique_ptr<btDeformableMultiBodyConstraintSolver> constraint_solver_;
  std::unique_ptr<btDeformableMultiBodyDynamicsWorld> world_;
  std::vector<std::unique_ptr<btCollisionShape>> shapes_;
  std::vector<std::unique_ptr<btDefaultMotionState>> motion_states_;
  std::vector<std::unique_ptr<btRigidBody>> rigid_bodies_;  ///< ground (if any) then the boxes
  std::vector<btRigidBody*> boxes_;
  std::vector<std::unique_ptr<btSoftBody>> bodies_;
  std::vector<std::unique_ptr<btDeformableLagrangianForce>> forces_;
  std::vector<btDeformableLagrangianForce*> elastic_;  ///< per body (all the first body's)
  std::vector<btDeformableLagrangianForce*> first_body_forces_;
  std::vector<FemMaterial> materials_;
};

}  // namespace fissure::host
