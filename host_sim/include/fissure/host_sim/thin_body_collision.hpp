#pragma once
// Paired-node thin-body collision (BRIEF §3; the paper's core) and its ray-only variant.
//
// Call order (the world owns it): every host step
//   1. move the tool's kinematic body to `current` and call world.stepSimulation(dt, 1, dt)
//      (ONE Bullet substep per collision step — the soft body's btSoftBody::Node::m_q then holds
//      each node's position at the start of the step, which the sweep uses; keep
//      m_cfg.diterations = 0, Bullet's default, because drift iterations overwrite m_q);
//   2. collision.step(previous, current, dt, soft, result): detects, writes enforced
//      displacements into soft.m_nodes[i].m_x / m_v, and computes the Hunt-Crossley force.
// The tool's rigid body must NOT also collide with the soft body through Bullet (no SDF_RS contact
// between them) for the paired / ray methods.
#include <fissure/host_sim/scene_description.hpp>
#include <fissure/host_sim/thin_tool.hpp>

#include <Eigen/Core>

#include <memory>
#include <vector>

class btSoftBody;

namespace fissure::host {

struct SoftNodeBounds;         // node_bounds_solver.hpp
class SoftContactConstraint;  // node_bounds_solver.hpp

struct ThinBodyCollisionParams {
  HuntCrossleyParams hunt_crossley;
  // Gap left between a displaced soft node and the tool face (keeps nodes strictly outside the
  // tool in float precision; Bullet's soft body here is single precision).
  double skin_m = 1.0e-6;
  // A tool node within this distance in front of a soft triangle counts as touching it (keeps a
  // resting contact from flickering at slow speeds).
  double contact_distance_m = 1.0e-5;
  // A soft node held on the tool stays a colliding node until it separates from the tool face by
  // more than this: hysteresis against contact-set chatter when the soft body's own dynamics lift
  // a held node. Under normal_displacement its force share ramps (smoothstep) from 1 on the face
  // to 0 here, so this is also the width over which a separating node's force fades: 2 mm keeps
  // the share's slope small against a held tool's ±40 µm encoder dither (0.2 mm puts ~7 N/mm
  // of extra stiffness on the coarse ball: force steps of 15 % per dither step).
  double release_distance_m = 2.0e-3;
  // after_step: a held node behind its plane is released, and the tool face is frictionless:
  // putting such a node back on the face, or Coulomb friction between a held node and the face,
  // make the bench's paired hold cells and the proxy tests worse (docs/decisions.md, "Held soft
  // nodes"). in_solver has its own friction (friction_*_ratio below).
  // ẋ is a finite difference of x filtered by a first-order low-pass with this cut-off
  // (time constant 1/(2π·fc), i.e. ≈1.6 ms lag at 100 Hz).
  double velocity_filter_cutoff_hz = 100.0;
  // normal_displacement: a soft node that joins a triangle's contact brings its force in over this
  // time (its share × a ramp 0 → 1), as a leaving node fades over release_distance. A joining node
  // comes with its whole x = n·(q − p_rest) at once — on the coarse shell 5–30 mm for a node
  // carried round a rim — and one node's membership moved the held force by 5–50 %; a node that
  // flickers in and out of the set every other step (a straddling triangle at a blade's edge)
  // then adds ≤ h/ramp of its share. 10 ms: 1 mm of travel at 0.1 m/s; measured against 5 / 20 ms
  // in docs/decisions.md ("Contact inside the solver", 2026-12-07 third session).
  double contact_onset_ramp_s = 0.010;
  // Reported in ContactRecord::jaw so that a clamp can run one instance per jaw.
  int jaw = 0;
  // Where the response acts (scene_description.hpp): after Bullet's step (the call order above)
  // or inside its position iterations (solver_contact(), prepare_step()).
  ContactResponse response = ContactResponse::kAfterStep;
  // In-solver: soft faces this much beyond contact_distance from the tool (at the predicted
  // positions) are candidates too, so that a node the solver's iterations pull towards the tool
  // is projected out of it. 1 mm: a link pulls a node at most its share of the held nodes'
  // displacement in one step; the hold-and-sweep tests check no node ends inside.
  double solver_reach_m = 1.0e-3;
  // In-solver: Coulomb friction of a held node on its tool face, at position level (Macklin et al.
  // 2014, "Unified particle physics", §6.1), against the node's own Hunt-Crossley normal force
  // F_n (the elastic part the force stage gives it, s_v·(w_v)·k·x_vⁿ): within one step the node's
  // tangential move relative to the tool is undone while that costs at most static × F_n·h²/m
  // (the friction impulse within the cone of the normal impulse F_n·h), else undone by kinetic ×
  // F_n·h²/m only (sliding on the cone). So the friction the solver applies and the friction the
  // tool feels (CollisionStepResult::friction_force_on_tool_world_n, m·correction/h²) obey one
  // Coulomb law of the rendered normal force. 0: frictionless.
  double friction_static_ratio = 0.0;
  double friction_kinetic_ratio = 0.0;
  // In-solver, with friction: viscous shear of the contact per unit of contact area [Pa·s/m =
  // N·s/m³] (SceneDescription's tool.friction_shear_damping_pa_s_per_m). A sliding node's slip
  // beyond the kinetic cone meets b = this × its rest area, applied implicitly (the share
  // β/(1+β) of that slip is undone, β = b·h/m), so it is stable at any value and never reverses
  // the slip. Why: a discrete node on springs sliding under a slowly moving face sticks and slips
  // step to step, and its average friction falls below μ_k·F_n (docs/decisions.md, "Friction and
  // grasp"); a continuum with a lubricated contact slides steadily. 0: Coulomb only.
  double friction_shear_damping_pa_s_per_m = 0.0;
};

// One contacted soft triangle (what the proxy builder needs: a plane per contact, which tool face
// / jaw it is on, and this triangle's share of the force).
struct ContactRecord {
  int soft_face = -1;                 // index into btSoftBody::m_faces
  int tool_node = -1;                 // leading tool node that hit it this step on tool_plane (-1: none —
                                      // in the set because one of its soft nodes is colliding)
  int tool_plane = -1;                // tool face (index into ToolNodes::planes()) its colliding node is held on
  int jaw = 0;                        // ThinBodyCollisionParams::jaw
  Eigen::Vector3d point_world_m = Eigen::Vector3d::Zero();   // triangle centroid after the response (in_solver rim contact: the deepest rim point)
  Eigen::Vector3d normal_world = Eigen::Vector3d::Zero();    // tool face outward normal (world)
  double penetration_m = 0.0;         // HC deformation x. centroid_distance: |centroid − rest centroid|;
                                      // normal_displacement: the share-weighted n-mean of its colliding
                                      // vertices' x_v, (Σ s_v·x_vⁿ / Σ s_v)^(1/n), so that
                                      // weight·k·penetrationⁿ = this triangle's elastic force
  double penetration_rate_m_s = 0.0;  // filtered ẋ (normal_displacement: Σ s_v·x_vⁿ·ẋ_v / Σ s_v·x_vⁿ)
  double weight = 1.0;                // per-unit-area mode: contacted share of the rest area (m²) = rest
                                      // area × (Σ colliding-vertex shares s_v / 3; centroid_distance:
                                      // s_v = 1); per-triangle mode: the same without the area
  double force_n = 0.0;               // this triangle's HC force magnitude (≥ 0)
  int soft_body = 0;                  // which of the scene's soft bodies soft_face belongs to (HostSimulation sets it)
};

struct CollisionStepResult {
  Eigen::Vector3d force_on_tool_world_n = Eigen::Vector3d::Zero();  // normal (Hunt-Crossley) + friction
  Eigen::Vector3d friction_force_on_tool_world_n = Eigen::Vector3d::Zero();  // of which friction (in_solver with friction)
  int sticking_nodes = 0;         // in_solver friction: held nodes whose tangential move friction undid whole this step ...
  int sliding_nodes = 0;          // ... and those that slid on the cone's boundary
  std::vector<ContactRecord> contacts;  // reserved once by reserve_for(), reused (no allocation)
  int colliding_tool_nodes = 0;   // tool nodes in contact after the exclusion
  int excluded_pairs = 0;         // tool nodes excluded as the non-leading node of a pair in contact
  int both_face_contacts = 0;     // pairs with both nodes pushing (always 0 for paired; ray's instability)
  int contacted_triangles = 0;    // triangles with a colliding soft node (= contacts.size())
  int displaced_soft_nodes = 0;   // soft nodes written by the enforced displacement
  int guard_corrections = 0;      // soft nodes the swept soft-node guard had to put back (paired only); in_solver:
                                  // plus the projections of the position iterations (a node moved twice counts twice)
  bool broad_phase_hit = false;
  double seconds_broad = 0.0;
  double seconds_narrow = 0.0;
  double seconds_response = 0.0;
  double seconds_force = 0.0;
  double seconds_in_solver = 0.0;  // in_solver: of the above, what ran inside Bullet's solve (detection, placement, projections)

