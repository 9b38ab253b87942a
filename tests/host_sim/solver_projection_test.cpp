// In-solver Coulomb friction in isolation (solver_projection.cpp): a slab node held on a plate
// that presses into the slab, pulled along the face by a given move within one step. Inside the
// cone (static × its Hunt-Crossley normal force F_n × h²/m) the move is undone whole; beyond it,
// undone by kinetic × F_n·h²/m only, however many projection passes run; the force on the tool is
// m·correction/h² — exactly kinetic × F_n while sliding (plus the contact's viscous shear when it
// has one). And the swept guard after the solve: a
// node whose step path passes through the plate ends on the face that path enters by.
#include "../../host_sim/src/thin_body/collision_state.hpp"
#include "soft_scene_fixture.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace fissure::host::thin_body {
namespace {

constexpr double kSlabSide_m = 0.1;
constexpr int kSlabCells = 4;
constexpr double kPress_m = 0.002;       // the plate's face this far below the slab's rest surface
constexpr double kStep_s = 1e-3;
constexpr double kStatic = 0.5;
constexpr double kKinetic = 0.4;

CollisionModel slab_friction_model(test_scene::SoftWorld& world, const ToolNodes& tool) {
  world.add_slab(kSlabSide_m, kSlabCells);
  ThinBodyCollisionParams params;
  params.response = ContactResponse::kInSolver;
  params.friction_static_ratio = kStatic;
  params.friction_kinetic_ratio = kKinetic;
  return build_collision_model(tool, world.soft(), params, true);
}

struct FrictionFixture {
  test_scene::SoftWorld world{false};
  ToolNodes tool = test_scene::plate_tool(0.002);
  CollisionModel model = slab_friction_model(world, tool);
  CollisionData data;
  StepFrame frame;
  int node = -1;
  int plane = -1;

  FrictionFixture() {
    allocate_collision_data(model, data);
    // The middle node of the slab (x = z = 0), and the plate above it with its lower face
    // kPress_m below the node's rest position: the plate presses the slab down.
    const int middle = (kSlabCells / 2) * (kSlabCells + 1) + kSlabCells / 2;
    node = middle;
    ToolPose pose;
    pose.position_world_m = Eigen::Vector3d(0.0, 0.001 - kPress_m, 0.0);  // half thickness 1 mm
    data.step = 1;
    frame = make_step_frame(model, data.step, pose, pose, kStep_s);
    // The plate's lower face (outward normal −y in the tool frame = world).
    for (std::size_t q = 0; q < tool.planes().size(); ++q)
      if (tool.planes()[q].normal_tool.y() < -0.5) plane = static_cast<int>(q);
    data.broad.candidate_nodes.push_back(node);
    // Held on that face (+ skin), sticking where it is.
    const ToolPlane& face = tool.planes()[static_cast<std::size_t>(plane)];
    const Eigen::Vector3d on_face_tool = Eigen::Vector3d(0.0, 0.0, 0.0) + (face.offset_m + model.params.skin_m) * face.normal_tool;
    set_node_tool(on_face_tool);
    data.displacement.hold_stamp[static_cast<std::size_t>(node)] = data.step;
    data.displacement.hold_plane[static_cast<std::size_t>(node)] = plane;
    data.solver.friction_anchor_tool_m[static_cast<std::size_t>(node)] = on_face_tool;
    data.solver.friction_anchor_stamp[static_cast<std::size_t>(node)] = data.step - 1;
    start_iterates(model, frame, world.soft(), data);
  }

