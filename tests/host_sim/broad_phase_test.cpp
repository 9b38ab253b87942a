// Stage 1 of the thin-body collision (host_sim/src/thin_body/broad_phase.cpp), tested through its
// internal interface: the candidate faces must be exactly the faces the later stages need
// (compared with a brute-force scan of every face, on random poses and through real plunges
// where Bullet's node-tree leaves go stale), nothing out of contact, and for a fixed contact the
// work done (tree nodes, seeds, faces tested) must not grow with the mesh.
#include "thin_body/collision_state.hpp"

#include <gtest/gtest.h>

#include <BulletSoftBody/btSoftBody.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <iterator>
#include <set>
#include <string>
#include <vector>

#include "soft_scene_fixture.hpp"

namespace fissure::host {
namespace {

using test_scene::kStep_s;

// CreateEllipsoid(res) gives 2·res + 2 faces: 63 → the paper's 128; 639 → 1280; 2559 → 5120; 10239 → 20480.
int ellipsoid_resolution(int faces) { return (faces - 2) / 2; }

// The collision's own frame construction, for driving the stages one by one.
thin_body::StepFrame make_frame(const thin_body::CollisionModel& model, std::int64_t step, const ToolPose& previous, const ToolPose& current) {
  return thin_body::make_step_frame(model, step, previous, current, kStep_s);
}

Eigen::Vector3d to_eigen(const btVector3& v) { return {v.x(), v.y(), v.z()}; }

// Brute force over EVERY face, against broad_phase.cpp's criterion. A face is NEEDED when a vertex
// of it was held on the tool last step and is still within release_distance of the tool's bounds,
// or when its tool-frame start/end bounds come within contact_distance + skin of the tool's
// bounds, or within memory_pad of the tool nodes in contact last step, AND its world start/end
// bounds meet those padded regions
// swept over the step (the tool-frame bounds alone over-cover: a face moving 6 cm past the tool
// within one step has tool-frame bounds spanning the tool although its path does not). A face is
// ALLOWED when the tool-frame condition holds. The broad phase must return every needed face and
// only allowed ones.
struct FaceSets {
  std::set<int> needed, allowed;
};

Eigen::AlignedBox3d grown(Eigen::AlignedBox3d box, double by_m) {
  box.min().array() -= by_m;
  box.max().array() += by_m;
  return box;
}

Eigen::AlignedBox3d swept_world(const thin_body::StepFrame& frame, const Eigen::AlignedBox3d& box_tool) {
  Eigen::AlignedBox3d out;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d p = box_tool.corner(static_cast<Eigen::AlignedBox3d::CornerType>(corner));
    out.extend(frame.r_prev * p + frame.t_prev);
    out.extend(frame.r_cur * p + frame.t_cur);
  }
  return out;
}

FaceSets needed_faces(const thin_body::CollisionModel& model, const thin_body::CollisionData& data, const thin_body::StepFrame& frame,
                      const btSoftBody& soft, const std::vector<int>& last_contact_nodes) {
  const ThinBodyCollisionParams& p = model.params;
  const Eigen::AlignedBox3d near = grown(model.tool.bounds_tool_m(), p.contact_distance_m + p.skin_m);
  const Eigen::AlignedBox3d release = grown(model.tool.bounds_tool_m(), std::max(p.contact_distance_m, p.release_distance_m) + p.skin_m);
  Eigen::AlignedBox3d memory;
  for (const int n : last_contact_nodes) memory.extend(model.tool.positions_tool_m()[static_cast<std::size_t>(n)]);
  if (!memory.isEmpty()) memory = grown(memory, model.memory_depth_m + p.contact_distance_m);
  const Eigen::AlignedBox3d near_world = swept_world(frame, near);
  const Eigen::AlignedBox3d memory_world = memory.isEmpty() ? memory : swept_world(frame, memory);
  FaceSets out;
  for (int f = 0; f < model.soft.face_count; ++f) {
    Eigen::AlignedBox3d box_tool, box_world;
    bool held = false;
    for (const int v : model.soft.face_nodes[static_cast<std::size_t>(f)]) {
      const Eigen::Vector3d end = frame.r_cur.transpose() * (to_eigen(soft.m_nodes[v].m_x) - frame.t_cur);
      held = held || (data.displacement.hold_stamp[static_cast<std::size_t>(v)] == frame.step - 1 && release.contains(end));
      box_tool.extend(frame.r_prev.transpose() * (to_eigen(soft.m_nodes[v].m_q) - frame.t_prev));
      box_tool.extend(end);
      box_world.extend(to_eigen(soft.m_nodes[v].m_q));
      box_world.extend(to_eigen(soft.m_nodes[v].m_x));
    }
    const bool near_tool = box_tool.intersects(near);
    const bool memory_tool = !memory.isEmpty() && box_tool.intersects(memory);
    if (near_tool || memory_tool || held) out.allowed.insert(f);
    if (held || (near_tool && box_world.intersects(near_world)) || (memory_tool && box_world.intersects(memory_world))) out.needed.insert(f);
  }
  return out;
}

void expect_between(const std::set<int>& got, const FaceSets& sets, const std::string& where) {
  std::vector<int> missing, extra;
  std::set_difference(sets.needed.begin(), sets.needed.end(), got.begin(), got.end(), std::back_inserter(missing));
  std::set_difference(got.begin(), got.end(), sets.allowed.begin(), sets.allowed.end(), std::back_inserter(extra));
  EXPECT_TRUE(missing.empty()) << where << ": " << missing.size() << " needed faces missing, first " << (missing.empty() ? -1 : missing[0]);
  EXPECT_TRUE(extra.empty()) << where << ": " << extra.size() << " candidates not allowed, first " << (extra.empty() ? -1 : extra[0]);
}

// The pre-filter (broad_phase.cpp, header comment 3.) may only skip work, never change a decision:
// among the faces the broad phase reached this step (face_candidate_stamp == step), the candidates
// must be exactly the ALLOWED ones (the exact tool-frame test, brute force) — a face the exact test
// keeps but the pre-filter dropped would be missing here even where brute force does not call it
// needed.
void expect_reached_faces_decided_exactly(const thin_body::CollisionData& data, std::int64_t step, const FaceSets& sets, const std::string& where) {
  const std::set<int> got(data.broad.candidate_faces.begin(), data.broad.candidate_faces.end());
  int wrong = 0, first = -1;
  for (int f = 0; f < static_cast<int>(data.broad.face_candidate_stamp.size()); ++f) {
    const bool reached = data.broad.face_candidate_stamp[static_cast<std::size_t>(f)] == step;
    const bool expected = reached && sets.allowed.count(f) != 0;
    if (expected != (got.count(f) != 0)) {
      ++wrong;
      if (first < 0) first = f;
    }
  }
  EXPECT_EQ(wrong, 0) << where << ": " << wrong << " reached faces decided unlike the exact test, first " << first;
}

// The node bounds NodeBoundsSolver leaves after a solve (every node's m_q and m_x, per block),
// taken by brute force from the body as it is now.
SoftNodeBounds bounds_as_the_solver_leaves_them(const btSoftBody& soft) {
  SoftNodeBounds bounds;
  bounds.node_count = soft.m_nodes.size();
  const int blocks = (bounds.node_count + SoftNodeBounds::kNodesPerBlock - 1) / SoftNodeBounds::kNodesPerBlock;
  const btVector3 large(BT_LARGE_FLOAT, BT_LARGE_FLOAT, BT_LARGE_FLOAT);
  bounds.block_lo.assign(static_cast<std::size_t>(blocks), large);
  bounds.block_hi.assign(static_cast<std::size_t>(blocks), -large);
  bounds.all_lo = large;
  bounds.all_hi = -large;
  for (int i = 0; i < soft.m_nodes.size(); ++i) {
    bounds.extend(i, soft.m_nodes[i].m_q);
    bounds.extend(i, soft.m_nodes[i].m_x);
  }
  bounds.valid = true;
  return bounds;
}

struct Harness {
  test_scene::SoftWorld world{true};
  ToolNodes tool;
  ThinBodyCollisionParams params;
  thin_body::CollisionModel model;
  thin_body::CollisionData data;
  // with_bounds: the broad phase reads node bounds as NodeBoundsSolver leaves them (every node's
  // m_q and m_x, per block; taken here by brute force before each step) instead of every node.
  bool with_bounds = false;
  SoftNodeBounds bounds;