  // Reserve capacity for a soft body with this many faces (call once, before the loop).
  void reserve_for(int soft_face_count) { contacts.reserve(static_cast<std::size_t>(soft_face_count)); }
};

class ThinBodyCollision {
 public:
  virtual ~ThinBodyCollision();
  ThinBodyCollision() = default;
  ThinBodyCollision(const ThinBodyCollision&) = delete;
  ThinBodyCollision& operator=(const ThinBodyCollision&) = delete;

  // One collision step (see the call order above). `soft` must be the body given at
  // construction. Does not allocate once `out.reserve_for(faces)` has been called.
  virtual void step(const ToolPose& previous, const ToolPose& current, double dt_s, btSoftBody& soft,
                    CollisionStepResult& out) = 0;
  // Re-take the rest state (rest centroids for x) from the body's current positions, e.g. after
  // letting it settle under gravity, so that x = 0 at the settled shape.
  virtual void reset_rest_state(const btSoftBody& soft) = 0;
  // The tool was re-seated (HostSimulation::reseat_tool) from `previous` to `current` without
  // moving through the space between (a position rt_core marked as not continuous: an accepted
  // encoder jump, the first sample after a device fault). Nothing of the previous pose may act on
  // the next step, so this forgets the tool nodes' contacts, the soft nodes' side memory (held on
  // which face, where) and the ẋ filters — kept, a node held on a face before the re-seat is put
  // back on that face at the new pose, from wherever it now is. And it puts every free soft node
  // that lies inside the tool at `current` out onto a face (+ skin_m), so that the step after
  // starts with none inside: of the faces at most a tool thickness away, the one the node was
  // furthest in front of at `previous` — for a short re-seat (the hand moved on during a few
  // dropped replies) the side it was really on, where a sweep would have put it too; the
  // nearest face would put a node the tool advanced past its mid-plane on the far side, through
  // the tool. Returns the number of nodes put out. Does not allocate.
  virtual int reseat(const ToolPose& previous, const ToolPose& current, btSoftBody& soft) = 0;
  [[nodiscard]] virtual SceneCollisionMethod method() const = 0;