  void set_node_tool(const Eigen::Vector3d& p_tool) {
    const Eigen::Vector3d w = frame.r_cur * p_tool + frame.t_cur;
    world.soft().m_nodes[node].m_x = btVector3(static_cast<btScalar>(w.x()), static_cast<btScalar>(w.y()), static_cast<btScalar>(w.z()));
  }
  [[nodiscard]] Eigen::Vector3d node_tool() {
    const btVector3& x = world.soft().m_nodes[node].m_x;
    return frame.r_cur.transpose() * (Eigen::Vector3d(x.x(), x.y(), x.z()) - frame.t_cur);
  }
  [[nodiscard]] double normal_force_n() const {
    return held_node_normal_force(model, frame, node, tool.planes()[static_cast<std::size_t>(plane)], model.params.skin_m);
  }
  // The cone's length: F_n·h²/m.
  [[nodiscard]] double cone_m() { return normal_force_n() * kStep_s * kStep_s * world.soft().m_nodes[node].m_im; }
  // A link's pull along +x since the last projection, then `passes` projections.
  void pull_and_project(double pull_m, int passes) {
    set_node_tool(node_tool() + Eigen::Vector3d(pull_m, 0.0, 0.0));
    for (int i = 0; i < passes; ++i) project_contacts(model, frame, world.soft(), data);
  }
  [[nodiscard]] CollisionStepResult result() {
    CollisionStepResult out;
    friction_force_on_tool(model, frame, world.soft(), data, out);
    return out;
  }
};

TEST(SolverFriction, TheNormalForceIsTheNodesHuntCrossleyShare) {
  FrictionFixture f;
  // k·xⁿ over a third of the rest area of the node's faces, x = kPress_m (the share is 1 on the face).
  const HuntCrossleyParams& hc = f.model.params.hunt_crossley;
  ASSERT_GT(f.model.soft.node_rest_area_m2[static_cast<std::size_t>(f.node)], 0.0);
  const double area = f.model.soft.node_rest_area_m2[static_cast<std::size_t>(f.node)];
  const double expected = (hc.per_unit_area ? area : 2.0) * hc.k * std::pow(kPress_m, hc.n);
  EXPECT_NEAR(f.normal_force_n(), expected, 1e-9 * expected + 1e-3 * expected);
}

TEST(SolverFriction, APullInsideTheStaticConeIsUndoneWholeAndTheToolFeelsIt) {
  FrictionFixture f;
  ASSERT_GT(f.normal_force_n(), 0.0);
  const double pull = 0.5 * kStatic * f.cone_m();
  const Eigen::Vector3d anchor = f.node_tool();
  f.pull_and_project(pull, 1);
  EXPECT_NEAR((f.node_tool() - anchor).x(), 0.0, 1e-6 * pull + 1e-9);
  const CollisionStepResult r = f.result();
  EXPECT_EQ(r.sticking_nodes, 1);
  EXPECT_EQ(r.sliding_nodes, 0);
  // The tissue drags the node along +x; the tool feels the reaction along +x: m·pull/h².
  const double expected = pull / (f.world.soft().m_nodes[f.node].m_im * kStep_s * kStep_s);
  EXPECT_NEAR(r.friction_force_on_tool_world_n.x(), expected, 1e-3 * expected);
  EXPECT_NEAR(r.friction_force_on_tool_world_n.norm(), expected, 1e-3 * expected);
}

TEST(SolverFriction, BeyondTheConeTheNodeSlidesAndTheForceIsKineticTimesTheNormalForceWhateverThePasses) {
  for (const int passes : {1, 2, 8}) {
    FrictionFixture f;
    const double cone = f.cone_m();
    const double pull = 3.0 * kStatic * cone;
    const Eigen::Vector3d anchor = f.node_tool();
    f.pull_and_project(pull, passes);
    // Undone by kinetic × the cone once, not once per pass.
    EXPECT_NEAR((f.node_tool() - anchor).x(), pull - kKinetic * cone, 1e-4 * pull) << passes << " passes";
    const CollisionStepResult r = f.result();
    EXPECT_EQ(r.sliding_nodes, 1);
    EXPECT_NEAR(r.friction_force_on_tool_world_n.norm(), kKinetic * f.normal_force_n(), 1e-3 * kKinetic * f.normal_force_n())
        << passes << " passes";
  }
}

TEST(SolverFriction, PullsSpreadOverIterationsShareOneCone) {
  FrictionFixture f;
  const double cone = f.cone_m();
  // Four iterations each pull 0.2 × the static cone: together 0.8 of it (stick), then 0.8 more (slide).
  for (int i = 0; i < 4; ++i) f.pull_and_project(0.2 * kStatic * cone, 2);
  EXPECT_EQ(f.result().sticking_nodes, 1);
  for (int i = 0; i < 4; ++i) f.pull_and_project(0.2 * kStatic * cone, 2);
  const CollisionStepResult r = f.result();
  EXPECT_EQ(r.sliding_nodes, 1);
  EXPECT_NEAR(r.friction_force_on_tool_world_n.norm(), kKinetic * f.normal_force_n(), 1e-3 * kKinetic * f.normal_force_n());
}

// The contact's viscous shear (friction_shear_damping_pa_s_per_m): a sliding node's slip beyond the
// kinetic cone is undone by the implicit share β/(1+β), β = b·A·h/m; sticking is unchanged, the
// passes still share one correction, and the tool feels the whole correction.
TEST(SolverFriction, ShearDampingUndoesItsImplicitShareOfTheSlipBeyondTheKineticCone) {
  for (const double damping_pa_s_per_m : {1.0e3, 1.0e5, 1.0e9}) {
    for (const int passes : {1, 4}) {
      FrictionFixture f;
      f.model.params.friction_shear_damping_pa_s_per_m = damping_pa_s_per_m;
      const double cone = f.cone_m();
      const double im = f.world.soft().m_nodes[f.node].m_im;
      const double beta = damping_pa_s_per_m * f.model.soft.node_rest_area_m2[static_cast<std::size_t>(f.node)] * kStep_s * im;
      const double pull = 3.0 * kStatic * cone;
      const double undone = kKinetic * cone + beta / (1.0 + beta) * (pull - kKinetic * cone);
      const Eigen::Vector3d anchor = f.node_tool();
      f.pull_and_project(pull, passes);
      const double kept = (f.node_tool() - anchor).x();
      EXPECT_NEAR(kept, pull - undone, 1e-4 * pull) << damping_pa_s_per_m << " Pa·s/m, " << passes << " passes";
      // It slows the slip, never reverses it.
      EXPECT_GE(kept, -1e-9);
      const CollisionStepResult r = f.result();
      EXPECT_EQ(r.sliding_nodes, 1);
      EXPECT_NEAR(r.friction_force_on_tool_world_n.norm(), undone / (im * kStep_s * kStep_s), 1e-3 * undone / (im * kStep_s * kStep_s));
      EXPECT_GT(r.friction_force_on_tool_world_n.norm(), kKinetic * f.normal_force_n());
    }
  }
  // Inside the static cone the node sticks whatever the damping.
  FrictionFixture f;
  f.model.params.friction_shear_damping_pa_s_per_m = 1.0e5;
  const Eigen::Vector3d anchor = f.node_tool();
  f.pull_and_project(0.5 * kStatic * f.cone_m(), 1);
  EXPECT_NEAR((f.node_tool() - anchor).x(), 0.0, 1e-9);
  EXPECT_EQ(f.result().sticking_nodes, 1);
}

TEST(SolverFriction, NoIndentationNoFriction) {
  FrictionFixture f;
  // The plate's face at the node's rest position (x = 0): no normal force, so no cone.
  ToolPose pose;
  pose.position_world_m = Eigen::Vector3d(0.0, 0.001, 0.0);
  f.frame = make_step_frame(f.model, f.data.step, pose, pose, kStep_s);
  EXPECT_DOUBLE_EQ(f.normal_force_n(), 0.0);
  f.pull_and_project(1e-4, 1);
  EXPECT_TRUE(f.result().friction_force_on_tool_world_n.isZero(0.0));
}


// The swept guard: the plate (40 × 2 × 40 mm, tool frame = world) stands still; a slab node
// started 1 mm beside its +x side face, level with its middle, and the solve left it 0.5 mm above
// the top face, 2 mm in from the corner — each position clear of the plate, the straight path
// between them through the corner.
struct SweptGuardFixture {
  test_scene::SoftWorld world{false};
  ToolNodes tool = test_scene::plate_tool(0.002);
  CollisionModel model = slab_friction_model(world, tool);
  CollisionData data;
  StepFrame frame;
  int node = 0;
  Eigen::Vector3d start{0.021, 0.0, 0.0};