  Harness(int faces, const ToolNodes& t)
      : tool(t), model(thin_body::build_collision_model(tool, settled_sphere(world, faces).soft(), params, true)) {
    thin_body::allocate_collision_data(model, data);
  }

  static test_scene::SoftWorld& settled_sphere(test_scene::SoftWorld& w, int faces) {
    w.add_sphere(test_scene::kSphereRadius_m, ellipsoid_resolution(faces));
    for (int i = 0; i < 20; ++i) w.step_dynamics();
    return w;
  }

  // The pipeline of ThinBodyCollisionImpl::step, stage by stage, so the test can see the broad
  // phase's data. Returns the frame used.
  thin_body::StepFrame step(const ToolPose& previous, const ToolPose& current, bool respond) {
    ++data.step;
    const thin_body::StepFrame frame = make_frame(model, data.step, previous, current);
    if (with_bounds) take_bounds();
    const bool hit = thin_body::broad_phase(model, frame, world.soft(), data, with_bounds ? &bounds : nullptr);
    if (!hit) {
      std::fill(data.sweep.node_face.begin(), data.sweep.node_face.end(), -1);
      std::fill(data.sweep.node_age.begin(), data.sweep.node_age.end(), 0);
      return frame;
    }
    if (respond) {
      thin_body::sweep_tool_nodes(model, data);
      (void)thin_body::exclude_infeasible_pairs(model, data);
      (void)thin_body::enforce_displacement(model, frame, world.soft(), data, with_bounds ? &bounds : nullptr);
      CollisionStepResult out;
      out.reserve_for(model.soft.face_count);
      thin_body::hunt_crossley_force(model, frame, world.soft(), data, out);
    }
    return frame;
  }

