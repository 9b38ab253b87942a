#pragma once
// Minimal Bullet soft-rigid worlds for the thin-body collision tests: the paper's soft sphere of
// 128 faces on a box ground, and a flat soft slab. The tool is NOT a Bullet body here — only the
// collision under test touches the soft body. Also a crossed-node tracker with the issue-5
// definition and a plunge driver (kinematic tool, lockstep, 1 ms).
#include <fissure/host_sim/contact_metrics.hpp>
#include <fissure/host_sim/thin_body_collision.hpp>
#include <fissure/host_sim/thin_tool.hpp>

#include <BulletCollision/BroadphaseCollision/btDbvtBroadphase.h>
#include <BulletCollision/CollisionDispatch/btCollisionDispatcher.h>
#include <BulletCollision/CollisionShapes/btBoxShape.h>
#include <BulletDynamics/ConstraintSolver/btSequentialImpulseConstraintSolver.h>
#include <BulletDynamics/Dynamics/btRigidBody.h>
#include <BulletSoftBody/btDefaultSoftBodySolver.h>
#include <BulletSoftBody/btSoftBodyHelpers.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <LinearMath/btDefaultMotionState.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

namespace fissure::host::test_scene {

inline constexpr double kSphereRadius_m = 0.05;  // paper / BRIEF §3: R = 5 cm
inline constexpr int kSphereResolution = 63;     // CreateEllipsoid(.., 63) → 66 nodes, 128 faces (BRIEF §3)
inline constexpr double kStep_s = 1e-3;          // 1 kHz host step

class SoftWorld {
 public:
  explicit SoftWorld(bool with_ground_and_gravity)
      : dispatcher_(&configuration_),
        world_(&dispatcher_, &broadphase_, &solver_, &configuration_, &soft_solver_) {
    btSoftBodyWorldInfo& info = world_.getWorldInfo();
    info.m_dispatcher = &dispatcher_;
    info.m_broadphase = &broadphase_;
    info.m_sparsesdf.Initialize();
    info.m_sparsesdf.setDefaultVoxelsz(0.005);  // BRIEF §3: Initialize() forces 0.25 m; refine after it
    info.m_sparsesdf.Reset();
    const btVector3 gravity = with_ground_and_gravity ? btVector3(0, -9.81f, 0) : btVector3(0, 0, 0);
    world_.setGravity(gravity);
    info.m_gravity = gravity;
    if (with_ground_and_gravity) {
      ground_shape_ = std::make_unique<btBoxShape>(btVector3(0.5f, 0.05f, 0.5f));
      btTransform ground_pose;
      ground_pose.setIdentity();
      ground_pose.setOrigin(btVector3(0, -0.05f, 0));  // top face at y = 0
      ground_state_ = std::make_unique<btDefaultMotionState>(ground_pose);
      ground_ = std::make_unique<btRigidBody>(btRigidBody::btRigidBodyConstructionInfo(0, ground_state_.get(), ground_shape_.get()));
      world_.addRigidBody(ground_.get());
    }
  }
  ~SoftWorld() {
    if (soft_) world_.removeSoftBody(soft_.get());
    if (ground_) world_.removeRigidBody(ground_.get());
  }
  SoftWorld(const SoftWorld&) = delete;
  SoftWorld& operator=(const SoftWorld&) = delete;

  // The paper's sphere: R = 5 cm, 128 faces, resting on the ground (centre at y = R).
  void add_sphere(double radius_m = kSphereRadius_m, int resolution = kSphereResolution) {
    const auto r = static_cast<btScalar>(radius_m);
    adopt(btSoftBodyHelpers::CreateEllipsoid(world_.getWorldInfo(), btVector3(0, r, 0), btVector3(r, r, r), resolution));
    soft_->m_materials[0]->m_kLST = 0.5f;
    soft_->m_cfg.piterations = 4;
    soft_->m_cfg.kDF = 0.5f;
    soft_->m_cfg.kDP = 0.01f;
    soft_->m_cfg.kPR = 0.0f;  // no pressure: Bullet's pressure term launches a 0.1 kg ball off the ground
    soft_->setTotalMass(0.1f, true);
    soft_->getCollisionShape()->setMargin(0.002f);
    // Shape matching (Bullet's pose matching) makes the shell a springy ball that keeps pushing
    // back on a plate holding it squashed; without it a pressure-less shell just lies flat.
    soft_->m_cfg.kMT = 0.05f;
    soft_->setPose(false, true);
  }