  SweptGuardFixture() {
    allocate_collision_data(model, data);
    ToolPose pose;
    data.step = 1;
    frame = make_step_frame(model, data.step, pose, pose, kStep_s);
    world.soft().m_sst.isdt = static_cast<btScalar>(1.0 / kStep_s);
    data.broad.candidate_nodes.push_back(node);
    data.broad.start_tool_m[static_cast<std::size_t>(node)] = start;
    world.soft().m_nodes[node].m_q = btVector3(static_cast<btScalar>(start.x()), 0, 0);
  }
  void end_at(const Eigen::Vector3d& p) { world.soft().m_nodes[node].m_x = btVector3(static_cast<btScalar>(p.x()), static_cast<btScalar>(p.y()), static_cast<btScalar>(p.z())); }
  [[nodiscard]] Eigen::Vector3d end() {
    const btVector3& x = world.soft().m_nodes[node].m_x;
    return {x.x(), x.y(), x.z()};
  }
};

TEST(SweptGuard, ANodeCarriedRoundTheCornerEndsOnTheFaceItsPathEntersBy) {
  SweptGuardFixture f;
  const Eigen::Vector3d over_the_top(0.018, 0.0015, 0.0);
  ASSERT_FALSE(segment_clears_tool(f.tool.planes(), f.start, over_the_top));
  f.end_at(over_the_top);
  EXPECT_EQ(guard_swept_paths(f.model, f.frame, f.world.soft(), f.data, nullptr), 1);
  const Eigen::Vector3d end = f.end();
  // The +x side face's plane (x = 20 mm) + skin, the rest of the move kept.
  EXPECT_NEAR(end.x(), 0.02 + f.model.params.skin_m, 1e-6);
  EXPECT_NEAR(end.y(), 0.0015, 1e-6);
  EXPECT_TRUE(segment_clears_tool(f.tool.planes(), f.start, end));
  const auto n = static_cast<std::size_t>(f.node);
  EXPECT_EQ(f.data.displacement.hold_stamp[n], f.data.step);
  EXPECT_GT(f.tool.planes()[static_cast<std::size_t>(f.data.displacement.hold_plane[n])].normal_tool.x(), 0.99);
  // The velocity Bullet derives, from the new end.
  const btSoftBody::Node& soft_node = f.world.soft().m_nodes[f.node];
  const double scale = (1.0 - f.world.soft().m_cfg.kDP) / kStep_s;
  EXPECT_NEAR(soft_node.m_v.y(), 0.0015 * scale, 1e-4);
  EXPECT_NEAR(soft_node.m_v.x(), (end.x() - f.start.x()) * scale, 1e-4);
}

TEST(SweptGuard, APathBesideTheToolIsLeftAlone) {
  SweptGuardFixture f;
  const Eigen::Vector3d further_out(0.025, 0.003, 0.001);
  f.end_at(further_out);
  const btVector3 velocity_before = f.world.soft().m_nodes[f.node].m_v;
  EXPECT_EQ(guard_swept_paths(f.model, f.frame, f.world.soft(), f.data, nullptr), 0);
  EXPECT_TRUE(f.end().isApprox(further_out, 1e-7));
  EXPECT_EQ(f.world.soft().m_nodes[f.node].m_v, velocity_before);
}

}  // namespace
}  // namespace fissure::host::thin_body