  std::vector<int> last_contact_nodes() const {
    std::vector<int> out;
    for (const int n : data.sweep.contact_nodes)
      if (data.sweep.node_face[static_cast<std::size_t>(n)] >= 0) out.push_back(n);
    return out;
  }

  std::set<int> candidate_faces() const { return {data.broad.candidate_faces.begin(), data.broad.candidate_faces.end()}; }

  void take_bounds() { bounds = bounds_as_the_solver_leaves_them(world.soft()); }
};

void expect_candidate_nodes_are_the_vertices(Harness& h, const thin_body::StepFrame& frame) {
  std::set<int> vertices;
  for (const int f : h.data.broad.candidate_faces)
    for (const int v : h.model.soft.face_nodes[static_cast<std::size_t>(f)]) vertices.insert(v);
  const std::set<int> nodes(h.data.broad.candidate_nodes.begin(), h.data.broad.candidate_nodes.end());
  EXPECT_EQ(nodes.size(), h.data.broad.candidate_nodes.size()) << "a candidate node listed twice";
  EXPECT_EQ(nodes, vertices);
  for (const int v : h.data.broad.candidate_nodes) {
    const auto i = static_cast<std::size_t>(v);
    const Eigen::Vector3d start = frame.r_prev.transpose() * (to_eigen(h.world.soft().m_nodes[v].m_q) - frame.t_prev);
    EXPECT_LT((h.data.broad.start_tool_m[i] - start).norm(), 1e-9);
  }
}

// Random tool poses around and through the sphere (random orientation, a random move of up to
// 6 cm and up to 0.2 rad per step): every needed face, only allowed ones (brute force).
TEST(BroadPhase, RandomPosesGiveEveryNeededFaceAndNoOther) {
  std::mt19937 rng(5150);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int poses_with_candidates = 0;
  for (const bool with_bounds : {false, true})
  for (const int faces : {128, 1280}) {
    Harness h(faces, test_scene::plate_tool(0.004));
    h.with_bounds = with_bounds;
    const Eigen::Vector3d centre(0, test_scene::kSphereRadius_m, 0);
    for (int trial = 0; trial < 150; ++trial) {
      h.world.step_dynamics();  // start (m_q) and end (m_x) positions differ
      ToolPose previous;
      previous.orientation_world = Eigen::Quaterniond::UnitRandom();
      previous.position_world_m = centre + 0.07 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
      ToolPose current = previous;
      current.position_world_m += 0.06 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng)) * std::abs(unit(rng));
      current.orientation_world =
          (Eigen::Quaterniond(Eigen::AngleAxisd(0.2 * unit(rng), Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized())) *
           previous.orientation_world).normalized();
      // Some tool nodes "in contact last step" (the side-memory region of the query).
      h.data.sweep.contact_nodes.clear();
      std::fill(h.data.sweep.node_face.begin(), h.data.sweep.node_face.end(), -1);
      if (trial % 2 == 0) {
        const int first = static_cast<int>(std::abs(unit(rng)) * (h.tool.node_count() - 5));
        for (int n = first; n < first + 5; ++n) {
          h.data.sweep.contact_nodes.push_back(n);
          h.data.sweep.node_face[static_cast<std::size_t>(n)] = 0;
        }
      }
      const std::vector<int> memory = h.last_contact_nodes();
      // needed_faces() must see the body as broad_phase() does: compute it on the same frame.
      const thin_body::StepFrame frame = make_frame(h.model, h.data.step + 1, previous, current);
      const FaceSets expected = needed_faces(h.model, h.data, frame, h.world.soft(), memory);
      const thin_body::StepFrame used = h.step(previous, current, false);
      ASSERT_EQ(used.step, frame.step);
      const std::string where = std::to_string(faces) + " faces, trial " + std::to_string(trial) + (with_bounds ? ", node bounds" : "");
      expect_between(h.candidate_faces(), expected, where);
      expect_reached_faces_decided_exactly(h.data, used.step, expected, where);
      expect_candidate_nodes_are_the_vertices(h, used);
      poses_with_candidates += expected.needed.empty() ? 0 : 1;
    }
  }
  EXPECT_GT(poses_with_candidates, 120) << "the random poses must mostly reach the sphere";
}