  // A flat sheet of (cells+1)² nodes, side_m wide, at y = 0, faces wound so normals point +y.
  void add_slab(double side_m, int cells) {
    std::vector<btScalar> vertices;
    for (int i = 0; i <= cells; ++i)
      for (int j = 0; j <= cells; ++j) {
        vertices.push_back(static_cast<btScalar>(-0.5 * side_m + side_m * i / cells));
        vertices.push_back(0);
        vertices.push_back(static_cast<btScalar>(-0.5 * side_m + side_m * j / cells));
      }
    std::vector<int> triangles;
    const auto id = [cells](int i, int j) { return i * (cells + 1) + j; };
    for (int i = 0; i < cells; ++i)
      for (int j = 0; j < cells; ++j) {
        // (x, z) grid: (i,j)→(i,j+1)→(i+1,j) has normal (0,+1,0)·sign; check below.
        triangles.insert(triangles.end(), {id(i, j), id(i, j + 1), id(i + 1, j)});
        triangles.insert(triangles.end(), {id(i + 1, j), id(i, j + 1), id(i + 1, j + 1)});
      }
    adopt(btSoftBodyHelpers::CreateFromTriMesh(world_.getWorldInfo(), vertices.data(), triangles.data(),
                                               static_cast<int>(triangles.size() / 3), false));
    soft_->setTotalMass(0.1f, true);
    soft_->getCollisionShape()->setMargin(0.002f);
  }

  // A soft surface of the given triangles (xyz per vertex, three indices per triangle), 0.1 kg.
  void add_triangles(const std::vector<Eigen::Vector3d>& vertices_m, const std::vector<int>& triangles) {
    std::vector<btScalar> flat;
    for (const Eigen::Vector3d& v : vertices_m)
      for (int axis = 0; axis < 3; ++axis) flat.push_back(static_cast<btScalar>(v[axis]));
    adopt(btSoftBodyHelpers::CreateFromTriMesh(world_.getWorldInfo(), flat.data(), triangles.data(),
                                               static_cast<int>(triangles.size() / 3), false));
    soft_->setTotalMass(0.1f, true);
    soft_->getCollisionShape()->setMargin(0.002f);
  }

  // One Bullet step (ONE substep, as the collision's call order requires).
  void step_dynamics(double dt_s = kStep_s) {
    world_.stepSimulation(static_cast<btScalar>(dt_s), 1, static_cast<btScalar>(dt_s));
  }
  // Quasi-static use without dynamics: start-of-step positions = now, node tree refreshed.
  void step_without_dynamics() {
    for (int i = 0; i < soft_->m_nodes.size(); ++i) {
      btSoftBody::Node& n = soft_->m_nodes[i];
      n.m_q = n.m_x;
      n.m_v.setZero();
      btDbvtVolume volume = btDbvtVolume::FromCR(n.m_x, soft_->getCollisionShape()->getMargin());
      soft_->m_ndbvt.update(n.m_leaf, volume);
    }
    soft_->updateBounds();
  }

  btSoftBody& soft() { return *soft_; }
  btSoftRigidDynamicsWorld& world() { return world_; }

  std::vector<Eigen::Vector3d> node_positions() const {
    std::vector<Eigen::Vector3d> out;
    for (int i = 0; i < soft_->m_nodes.size(); ++i) {
      const btVector3& x = soft_->m_nodes[i].m_x;
      out.emplace_back(x.x(), x.y(), x.z());
    }
    return out;
  }

