// host_sim/src/node_bounds_solver.cpp: Bullet's soft-body solve with the node bounds fused into
// its velocity update must be Bullet's solve bit for bit, and its bounds must hold every node's
// start (m_q) and end (m_x) position of the step — tightly, as Bullet left them. And the whole
// paired simulation driven by those bounds must be the simulation that reads every node.
#include "fissure/host_sim/node_bounds_solver.hpp"

#include <gtest/gtest.h>

#include <BulletSoftBody/btSoftBody.h>

#include <algorithm>
#include <cstring>
#include <string>

#include "fissure/host_sim/host_simulation.hpp"
#include "fissure/host_sim/scene_loader.hpp"
#include "fissure/host_sim/soft_world.hpp"

namespace fissure::host {
namespace {

bool same_bits(const btVector3& a, const btVector3& b) { return std::memcmp(a.m_floats, b.m_floats, 3 * sizeof(btScalar)) == 0; }

// Steps two worlds of the same scene (tool not in Bullet: the paired / ray setting), one solved by
// a NodeBoundsSolver and one by Bullet's stock solver, and checks after every step that every
// node's m_x, m_q and m_v are the same bits and that the bounds are exactly those of m_q ∪ m_x.
void expect_same_world_and_exact_bounds(const std::string& scene_file, int steps) {
  const SceneDescription scene = load_scene(scene_file);
  SoftWorld ours(scene, false, true);
  SoftWorld stock(scene, false, false);
  ASSERT_EQ(ours.soft_body_count(), static_cast<int>(scene.soft_bodies.size()));
  for (int body = 0; body < ours.soft_body_count(); ++body) {
    ASSERT_NE(ours.node_bounds(body), nullptr);
    ASSERT_EQ(stock.node_bounds(body), nullptr);
  }
  const double h = scene.simulation.time_step_s / scene.simulation.substeps_count;
  for (int s = 0; s < steps; ++s) {
    ours.step(h);
    stock.step(h);
    for (int body = 0; body < ours.soft_body_count(); ++body) {
      const btSoftBody& a = ours.soft(body);
      const btSoftBody& b = stock.soft(body);
      const SoftNodeBounds& bounds = *ours.node_bounds(body);
      const std::string where = scene_file + " body " + std::to_string(body) + " step " + std::to_string(s);
      ASSERT_TRUE(bounds.valid) << where;
      ASSERT_EQ(bounds.node_count, a.m_nodes.size());
      const btVector3 large(BT_LARGE_FLOAT, BT_LARGE_FLOAT, BT_LARGE_FLOAT);
      btVector3 all_lo = large, all_hi = -large;
      for (int blk = 0; blk < bounds.block_count(); ++blk) {
        btVector3 lo = large, hi = -large;
        const int first = blk * SoftNodeBounds::kNodesPerBlock;
        const int last = std::min(a.m_nodes.size(), first + SoftNodeBounds::kNodesPerBlock);
        for (int i = first; i < last; ++i) {
          const btSoftBody::Node& n = a.m_nodes[i];
          ASSERT_TRUE(same_bits(n.m_x, b.m_nodes[i].m_x)) << where << " node " << i << ": m_x";
          ASSERT_TRUE(same_bits(n.m_q, b.m_nodes[i].m_q)) << where << " node " << i << ": m_q";
          ASSERT_TRUE(same_bits(n.m_v, b.m_nodes[i].m_v)) << where << " node " << i << ": m_v";
          lo.setMin(n.m_x), lo.setMin(n.m_q), hi.setMax(n.m_x), hi.setMax(n.m_q);
        }
        ASSERT_TRUE(same_bits(lo, bounds.block_lo[static_cast<std::size_t>(blk)])) << where << " block " << blk;
        ASSERT_TRUE(same_bits(hi, bounds.block_hi[static_cast<std::size_t>(blk)])) << where << " block " << blk;
        all_lo.setMin(lo), all_hi.setMax(hi);
      }
      ASSERT_TRUE(same_bits(all_lo, bounds.all_lo) && same_bits(all_hi, bounds.all_hi)) << where;
    }
  }
}

// The sphere drops onto the ground and bounces (ground contacts in the position solve); the
// vessel is anchored to the ground (Bullet anchors, [[soft_body.anchor]]); the fissure's two
// lobes ([[soft_body]]) settle side by side, each solved and bounded by the same solver.
TEST(NodeBoundsSolver, IsBulletsOwnSolveBitForBitWithExactBounds) {
  expect_same_world_and_exact_bounds("scenes/spatula-sphere.toml", 400);
  expect_same_world_and_exact_bounds("scenes/clamp-vessel.toml", 200);
  expect_same_world_and_exact_bounds("scenes/spatula-fissure.toml", 200);
}

TEST(NodeBoundsSolver, ABodyItCannotReproduceGetsTheStockSolveAndNoBounds) {
  const SceneDescription scene = load_scene("scenes/spatula-sphere.toml");
  SoftWorld ours(scene, false, true);
  SoftWorld stock(scene, false, false);
  // Drift iterations rewrite m_q after the velocity update: the fused path does not apply.
  ours.soft().m_cfg.diterations = 1;
  stock.soft().m_cfg.diterations = 1;
  for (int s = 0; s < 50; ++s) {
    ours.step(scene.simulation.time_step_s);
    stock.step(scene.simulation.time_step_s);
    EXPECT_FALSE(ours.node_bounds()->valid);
  }
  for (int i = 0; i < ours.soft().m_nodes.size(); ++i) ASSERT_TRUE(same_bits(ours.soft().m_nodes[i].m_x, stock.soft().m_nodes[i].m_x)) << i;
}

// The whole host step, paired, with the broad phase reading the solver's bounds vs reading every
// node: the same forces and node positions, bit for bit, through plunges, holds and a squeeze —
// including the clamp, whose second jaw's broad phase runs after the first jaw moved nodes.
void expect_same_simulation(const SceneDescription& scene, double seconds) {
  const std::string& scene_file = scene.name;
  HostSimulation with_bounds(scene, SceneCollisionMethod::kPaired, HostSimulationOptions{true});
  HostSimulation scanning(scene, SceneCollisionMethod::kPaired, HostSimulationOptions{false});
  ASSERT_NE(with_bounds.world().node_bounds(), nullptr);
  ASSERT_EQ(scanning.world().node_bounds(), nullptr);
  with_bounds.settle(0.2);
  scanning.settle(0.2);
  const int steps = static_cast<int>(seconds / scene.simulation.time_step_s);
  int contact_steps = 0;
  for (int s = 0; s < steps; ++s) {
    const TrajectorySample target = with_bounds.scripted_target();
    const HostStepResult& a = with_bounds.step(to_tool_pose(target.pose), target.jaw_gap_m);
    const HostStepResult& b = scanning.step(to_tool_pose(target.pose), target.jaw_gap_m);
    ASSERT_EQ(a.force_on_tool_world_n, b.force_on_tool_world_n) << scene_file << " step " << s;
    ASSERT_EQ(a.contact_count, b.contact_count) << scene_file << " step " << s;
    ASSERT_EQ(with_bounds.node_positions_world_m(), scanning.node_positions_world_m()) << scene_file << " step " << s;
    contact_steps += a.contact_count > 0 ? 1 : 0;
  }
  EXPECT_GT(contact_steps, steps / 10) << scene_file << ": the comparison must cover contact";
}

TEST(NodeBoundsSolver, PairedSimulationIsTheSameWithTheSolversBounds) {
  expect_same_simulation(load_scene("scenes/spatula-sphere.toml"), 1.5);
  // The in-solver response needs the bounding solver, so it has no scanning twin: the clamp and
  // the two bodies (each with its own bounds) run the response after the step, without friction.
  SceneDescription clamp = load_scene("scenes/clamp-sphere.toml");
  clamp.simulation.contact_response = ContactResponse::kAfterStep;
  clamp.tool.friction_static_ratio = clamp.tool.friction_kinetic_ratio = 0.0;
  expect_same_simulation(clamp, 2.0);
  SceneDescription fissure = load_scene("scenes/spatula-fissure.toml");
  fissure.simulation.contact_response = ContactResponse::kAfterStep;
  expect_same_simulation(fissure, 2.0);
}

// A contact solved with the body (the in-solver response's hook): begin_solve once per step on
// Bullet's prediction with valid bounds of it, project after every position iteration; a contact
// that moves nothing leaves the solve bit for bit Bullet's own.
class CountingContact final : public SoftContactConstraint {
 public:
  explicit CountingContact(const SoftNodeBounds& bounds) : bounds_(bounds) {}
  void begin_solve(btSoftBody& soft) override {
    ++begins;
    bounds_valid_at_begin = bounds_valid_at_begin && bounds_.valid;
    // The bounds handed to the detection hold every node's start and predicted end.
    for (int i = 0; i < soft.m_nodes.size(); ++i) {
      const btSoftBody::Node& n = soft.m_nodes[i];
      const auto b = static_cast<std::size_t>(i / SoftNodeBounds::kNodesPerBlock);
      for (int k = 0; k < 3; ++k) {
        const bool inside = bounds_.block_lo[b][k] <= std::min(n.m_x[k], n.m_q[k]) && std::max(n.m_x[k], n.m_q[k]) <= bounds_.block_hi[b][k];
        bounds_hold_prediction = bounds_hold_prediction && inside;
      }
    }
  }
  void project(btSoftBody& /*soft*/) override { ++projections; }
  int begins = 0, projections = 0;
  bool bounds_valid_at_begin = true, bounds_hold_prediction = true;