// Through real plunges (the collision moving nodes, Bullet predicting them elsewhere, the tool
// stopping dead at the bottom) and holds, at 0.1–50 m/s: never a needed face missing, never a
// candidate that is not allowed.
TEST(BroadPhase, PlungesAndHoldsGiveEveryNeededFaceAndNoOther) {
  for (const bool with_bounds : {false, true})
  for (const double speed : {0.1, 2.0, 20.0, 50.0}) {
    Harness h(1280, test_scene::plate_tool(0.002));
    h.with_bounds = with_bounds;
    ToolPose previous;
    previous.position_world_m = Eigen::Vector3d(0.003, 0.115, -0.002);
    int contact_steps = 0;
    const int plunge_steps = static_cast<int>(std::ceil(0.045 / (speed * kStep_s)));
    for (int s = 0; s < plunge_steps + 150; ++s) {
      ToolPose current = previous;
      current.position_world_m.y() = std::max(0.07, previous.position_world_m.y() - speed * kStep_s);
      h.world.step_dynamics();
      const std::vector<int> memory = h.last_contact_nodes();
      const thin_body::StepFrame frame = make_frame(h.model, h.data.step + 1, previous, current);
      const FaceSets expected = needed_faces(h.model, h.data, frame, h.world.soft(), memory);
      (void)h.step(previous, current, true);
      const std::string where = "speed " + std::to_string(speed) + " step " + std::to_string(s) + (with_bounds ? ", node bounds" : "");
      expect_between(h.candidate_faces(), expected, where);
      expect_reached_faces_decided_exactly(h.data, frame.step, expected, where);
      if (HasFailure()) return;
      contact_steps += h.data.sweep.contact_nodes.empty() ? 0 : 1;
      previous = current;
    }
    EXPECT_GT(contact_steps, 100) << "speed " << speed;
  }
}

