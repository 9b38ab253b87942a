#pragma once
// Bounds of every soft node's start and end position of the current Bullet step, kept by the
// soft-body solver itself, so that the thin-body collision's broad phase can skip what is far
// from the tool without reading every node (BRIEF §3 item 6: "nothing when out of contact").
//
// Why inside Bullet's solve: the broad phase must be exact with respect to the positions the
// collision uses — m_q (start of the step) and m_x (end) AFTER Bullet's pose matching and
// constraint solver, which move nodes 10-25 mm after Bullet refits its own node tree
// (broad_phase.cpp's header). The last thing btSoftBody::solveConstraints does to the nodes is a
// loop that reads exactly those two positions of every node (the velocity update
// v = (m_x − m_q)·(1 − kDP)/h). NodeBoundsSolver runs Bullet's solve with that loop taken over
// and the bounds fused into it: one pass over the nodes instead of two. A separate pass after
// the solve costs what the broad phase's own scan costs (+38-48 µs a step on 10 242 nodes), since
// the nodes are cold again by then.
//
// The simulation is bit-identical to Bullet's own solver (tests/host_sim/node_bounds_solver_test.cpp):
// the same solvers run in the same order on the same data; only the no-op cluster passes move
// relative to the position iterations, and the solver falls back to the stock path (bounds
// invalid) for a body whose solve it cannot reproduce that way (clusters, drift iterations).
#include <memory>
#include <vector>

#include <BulletSoftBody/btDefaultSoftBodySolver.h>
#include <LinearMath/btVector3.h>

class btSoftBody;

namespace fissure::host {

struct SoftNodeBounds {
  // Nodes per block (consecutive node indices). The icosphere and slab builders emit nodes in
  // a spatially coherent order (subdivision / grid order), so a block is a small patch of the
  // surface; 32 keeps the per-block test (one box) well under the nodes' own cost. Bullet's
  // CreateEllipsoid order is not (on a 5120-face ellipsoid every block spans most of the ball,
  // so the broad phase reads every node as before); only the 128-face paper ball (66 nodes)
  // uses it in the scenes and benchmarks.
  static constexpr int kNodesPerBlock = 32;

  // True from the solve that computed the bounds until the next solve starts; writers of node
  // positions between the solve and the collision must extend() (enforced displacement, re-seat).
  bool valid = false;
  btVector3 all_lo{0, 0, 0}, all_hi{0, 0, 0};       // every node's m_q and m_x (world, m)
  std::vector<btVector3> block_lo, block_hi;        // per block of kNodesPerBlock nodes
  int node_count = 0;

  [[nodiscard]] int block_count() const noexcept { return static_cast<int>(block_lo.size()); }
  // A node was moved to `position_world_m` after the solve: its block and the whole-body box take
  // it in (the bounds only ever grow, so they stay conservative).
  void extend(int node, const btVector3& position_world_m) noexcept {
    const auto b = static_cast<std::size_t>(node / kNodesPerBlock);
    block_lo[b].setMin(position_world_m);
    block_hi[b].setMax(position_world_m);
    all_lo.setMin(position_world_m);
    all_hi.setMax(position_world_m);
  }
};

// A contact solved inside the attached body's position iterations (the thin-body collision's
// in-solver response, issue 22): Bullet's links, anchors and rigid contacts and this contact are
// iterated together, so they converge together in every step.
class SoftContactConstraint {
 public:
  virtual ~SoftContactConstraint() = default;
  // After Bullet's prediction (m_q: start of the step, m_x: predicted end) and before the position
  // iterations, with the bounds of both valid: decide this step's contacts and place their nodes.
  virtual void begin_solve(btSoftBody& soft) = 0;
  // After every position iteration: put the contacts' nodes back where the contact allows them.
  virtual void project(btSoftBody& soft) = 0;
  // After the solve's velocity update (m_v = (m_x − m_q)/h): what the contact's projections should
  // not leave in the velocity.
  virtual void end_solve(btSoftBody& /*soft*/) {}
};

class NodeBoundsSolver : public btDefaultSoftBodySolver {
 public:
  NodeBoundsSolver() = default;
  NodeBoundsSolver(const NodeBoundsSolver&) = delete;
  NodeBoundsSolver& operator=(const NodeBoundsSolver&) = delete;
  ~NodeBoundsSolver() override;

  // Keep bounds for this body and solve its contacts; returns its index for bounds() and
  // add_contact() (a scene's bodies in their order). A body not attached gets Bullet's stock solve.
  int attach(btSoftBody* soft);
  [[nodiscard]] int attached_count() const noexcept { return static_cast<int>(bodies_.size()); }
  // The bounds of attached body `body` (stable address: the collisions keep a pointer).
  [[nodiscard]] SoftNodeBounds& bounds(int body = 0) noexcept { return bodies_[static_cast<std::size_t>(body)]->bounds; }
  // Solve `contact` with attached body `body`, in the order added (a clamp: one per jaw). Not
  // owned: it must outlive the solver or be removed by clear_contacts().
  void add_contact(SoftContactConstraint* contact, int body = 0) { bodies_[static_cast<std::size_t>(body)]->contacts.push_back(contact); }
  void clear_contacts() noexcept;

  void solveConstraints(btScalar solver_dt) override;

 private:
  struct AttachedBody {
    btSoftBody* soft = nullptr;
    SoftNodeBounds bounds;
    std::vector<SoftContactConstraint*> contacts;
  };
  void solve_with_bounds(AttachedBody& body);
  // The bounds of every node's m_q and m_x; with `velocity_update` Bullet's velocity update is
  // fused into the same pass (node_bounds_solver.cpp).
  static void take_bounds(btSoftBody& soft, SoftNodeBounds& bounds, bool velocity_update);

  std::vector<std::unique_ptr<AttachedBody>> bodies_;
};

}  // namespace fissure::host