  // In-solver response only (params.response == kInSolver): the constraint the world's
  // NodeBoundsSolver solves with the body (null for after_step), and the poses of the coming
  // Bullet step, given before it; step() after Bullet's step then reads the solved state and
  // computes the force (it places nothing).
  [[nodiscard]] virtual SoftContactConstraint* solver_contact() noexcept = 0;
  virtual void prepare_step(const ToolPose& previous, const ToolPose& current, double dt_s) = 0;
};

// The soft body must have triangle faces (btSoftBody::m_faces); its rest state (rest centroids,
// rest areas) is taken from its positions now. The closed-surface orientation (outward normals) is
// detected from the signed volume; an open sheet's outward side is the side its face normals
// (Bullet's winding) point to. Throws std::invalid_argument on a body without faces.
// `node_bounds`: the node bounds a NodeBoundsSolver keeps for `soft` (SoftWorld::node_bounds()),
// read by the broad phase instead of every node, and extended by every position the collision
// writes. Null: the broad phase reads every node (a world with Bullet's stock solver).
std::unique_ptr<ThinBodyCollision> make_paired_collision(const ToolNodes& tool, const btSoftBody& soft,
                                                         const ThinBodyCollisionParams& params, SoftNodeBounds* node_bounds = nullptr);
// The same detection without the pairing / exclusion step and without the soft-node side memory:
// every tool node in contact places its triangle on its own face (paper Fig. 3 right).
std::unique_ptr<ThinBodyCollision> make_ray_collision(const ToolNodes& tool, const btSoftBody& soft,
                                                      const ThinBodyCollisionParams& params, SoftNodeBounds* node_bounds = nullptr);

}  // namespace fissure::host