// Bullet fits each node-tree leaf around the node's PREDICTED position and then moves the node
// (pose matching, then the constraint solver): with strong pose matching a dented cap springs back
// 15-25 mm AFTER its leaves were fitted round the dent. A tool arriving where the nodes really are
// (last step out of contact, so there are no previous candidates to re-test) must still get every
// face brute force says it needs: the broad phase may not trust the leaves.
TEST(BroadPhase, NodesMovedAfterBulletFittedTheirLeavesAreStillFound) {
  for (const int faces : {1280, 5120}) {
    Harness h(faces, test_scene::plate_tool(0.002));
    btSoftBody& soft = h.world.soft();
    soft.m_cfg.kMT = 1.0f;  // pose matching puts every node on its goal after the leaf fit
    double top = -1.0;
    for (int i = 0; i < soft.m_nodes.size(); ++i) top = std::max(top, static_cast<double>(soft.m_nodes[i].m_x.y()));
    ToolPose far;
    far.position_world_m = Eigen::Vector3d(0, top + 0.2, 0);
    (void)h.step(far, far, true);  // out of contact: no candidates carried to the next step
    ASSERT_TRUE(h.data.broad.candidate_faces.empty());
    // Leaves fitted tightly round the nodes (Bullet inserts them 0.25 m loose and only refits a
    // leaf its node has left), so that the staleness below is Bullet's own.
    h.world.step_without_dynamics();
    // A cap dented 25 mm and at rest there (as a press the tool just left would leave it).
    constexpr double kDent_m = 0.025;
    for (int i = 0; i < soft.m_nodes.size(); ++i) {
      btSoftBody::Node& n = soft.m_nodes[i];
      if (n.m_x.y() < top - 0.012) continue;
      n.m_x.setY(n.m_x.y() - static_cast<btScalar>(kDent_m));
      n.m_q = n.m_x;
      n.m_v.setZero();
    }
    h.world.step_dynamics();
    // Precondition: nodes lie outside their leaves by more than the broad phase's margin.
    double outside_leaf_m = 0.0;
    double new_top = -1.0;
    for (int i = 0; i < soft.m_nodes.size(); ++i) {
      const btSoftBody::Node& n = soft.m_nodes[i];
      new_top = std::max(new_top, static_cast<double>(n.m_x.y()));
      const btVector3 lo = n.m_leaf->volume.Mins(), hi = n.m_leaf->volume.Maxs();
      for (int a = 0; a < 3; ++a)
        outside_leaf_m = std::max({outside_leaf_m, static_cast<double>(lo[a] - n.m_x[a]), static_cast<double>(n.m_x[a] - hi[a])});
    }
    constexpr double kFormerMarginM = 0.005;  // a node-tree walk's fixed leaf margin (docs/decisions.md, "Broad phase")
    ASSERT_GT(outside_leaf_m, 2.0 * kFormerMarginM) << faces << " faces: the scenario must put nodes outside their leaves";
    // The plate arrives 1 mm into the sprung-back cap and stays there.
    ToolPose pose;
    pose.position_world_m = Eigen::Vector3d(0, new_top - 0.001 + 0.001, 0);
    const thin_body::StepFrame frame = make_frame(h.model, h.data.step + 1, pose, pose);
    const FaceSets expected = needed_faces(h.model, h.data, frame, soft, h.last_contact_nodes());
    ASSERT_FALSE(expected.needed.empty());
    (void)h.step(pose, pose, false);
    expect_between(h.candidate_faces(), expected, std::to_string(faces) + " faces, " + std::to_string(outside_leaf_m * 1e3) + " mm outside a leaf");
    expect_reached_faces_decided_exactly(h.data, frame.step, expected, std::to_string(faces) + " faces, sprung-back cap");
  }
}