 private:
  const SoftNodeBounds& bounds_;
};

TEST(NodeBoundsSolver, AContactIsSolvedInsideThePositionIterationsAndANoOpOneChangesNothing) {
  const SceneDescription scene = load_scene("scenes/spatula-sphere.toml");
  SoftWorld ours(scene, false, true);
  SoftWorld stock(scene, false, false);
  CountingContact contact(*ours.node_bounds());
  ours.node_bounds_solver()->add_contact(&contact);
  const int steps = 100;
  for (int s = 0; s < steps; ++s) {
    ours.step(scene.simulation.time_step_s);
    stock.step(scene.simulation.time_step_s);
  }
  EXPECT_EQ(contact.begins, steps);
  EXPECT_EQ(contact.projections, steps * ours.soft().m_cfg.piterations);
  EXPECT_TRUE(contact.bounds_valid_at_begin);
  EXPECT_TRUE(contact.bounds_hold_prediction);
  for (int i = 0; i < ours.soft().m_nodes.size(); ++i) {
    ASSERT_TRUE(same_bits(ours.soft().m_nodes[i].m_x, stock.soft().m_nodes[i].m_x)) << i;
    ASSERT_TRUE(same_bits(ours.soft().m_nodes[i].m_v, stock.soft().m_nodes[i].m_v)) << i;
  }
  ours.node_bounds_solver()->clear_contacts();
}

}  // namespace
}  // namespace fissure::host