 private:
  void adopt(btSoftBody* body) {
    soft_.reset(body);
    world_.addSoftBody(soft_.get());
  }

  btSoftBodyRigidBodyCollisionConfiguration configuration_;
  btCollisionDispatcher dispatcher_;
  btDbvtBroadphase broadphase_;
  btSequentialImpulseConstraintSolver solver_;
  btDefaultSoftBodySolver soft_solver_;
  btSoftRigidDynamicsWorld world_;
  std::unique_ptr<btBoxShape> ground_shape_;
  std::unique_ptr<btDefaultMotionState> ground_state_;
  std::unique_ptr<btRigidBody> ground_;
  std::unique_ptr<btSoftBody> soft_;
};

// Issue 5's crossed-node measure, tool frame: a node remembers the side of the tool's mid-plane
// (sign of its thin-axis coordinate) it is on; the memory follows it freely outside the tool's
// footprint (it may go round the rim) and is frozen inside it. Crossed = inside the footprint on
// the other side than remembered, or deeper than 0.1 mm inside the tool.
class CrossingTracker {
 public:
  static constexpr double kInsideTolerance_m = 1e-4;  // issue 5: max penetration target 0.1 mm

  CrossingTracker(const ToolNodes& tool, const std::vector<Eigen::Vector3d>& nodes_world, const ToolPose& pose)
      : tool_(&tool), side_(nodes_world.size(), 0), crossed_(nodes_world.size(), 0) {
    for (std::size_t i = 0; i < nodes_world.size(); ++i) side_[i] = side_of(pose.to_tool(nodes_world[i]));
  }

  void update(const std::vector<Eigen::Vector3d>& nodes_world, const ToolPose& pose) {
    for (std::size_t i = 0; i < nodes_world.size(); ++i) {
      const Eigen::Vector3d p = pose.to_tool(nodes_world[i]);
      const double depth = -tool_->signed_distance_m(p);
      max_penetration_m_ = std::max(max_penetration_m_, depth);
      const int side = side_of(p);
      const bool inside_footprint = tool_->in_footprint(p);
      bool crossed = depth > kInsideTolerance_m;
      if (inside_footprint && side != 0 && side_[i] != 0 && side != side_[i]) crossed = true;
      if (!inside_footprint && side != 0) side_[i] = side;
      if (inside_footprint && side_[i] == 0) side_[i] = side;
      if (crossed) crossed_[i] = 1;
    }
  }
  [[nodiscard]] int crossed_nodes() const { return static_cast<int>(std::count(crossed_.begin(), crossed_.end(), 1)); }
  [[nodiscard]] double max_penetration_m() const { return max_penetration_m_; }