// The pre-filter's edge cases, each a face that ONLY the exact tool-frame test keeps for its own
// reason, with the tool turning 0.12 rad within the step (start and end in different frames) and
// tilted 0.7 rad: (a) a stretched triangle whose tool-frame bounds meet the padded tool while its
// three vertices and the triangle itself stay clear of it; (b) a face 1.5 mm under the plate
// (outside contact_distance + skin) with a vertex held on the tool last step (the release band);
// (c) the same face under tool nodes that were in contact last step (the side-memory band). Each
// must be a candidate, and must not be one without its reason (the control); every reached face
// must be decided as the exact test decides.
TEST(BroadPhase, PreFilterKeepsEveryFaceTheExactTestKeeps) {
  enum class Reason { kStretchedAcrossTheRim, kHeldVertexInReleaseBand, kMemoryBand };
  const ToolNodes plate = test_scene::plate_tool(0.002);
  const Eigen::AlignedBox3d bounds = plate.bounds_tool_m();
  const double half_x = bounds.max().x(), top = bounds.max().y(), bottom = bounds.min().y();
  for (const Reason reason : {Reason::kStretchedAcrossTheRim, Reason::kHeldVertexInReleaseBand, Reason::kMemoryBand}) {
    for (const bool with_reason : {true, false}) {
      Harness h(1280, plate);
      h.world.step_without_dynamics();
      btSoftBody& soft = h.world.soft();
      // The topmost face of the sphere is the one moved into place.
      int face = 0;
      double best = -1.0;
      for (int f = 0; f < h.model.soft.face_count; ++f) {
        double y = 0.0;
        for (const int v : h.model.soft.face_nodes[static_cast<std::size_t>(f)]) y += soft.m_nodes[v].m_x.y() / 3.0;
        if (y > best) best = y, face = f;
      }
      const std::array<int, 3> nodes = h.model.soft.face_nodes[static_cast<std::size_t>(face)];
      std::array<Eigen::Vector3d, 3> p_tool;
      switch (reason) {
        case Reason::kStretchedAcrossTheRim:
          // In the plane x + y = half_x + top + 0.5 mm: 0.35 mm clear of the rim edge (x = half_x,
          // y = top), with tool-frame bounds [half_x − 1, half_x + 1.5] × [top − 1, top + 1.5] mm
          // that take in the rim. Without the reason: the same triangle 3 mm further out.
          p_tool = {Eigen::Vector3d(half_x - 0.001, top + 0.0015, 0.0), Eigen::Vector3d(half_x + 0.0015, top - 0.001, 0.0),
                    Eigen::Vector3d(half_x + 0.0015, top - 0.001, 0.001)};
          if (!with_reason)
            for (Eigen::Vector3d& p : p_tool) p += Eigen::Vector3d(0.003, 0.003, 0.0);
          break;
        case Reason::kHeldVertexInReleaseBand:
        case Reason::kMemoryBand:
          // 1.5-2.5 mm under the plate's bottom, under its middle.
          p_tool = {Eigen::Vector3d(0.0, bottom - 0.0015, 0.0), Eigen::Vector3d(0.001, bottom - 0.0025, 0.0),
                    Eigen::Vector3d(0.0, bottom - 0.0025, 0.001)};
          break;
      }
      // Tool poses that put those points where the face was (the sphere's other faces do not matter).
      Eigen::Vector3d centroid_world = Eigen::Vector3d::Zero();
      for (const int v : nodes) centroid_world += to_eigen(soft.m_nodes[v].m_x) / 3.0;
      const Eigen::Vector3d centroid_tool = (p_tool[0] + p_tool[1] + p_tool[2]) / 3.0;
      ToolPose previous, current;
      previous.orientation_world = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, 0.3, -0.4).normalized()));
      current.orientation_world = (Eigen::Quaterniond(Eigen::AngleAxisd(0.12, Eigen::Vector3d(-0.2, 1.0, 0.5).normalized())) *
                                   previous.orientation_world).normalized();
      previous.position_world_m = centroid_world - previous.orientation_world * centroid_tool;
      current.position_world_m = centroid_world - current.orientation_world * centroid_tool + Eigen::Vector3d(0.0004, -0.0003, 0.0002);
      // Fixed in the tool frame over the step: start (m_q) at the previous pose, end (m_x) at the current one.
      for (std::size_t k = 0; k < 3; ++k) {
        const Eigen::Vector3d q = previous.to_world(p_tool[k]), x = current.to_world(p_tool[k]);
        btSoftBody::Node& n = soft.m_nodes[nodes[k]];
        n.m_q = btVector3(static_cast<btScalar>(q.x()), static_cast<btScalar>(q.y()), static_cast<btScalar>(q.z()));
        n.m_x = btVector3(static_cast<btScalar>(x.x()), static_cast<btScalar>(x.y()), static_cast<btScalar>(x.z()));
      }
      h.data.sweep.contact_nodes.clear();
      std::fill(h.data.sweep.node_face.begin(), h.data.sweep.node_face.end(), -1);
      if (reason == Reason::kHeldVertexInReleaseBand && with_reason) h.data.displacement.hold_stamp[static_cast<std::size_t>(nodes[0])] = h.data.step;
      if (reason == Reason::kMemoryBand && with_reason) {
        // Bottom-face tool nodes within 3 mm of the face's footprint were in contact last step.
        for (int n = 0; n < plate.node_count(); ++n) {
          const Eigen::Vector3d& p = plate.positions_tool_m()[static_cast<std::size_t>(n)];
          if (p.y() < bottom + 1e-9 && std::abs(p.x()) < 0.003 && std::abs(p.z()) < 0.003) {
            h.data.sweep.contact_nodes.push_back(n);
            h.data.sweep.node_face[static_cast<std::size_t>(n)] = face;
          }
        }
        ASSERT_FALSE(h.data.sweep.contact_nodes.empty());
      }
      const std::string where = std::string(reason == Reason::kStretchedAcrossTheRim ? "stretched across the rim"
                                            : reason == Reason::kHeldVertexInReleaseBand ? "held vertex" : "memory band") +
                                (with_reason ? "" : " (control)");
      // Preconditions: no vertex, start or end, within contact_distance + skin of the tool.
      const thin_body::StepFrame frame = make_frame(h.model, h.data.step + 1, previous, current);
      const Eigen::AlignedBox3d near = grown(bounds, h.params.contact_distance_m + h.params.skin_m);
      for (const int v : nodes) {
        const Eigen::Vector3d start = frame.r_prev.transpose() * (to_eigen(soft.m_nodes[v].m_q) - frame.t_prev);
        const Eigen::Vector3d end = frame.r_cur.transpose() * (to_eigen(soft.m_nodes[v].m_x) - frame.t_cur);
        ASSERT_FALSE(near.contains(start)) << where;
        ASSERT_FALSE(near.contains(end)) << where;
      }
      const FaceSets expected = needed_faces(h.model, h.data, frame, soft, h.last_contact_nodes());
      ASSERT_EQ(expected.allowed.count(face) != 0, with_reason) << where << ": the exact test must keep the face for its reason only";
      (void)h.step(previous, current, false);
      EXPECT_EQ(h.data.broad.face_candidate_stamp[static_cast<std::size_t>(face)], frame.step) << where << ": the face must be reached";
      EXPECT_EQ(h.candidate_faces().count(face) != 0, with_reason) << where;
      expect_between(h.candidate_faces(), expected, where);
      expect_reached_faces_decided_exactly(h.data, frame.step, expected, where);
    }
  }
}

// Two tool parts share the solver's bounds (the clamp's jaws): the first part's enforced
// displacement writes node positions after the bounds were taken, and the second part's broad
// phase must still find those nodes. On a flat sheet (grid order: a block of nodes is a strip of
// it), plate A plunges 30 mm in one step and lays the sheet's nodes under it on its bottom face,
// which ends on the mid-plane of a static plate B: B must get the same candidates as when it
// reads every node, although the bounds saw those nodes 30 mm away.
TEST(BroadPhase, NodesMovedByAnotherPartAfterTheBoundsWereTakenAreFound) {
  std::vector<std::set<int>> candidates_of_b;
  for (const bool with_bounds : {false, true}) {
    test_scene::SoftWorld world{false};
    world.add_slab(0.1, 32);
    const ToolNodes tool = test_scene::plate_tool(0.004);
    const ThinBodyCollisionParams params;
    const thin_body::CollisionModel model_a = thin_body::build_collision_model(tool, world.soft(), params, true);
    const thin_body::CollisionModel model_b = thin_body::build_collision_model(tool, world.soft(), params, true);
    thin_body::CollisionData data_a, data_b;
    thin_body::allocate_collision_data(model_a, data_a);
    thin_body::allocate_collision_data(model_b, data_b);
    world.step_without_dynamics();
    SoftNodeBounds bounds = bounds_as_the_solver_leaves_them(world.soft());
    SoftNodeBounds* shared = with_bounds ? &bounds : nullptr;
    ToolPose a_from, a_to, b_pose;
    a_from.position_world_m = Eigen::Vector3d(0, 0.003, 0);
    b_pose.position_world_m = Eigen::Vector3d(0, -0.03, 0);
    a_to.position_world_m = Eigen::Vector3d(0, -0.03 + 0.002, 0);  // A's bottom face on B's mid-plane
    data_a.step = 1;
    const thin_body::StepFrame frame_a = make_frame(model_a, 1, a_from, a_to);
    ASSERT_TRUE(thin_body::broad_phase(model_a, frame_a, world.soft(), data_a, shared));
    thin_body::sweep_tool_nodes(model_a, data_a);
    (void)thin_body::exclude_infeasible_pairs(model_a, data_a);
    (void)thin_body::enforce_displacement(model_a, frame_a, world.soft(), data_a, shared);
    ASSERT_GT(data_a.displacement.moved_nodes.size(), 50u);
    data_b.step = 1;
    const thin_body::StepFrame frame_b = make_frame(model_b, 1, b_pose, b_pose);
    (void)thin_body::broad_phase(model_b, frame_b, world.soft(), data_b, shared);
    candidates_of_b.emplace_back(data_b.broad.candidate_faces.begin(), data_b.broad.candidate_faces.end());
  }
  EXPECT_FALSE(candidates_of_b[0].empty()) << "A's displaced nodes lie inside B";
  EXPECT_EQ(candidates_of_b[1], candidates_of_b[0]);
}