 private:
  int side_of(const Eigen::Vector3d& p_tool) const {
    const double w = p_tool[tool_->thin_axis()];
    return w > 0.0 ? 1 : (w < 0.0 ? -1 : 0);
  }
  const ToolNodes* tool_;
  std::vector<int> side_;
  std::vector<std::uint8_t> crossed_;
  double max_penetration_m_ = 0.0;
};

// How many soft triangles the tool's interior cuts through deeper than depth_tolerance_m: the
// exact clip of each triangle against the tool's planes (triangles_cut_by_volume, the count
// HostSimulation reports). A blade that slices a coarse triangle between its nodes leaves the
// nodes outside but the triangle's interior inside — the node-based crossing metric cannot see
// that, this does.
inline int triangles_cut_by_tool(const ToolNodes& tool, const btSoftBody& soft, const ToolPose& pose, double depth_tolerance_m) {
  std::vector<std::pair<Eigen::Vector3d, double>> planes;
  for (const ToolPlane& plane : tool.planes()) planes.emplace_back(plane.normal_tool, plane.offset_m);
  const ToolVolume volume = ToolVolume::from_planes(planes, tool.hull_vertices_tool_m());
  std::vector<Eigen::Vector3d> nodes_world_m;
  for (int i = 0; i < soft.m_nodes.size(); ++i) {
    const btVector3& x = soft.m_nodes[i].m_x;
    nodes_world_m.emplace_back(x.x(), x.y(), x.z());
  }
  std::vector<std::array<int, 3>> faces;
  for (int f = 0; f < soft.m_faces.size(); ++f) {
    std::array<int, 3> face{};
    for (int k = 0; k < 3; ++k) face[static_cast<std::size_t>(k)] = static_cast<int>(soft.m_faces[f].m_n[k] - &soft.m_nodes[0]);
    faces.push_back(face);
  }
  Eigen::Isometry3d tool_to_world = Eigen::Isometry3d::Identity();
  tool_to_world.linear() = pose.orientation_world.toRotationMatrix();
  tool_to_world.translation() = pose.position_world_m;
  return triangles_cut_by_volume(volume, nodes_world_m, faces, tool_to_world, depth_tolerance_m);
}

struct PlungeOutcome {
  int crossed_nodes = 0;
  double max_penetration_m = 0.0;
  double max_force_n = 0.0;
  bool forces_finite = true;
  bool positions_finite = true;
  int max_both_face_contacts = 0;
  int total_both_face_contacts = 0;
  int total_excluded = 0;
  int steps_in_contact = 0;
  int max_contacted_triangles = 0;
  double final_force_y_n = 0.0;
  std::vector<double> force_y_n;  // per step
  std::vector<Eigen::Vector3d> final_nodes;
  std::vector<double> step_seconds;  // collision step wall time per in-contact step
  double force_y_at_arrival_n = 0.0; // F_y on the step the tool reaches its end height
  double max_force_y_at_end_n = 0.0; // largest F_y over the arrival step and the hold
  double soft_top_start_m = 0.0;     // highest soft node (world y) when the tool starts
  double tool_bottom_end_m = 0.0;    // lowest tool point (world y) at the end of the run
  int triangles_cut_end = -1;        // soft triangles cut by the tool at the end (spec.check_triangles_cut)
  int max_triangles_cut = -1;        // ... over every step
};

struct PlungeSpec {
  double speed_m_s = 1.0;
  double start_height_m = 0.115;  // tool origin at start (above the 10 cm sphere)
  double end_height_m = 0.03;     // tool origin when it stops
  int hold_steps = 50;
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  int settle_steps = 100;  // let the sphere settle on the ground before the rest state is taken
  // > 0: ignore end_height_m and stop when the tool's lowest point is this far below the top of
  // the settled sphere.
  double end_depth_into_soft_m = 0.0;
  // Count soft triangles cut by the tool's interior (triangles_cut_by_tool, deeper than
  // cut_tolerance_m) after every step.
  bool check_triangles_cut = false;
  double cut_tolerance_m = 1e-6;
};

// Drives the tool straight down (−y) through the sphere at constant speed, then holds.
inline PlungeOutcome run_sphere_plunge(const ToolNodes& tool, SceneCollisionMethod method, const PlungeSpec& spec,
                                       const ThinBodyCollisionParams& params = ThinBodyCollisionParams{}) {
  SoftWorld world(true);
  world.add_sphere();
  for (int i = 0; i < spec.settle_steps; ++i) world.step_dynamics();
  auto collision = method == SceneCollisionMethod::kPaired ? make_paired_collision(tool, world.soft(), params)
                                                      : make_ray_collision(tool, world.soft(), params);
  CollisionStepResult result;
  result.reserve_for(world.soft().m_faces.size());
  ToolPose previous;
  previous.orientation_world = spec.orientation;
  previous.position_world_m = Eigen::Vector3d(0, spec.start_height_m, 0);
  CrossingTracker tracker(tool, world.node_positions(), previous);
  PlungeOutcome outcome;
  double below_origin_m = 0.0;  // lowest tool point relative to its origin (world y)
  for (const auto& p : tool.hull_vertices_tool_m()) below_origin_m = std::min(below_origin_m, (spec.orientation * p).y());
  outcome.soft_top_start_m = -1e9;
  for (const auto& p : world.node_positions()) outcome.soft_top_start_m = std::max(outcome.soft_top_start_m, p.y());
  const double end_height_m = spec.end_depth_into_soft_m > 0.0
                                  ? outcome.soft_top_start_m - spec.end_depth_into_soft_m - below_origin_m
                                  : spec.end_height_m;
  const double drop_per_step = spec.speed_m_s * kStep_s;
  const int move_steps = static_cast<int>(std::ceil((spec.start_height_m - end_height_m) / drop_per_step));
  for (int s = 1; s <= move_steps + spec.hold_steps; ++s) {
    ToolPose current = previous;
    current.position_world_m.y() = std::max(end_height_m, spec.start_height_m - drop_per_step * s);
    world.step_dynamics();
    collision->step(previous, current, kStep_s, world.soft(), result);
    const auto nodes = world.node_positions();
    for (const auto& p : nodes) outcome.positions_finite = outcome.positions_finite && p.allFinite();
    tracker.update(nodes, current);
    outcome.forces_finite = outcome.forces_finite && result.force_on_tool_world_n.allFinite();
    outcome.max_force_n = std::max(outcome.max_force_n, result.force_on_tool_world_n.norm());
    outcome.max_both_face_contacts = std::max(outcome.max_both_face_contacts, result.both_face_contacts);
    outcome.total_both_face_contacts += result.both_face_contacts;
    outcome.total_excluded += result.excluded_pairs;
    outcome.max_contacted_triangles = std::max(outcome.max_contacted_triangles, result.contacted_triangles);
    if (result.contacted_triangles > 0) {
      ++outcome.steps_in_contact;
      outcome.step_seconds.push_back(result.seconds_broad + result.seconds_narrow + result.seconds_response + result.seconds_force);
    }
    outcome.final_force_y_n = result.force_on_tool_world_n.y();
    outcome.force_y_n.push_back(result.force_on_tool_world_n.y());
    if (s == move_steps) outcome.force_y_at_arrival_n = result.force_on_tool_world_n.y();
    if (s >= move_steps) outcome.max_force_y_at_end_n = std::max(outcome.max_force_y_at_end_n, result.force_on_tool_world_n.y());
    if (spec.check_triangles_cut) {
      outcome.triangles_cut_end = triangles_cut_by_tool(tool, world.soft(), current, spec.cut_tolerance_m);
      outcome.max_triangles_cut = std::max(outcome.max_triangles_cut, outcome.triangles_cut_end);
    }
    previous = current;
  }
  outcome.tool_bottom_end_m = previous.position_world_m.y() + below_origin_m;
  outcome.crossed_nodes = tracker.crossed_nodes();
  outcome.max_penetration_m = tracker.max_penetration_m();
  outcome.final_nodes = world.node_positions();
  return outcome;
}

// The tools: a 40×4×40 mm plate, a 40×1×40 mm plate, the 1 mm plate turned to move edge-first.
inline ToolNodes plate_tool(double thickness_m) {
  BoxToolShape shape;
  shape.half_extents_m = Eigen::Vector3d(0.02, 0.5 * thickness_m, 0.02);
  shape.thin_axis = 1;
  shape.nodes_u = 9;
  shape.nodes_v = 9;
  return ToolNodes::from_box(shape);
}

// Blade edge-first: the 1 mm plate rotated 90° about z, so its thin axis is world x and it moves
// down along its own face.
inline Eigen::Quaterniond edge_first_orientation() {
  return Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * 3.14159265358979323846, Eigen::Vector3d::UnitZ()));
}

}  // namespace fissure::host::test_scene