TEST(BroadPhase, OutOfContactNoFaceIsTested) {
  Harness h(5120, test_scene::plate_tool(0.004));
  ToolPose previous;
  previous.position_world_m = Eigen::Vector3d(0, 0.2, 0);
  ToolPose current = previous;
  current.position_world_m.y() = 0.17;  // moving, 6 cm above the sphere
  (void)h.step(previous, current, true);
  h.world.step_dynamics();
  (void)h.step(current, current, true);
  EXPECT_TRUE(h.data.broad.candidate_faces.empty());
  EXPECT_EQ(h.data.broad.nodes_scanned, h.model.soft.node_count);
  EXPECT_EQ(h.data.broad.seed_nodes, 0);
  EXPECT_EQ(h.data.broad.faces_tested, 0);
  // With the solver's node bounds the whole body is tested once and no node is read.
  h.with_bounds = true;
  (void)h.step(current, current, true);
  EXPECT_TRUE(h.data.broad.candidate_faces.empty());
  EXPECT_EQ(h.data.broad.nodes_scanned, 0);
  EXPECT_EQ(h.data.broad.seed_nodes, 0);
}

// The work for a fixed contact: a plate held on the sphere's top at the depth where about 24
// triangles are candidates. Seeds and faces tested per candidate face must not grow with the mesh
// (16× more faces from 1280 to 20480); the scan reads every node once, nothing more.
TEST(BroadPhase, WorkForAFixedContactDoesNotGrowWithTheMesh) {
  struct Work {
    int faces, candidates, scanned, seeds, tested, transformed;
  };
  std::vector<Work> rows;
  for (const int faces : {1280, 5120, 20480}) {
    Harness h(faces, test_scene::plate_tool(0.002));
    h.world.step_without_dynamics();
    double top = -1.0;
    for (int i = 0; i < h.world.soft().m_nodes.size(); ++i) top = std::max(top, static_cast<double>(h.world.soft().m_nodes[i].m_x.y()));
    // Lower the plate (quasi-statically, no response: the sphere stays as it is) until ~24 faces.
    double depth = 0.0;
    for (; depth < 0.01; depth += 2e-5) {
      ToolPose pose;
      pose.position_world_m = Eigen::Vector3d(0, top + 0.001 - depth, 0);
      (void)h.step(pose, pose, false);
      if (h.data.broad.candidate_faces.size() >= 24) break;
    }
    ToolPose pose;
    pose.position_world_m = Eigen::Vector3d(0, top + 0.001 - depth, 0);
    h.data.broad.previous_candidates.clear();  // measure one step's own work, not the re-test of the last
    (void)h.step(pose, pose, false);
    rows.push_back({faces, static_cast<int>(h.data.broad.candidate_faces.size()), h.data.broad.nodes_scanned, h.data.broad.seed_nodes,
                    h.data.broad.faces_tested, h.data.broad.faces_transformed});
    std::printf("faces %6d: candidate faces %4d, nodes scanned %5d, seed nodes %5d, faces tested %5d, transformed %4d\n", faces,
                rows.back().candidates, rows.back().scanned, rows.back().seeds, rows.back().tested, rows.back().transformed);
    EXPECT_EQ(rows.back().scanned, h.model.soft.node_count);
  }
  for (const Work& w : rows) {
    EXPECT_GE(w.candidates, 24);
    EXPECT_LE(w.candidates, 100);
    // The pre-filter: only faces near the tool get their vertices into the tool frame, not the
    // seed band (a plate held still on the sphere: its pre-filter is exact).
    EXPECT_GE(w.transformed, w.candidates);
    EXPECT_LE(w.transformed, 2 * w.candidates);
  }
  const auto per_candidate = [](const Work& w, int count) { return static_cast<double>(count) / w.candidates; };
  const Work& coarse = rows.front();
  const Work& fine = rows.back();
  EXPECT_LE(per_candidate(fine, fine.tested), 4.0 * per_candidate(coarse, coarse.tested));
  EXPECT_LE(per_candidate(fine, fine.seeds), 4.0 * per_candidate(coarse, coarse.seeds));
}

}  // namespace
}  // namespace fissure::host
