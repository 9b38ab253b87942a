// The Bullet world of a scene (soft_world.hpp).
#include "fissure/host_sim/soft_world.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

#include <BulletCollision/CollisionShapes/btBoxShape.h>
#include <BulletCollision/CollisionShapes/btConvexHullShape.h>
#include <BulletDynamics/ConstraintSolver/btSequentialImpulseConstraintSolver.h>
#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>

#include "fissure/host_sim/fem_world.hpp"
#include "fissure/host_sim/soft_body_builder.hpp"

namespace fissure::host {

namespace {

// The tool's Bullet shape margin, as a fraction of its half thickness. Measured here: with a
// small margin, btGjkEpaSolver2::SignedDistance (which fills btSparseSdf's voxels) returns
// POSITIVE distances for points inside a thin box away from its centre (GJK reports
// "separated"), so Bullet's SDF reads +0.5…1 mm inside a 4 mm plate and never pushes an
// entered node out — it leaks even at 0.1 m/s. With a margin close to the half thickness
// the shape is a thin core + margin and GJK's distances are right (negative) inside. The
// fair baseline therefore uses 0.9 × half thickness: the box keeps its outer size (its
// edges round off, like the convex spatula's rim).
constexpr double kToolShapeMarginRatio = 0.9;

// When only the ground meets the soft body through Bullet (paired / ray), the SDF only has
// to represent a flat box face, which trilinear interpolation reproduces exactly at any
// voxel size; a 1 cm voxel keeps the number of lazily built cells (each a GJK query per
// corner) small. Measured: with the 1 mm tool voxel a 5120-face ball pressed on the ground
// spent ~2 ms per step building ground cells.
constexpr double kGroundOnlyVoxelM = 0.01;

// FEM: the CG cap when stiffness damping couples the nodes (Bullet's own default), and the most
// symplectic substeps a host step may take — past that a 1 ms host step costs more than a
// session can wait for (measured: ~1 ms per substep at 1,000 nodes, docs/decisions.md).
constexpr int kFemDampedCgIterations = 300;
constexpr int kFemMaxSubsteps = 64;

// FEM with the in-solver contact: one implicit (backward Euler) step per host step, its Newton
// iterations each followed by the contact's projection (fem_world.cpp), each a CG solve capped
// at this many iterations (docs/decisions.md, "Tissue (issue 24)", for the figures behind both).
constexpr int kFemInSolverNewtonIterations = 1;
constexpr int kFemInSolverCgIterations = 10;

btVector3 bt(const Vec3& v) { return {static_cast<btScalar>(v[0]), static_cast<btScalar>(v[1]), static_cast<btScalar>(v[2])}; }
btVector3 bt(const Eigen::Vector3d& v) { return {static_cast<btScalar>(v.x()), static_cast<btScalar>(v.y()), static_cast<btScalar>(v.z())}; }

btTransform bt(const ToolPose& pose) {
  const Eigen::Quaterniond& q = pose.orientation_world;
  return btTransform(btQuaternion(static_cast<btScalar>(q.x()), static_cast<btScalar>(q.y()), static_cast<btScalar>(q.z()), static_cast<btScalar>(q.w())),
                     bt(pose.position_world_m));
}

}  // namespace

ToolPose to_tool_pose(const Pose& pose) noexcept {
  ToolPose out;
  out.position_world_m = Eigen::Vector3d(pose.position_world_m[0], pose.position_world_m[1], pose.position_world_m[2]);
  out.orientation_world = Eigen::Quaterniond(pose.orientation_world[0], pose.orientation_world[1], pose.orientation_world[2], pose.orientation_world[3]).normalized();
  return out;
}

Eigen::Isometry3d to_isometry(const ToolPose& pose) noexcept {
  Eigen::Isometry3d iso = Eigen::Isometry3d::Identity();
  iso.linear() = pose.orientation_world.toRotationMatrix();
  iso.translation() = pose.position_world_m;
  return iso;
}

ToolPartGeometry tool_part_geometry(const SceneDescription& scene) {
  ToolPartGeometry g;
  switch (scene.tool.kind) {
    case ToolKind::kBox:
      g.box_half_extents_m = 0.5 * Eigen::Vector3d(scene.tool.box_size_m[0], scene.tool.box_size_m[1], scene.tool.box_size_m[2]);
      g.thickness_m = scene.tool.box_size_m[1];
      break;
    case ToolKind::kClamp:
      g.part_count = 2;
      g.box_half_extents_m = 0.5 * Eigen::Vector3d(scene.tool.clamp.jaw_size_m[0], scene.tool.clamp.jaw_size_m[1], scene.tool.clamp.jaw_size_m[2]);
      g.thickness_m = scene.tool.clamp.jaw_size_m[1];
      break;
    case ToolKind::kConvexMesh: {
      g.is_mesh = true;
      double lo = 1e300, hi = -1e300;
      for (const Vec3& v : scene.tool.mesh_vertices_tool_m) {
        lo = std::min(lo, v[1]);
        hi = std::max(hi, v[1]);
      }
      g.thickness_m = hi - lo;
      break;
    }
  }
  return g;
}

void tool_part_poses(const SceneDescription& scene, const ToolPose& tool, double jaw_gap_m, std::array<ToolPose, kMaxToolParts>& parts) noexcept {
  if (scene.tool.kind != ToolKind::kClamp) {
    parts[0] = tool;
    parts[1] = tool;
    return;
  }
  const double gap_m = std::clamp(jaw_gap_m, scene.tool.clamp.jaw_gap_min_m, scene.tool.clamp.jaw_gap_open_m);
  const double offset_m = 0.5 * (gap_m + scene.tool.clamp.jaw_size_m[1]);
  for (int p = 0; p < 2; ++p) {
    ToolPose& part = parts[static_cast<std::size_t>(p)];
    part.orientation_world = tool.orientation_world;
    part.position_world_m = tool.to_world(Eigen::Vector3d(0.0, p == 0 ? offset_m : -offset_m, 0.0));
  }
}

void SoftWorld::make_tool_parts(const SceneDescription& scene) {
  // Kinematic bodies (the tool is driven, never pushed).
  for (int p = 0; p < geometry_.part_count; ++p) {
    const double margin_m = kToolShapeMarginRatio * 0.5 * geometry_.thickness_m;
    if (geometry_.is_mesh) {
      // btConvexHullShape adds its margin OUTSIDE the hull: give it the mesh's core, the
      // mesh shrunk by the margin (y flattened, x and z pulled in), so core + margin ≈ mesh.
      Eigen::AlignedBox3d bounds;
      for (const Vec3& v : scene.tool.mesh_vertices_tool_m) bounds.extend(Eigen::Vector3d(v[0], v[1], v[2]));
      const Eigen::Vector3d half = 0.5 * bounds.sizes(), centre = bounds.center();
      const Eigen::Vector3d scale(1.0 - margin_m / half.x(), 1.0 - margin_m / half.y(), 1.0 - margin_m / half.z());
      auto hull = std::make_unique<btConvexHullShape>();
      for (const Vec3& v : scene.tool.mesh_vertices_tool_m) {
        hull->addPoint(bt(Eigen::Vector3d(centre + scale.cwiseProduct(Eigen::Vector3d(v[0], v[1], v[2]) - centre))), false);
      }
      hull->recalcLocalAabb();
      hull->setMargin(static_cast<btScalar>(margin_m));
      shapes_.push_back(std::move(hull));
    } else {
      auto box = std::make_unique<btBoxShape>(bt(geometry_.box_half_extents_m));
      box->setMargin(static_cast<btScalar>(margin_m));  // keeps the outer size
      shapes_.push_back(std::move(box));
    }
    motion_states_.push_back(std::make_unique<btDefaultMotionState>(btTransform::getIdentity()));
    auto body = std::make_unique<btRigidBody>(btRigidBody::btRigidBodyConstructionInfo(0, motion_states_.back().get(), shapes_.back().get()));
    body->setCollisionFlags(body->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
    body->setActivationState(DISABLE_DEACTIVATION);
    body->setFriction(0);
    parts_[static_cast<std::size_t>(p)] = std::move(body);
  }
  std::array<ToolPose, kMaxToolParts> start{};
  tool_part_poses(scene, to_tool_pose(scene.trajectory.start), scene.trajectory.start_jaw_gap_m >= 0.0 ? scene.trajectory.start_jaw_gap_m : scene.tool.clamp.jaw_gap_open_m, start);
  for (int p = 0; p < geometry_.part_count; ++p) {
    btRigidBody& body = *parts_[static_cast<std::size_t>(p)];
    body.setWorldTransform(bt(start[static_cast<std::size_t>(p)]));
    body.getMotionState()->setWorldTransform(bt(start[static_cast<std::size_t>(p)]));
    body.setInterpolationWorldTransform(bt(start[static_cast<std::size_t>(p)]));
  }
}

// FEM bodies step in Bullet's deformable world (fem_world.hpp): its own solver, not the classic
// one the node-bounds solver replaces, so the broad phase reads every node. With after_step the
// thin-body contact acts after each step; with in_solver each host step is one implicit step whose
// Newton iterations the contact is projected after (FemWorld::add_solver_contact) — the
// placement that after_step makes does not survive an implicit step, and the stable step's
// substeps are what makes after_step costly (docs/decisions.md, "Tissue (issue 24)"). Every body of the scene is FEM (Bullet's deformable and
// classic soft bodies live in different worlds) and shares the first body's material (Bullet
// keeps one force per type: FemWorld::add_body). Anchored nodes are fixed (Dirichlet: mass 0),
// the bed being rigid. The host step is cut into symplectic substeps no longer than the stable
// step of the stiffest body (fem_stable_step_s): a 1 ms step is unstable on any mesh finer than
// ~c_p × 1 ms (docs/decisions.md, "Tissue (issue 24)").
void SoftWorld::build_fem_world(const SceneDescription& scene) {
  for (const SoftBodyDescription& body : scene.soft_bodies) {
    if (body.model != SoftBodyModel::kFem) {
      throw std::invalid_argument("[[soft_body]]: an FEM body (model = \"fem\") and a shell cannot share a scene (Bullet steps them in different worlds); make every body \"fem\" or every body a shell");
    }
  }
  if (parts_in_world_) {
    throw std::invalid_argument("the bullet collision method runs shell bodies only; an FEM body (model = \"fem\") meets the tool through the paired or ray method");
  }
  FemWorldConfig config;
  config.gravity_world_m_per_s2 = as_eigen(scene.simulation.gravity_world_m_per_s2);
  config.has_ground = true;
  config.ground_top_y_m = scene.ground.top_height_m;
  config.ground_friction_ratio = scene.ground.friction_ratio;
  // With mass damping alone the symplectic step's linear system is diagonal and one CG iteration
  // solves it exactly; stiffness damping couples the nodes and needs the solve (Bullet's cap).
  const bool stiffness_damped = std::any_of(scene.soft_bodies.begin(), scene.soft_bodies.end(),
                                            [](const SoftBodyDescription& body) { return body.fem.stiffness_damping_s > 0.0; });
  config.cg_max_iterations = stiffness_damped ? kFemDampedCgIterations : 1;
  const bool in_solver = scene.simulation.contact_response == ContactResponse::kInSolver;
  if (in_solver) {
    config.implicit = true;
    config.newton_iterations = kFemInSolverNewtonIterations;
    config.cg_max_iterations = kFemInSolverCgIterations;
  }
  fem_ = std::make_unique<FemWorld>(config);
  const double host_step_s = scene.simulation.time_step_s / std::max(1, scene.simulation.substeps_count);
  double stable_step_s = std::numeric_limits<double>::infinity();
  first_nodes_.push_back(0);
  for (const SoftBodyDescription& description : scene.soft_bodies) {
    const SoftMesh& file = std::get<SoftMesh>(description.shape);  // the loader's check: a tetrahedral mesh
    const VolumeMesh mesh{file.vertices_world_m, file.tetrahedra, file.triangles};
    const int b = fem_->add_body(mesh, description.fem, FemContact{description.collision_margin_m, description.friction_ratio});
    stable_step_s = std::min(stable_step_s, fem_stable_step_s(mesh, description.fem));
    const std::vector<int> fixed = anchored_nodes(file.vertices_world_m, description);
    fem_->fix_nodes(b, fixed);
    anchored_nodes_count_ += static_cast<int>(fixed.size());
    bodies_.push_back(&fem_->body(b));
    first_nodes_.push_back(first_nodes_.back() + fem_->body(b).m_nodes.size());
  }
  sdf_voxel_m_ = config.sdf_voxel_m;
  fem_start_x_.resize(static_cast<std::size_t>(first_nodes_.back()));
  fem_substeps_ = in_solver ? 1 : std::max(1, static_cast<int>(std::ceil(host_step_s / stable_step_s)));
  if (fem_substeps_ > kFemMaxSubsteps) {
    throw std::invalid_argument("[soft_body] model = \"fem\": a " + std::to_string(host_step_s * 1e3) + " ms step needs " + std::to_string(fem_substeps_) +
                                " substeps for this mesh and material (the stable step is " + std::to_string(stable_step_s * 1e6) +
                                " us: 0.3 sqrt 2 x the thinnest tetrahedron's height / the P-wave speed); at most " + std::to_string(kFemMaxSubsteps) +
                                " are run — use a coarser mesh, a softer material or a shorter time_step_s");
  }
  make_tool_parts(scene);
}

SoftWorld::SoftWorld(const SceneDescription& scene, bool tool_collides_in_bullet, bool instrumented_solver)
    : geometry_(tool_part_geometry(scene)), parts_in_world_(tool_collides_in_bullet) {
  if (scene.soft_bodies.empty() || static_cast<int>(scene.soft_bodies.size()) > kMaxSoftBodies) {
    throw std::invalid_argument("a scene holds 1 to " + std::to_string(kMaxSoftBodies) + " soft bodies (got " + std::to_string(scene.soft_bodies.size()) + ")");
  }
  const auto is_fem = [](const SoftBodyDescription& body) { return body.model == SoftBodyModel::kFem; };
  if (std::any_of(scene.soft_bodies.begin(), scene.soft_bodies.end(), is_fem)) {
    build_fem_world(scene);
    return;
  }
  // Bullet's own tool contact (the baseline) is measured by a probe that watches one body.
  if (tool_collides_in_bullet && scene.soft_bodies.size() > 1) {
    throw std::invalid_argument("the bullet collision method runs scenes with one soft body (this one has " + std::to_string(scene.soft_bodies.size()) +
                                "); use paired or ray");
  }
  configuration_ = std::make_unique<btSoftBodyRigidBodyCollisionConfiguration>();
  dispatcher_ = std::make_unique<btCollisionDispatcher>(configuration_.get());
  broadphase_ = std::make_unique<btDbvtBroadphase>();
  solver_ = std::make_unique<btSequentialImpulseConstraintSolver>();
  if (tool_collides_in_bullet && instrumented_solver) {
    auto probe = std::make_unique<ContactProbeSolver>();
    probe_ = probe.get();
    soft_solver_ = std::move(probe);
  } else if (instrumented_solver) {
    auto bounding = std::make_unique<NodeBoundsSolver>();
    bounding_solver_ = bounding.get();
    soft_solver_ = std::move(bounding);
  } else {
    soft_solver_ = std::make_unique<btDefaultSoftBodySolver>();
  }
  world_ = std::make_unique<btSoftRigidDynamicsWorld>(dispatcher_.get(), broadphase_.get(), solver_.get(), configuration_.get(), soft_solver_.get());
  const btVector3 gravity = bt(scene.simulation.gravity_world_m_per_s2);
  world_->setGravity(gravity);
  btSoftBodyWorldInfo& info = world_->getWorldInfo();
  info.m_gravity = gravity;
  info.m_dispatcher = dispatcher_.get();
  info.m_broadphase = broadphase_.get();
  // Initialize() forces a 0.25 m voxel; the fair baseline needs ~half the tool thickness.
  sdf_voxel_m_ = tool_collides_in_bullet ? 0.5 * geometry_.thickness_m : kGroundOnlyVoxelM;
  info.m_sparsesdf.Initialize();
  info.m_sparsesdf.setDefaultVoxelsz(static_cast<btScalar>(sdf_voxel_m_));
  info.m_sparsesdf.Reset();

  // Ground: a static box whose top face is at ground.top_height_m.
  const GroundDescription& g = scene.ground;
  shapes_.push_back(std::make_unique<btBoxShape>(bt(g.half_extents_m)));
  btTransform ground_pose = btTransform::getIdentity();
  ground_pose.setOrigin(btVector3(0, static_cast<btScalar>(g.top_height_m - g.half_extents_m[1]), 0));
  motion_states_.push_back(std::make_unique<btDefaultMotionState>(ground_pose));
  ground_ = std::make_unique<btRigidBody>(btRigidBody::btRigidBodyConstructionInfo(0, motion_states_.back().get(), shapes_.back().get()));
  ground_->setFriction(static_cast<btScalar>(g.friction_ratio));
  world_->addRigidBody(ground_.get());

  make_tool_parts(scene);
  if (parts_in_world_) {
    for (int p = 0; p < geometry_.part_count; ++p) world_->addRigidBody(parts_[static_cast<std::size_t>(p)].get());
  }

  // [[soft_body.anchor]]: tie the selected rest nodes to the ground (the bed the tissue lies on).
  try {
    for (const SoftBodyDescription& description : scene.soft_bodies) {
      softs_.emplace_back(build_soft_body(info, description));
      anchored_nodes_count_ += anchor_soft_body(*softs_.back(), *ground_, description);
    }
  } catch (...) {
    // The destructor does not run for a half-built world: take the bodies out of it here, or
    // the world's own destructor would touch their freed broadphase proxies.
    for (int p = 0; p < geometry_.part_count; ++p) {
      if (parts_in_world_) world_->removeRigidBody(parts_[static_cast<std::size_t>(p)].get());
    }
    world_->removeRigidBody(ground_.get());
    throw;
  }
  first_nodes_.push_back(0);
  for (const auto& body : softs_) {
    // Vertex–face soft–soft contact only (Bullet's classic handler runs VF_SS when it is the
    // only soft–soft bit of both bodies): the cluster variant needs clusters, which the
    // node-bounds solver does not reproduce.
    if (softs_.size() > 1) body->m_cfg.collisions = btSoftBody::fCollision::SDF_RS | btSoftBody::fCollision::VF_SS;
    world_->addSoftBody(body.get());
    bodies_.push_back(body.get());
    first_nodes_.push_back(first_nodes_.back() + body->m_nodes.size());
  }
  if (probe_ != nullptr) {
    std::array<const btCollisionObject*, kMaxToolParts> objects{};
    for (int p = 0; p < geometry_.part_count; ++p) objects[static_cast<std::size_t>(p)] = parts_[static_cast<std::size_t>(p)].get();
    probe_->attach(softs_.front().get(), objects);
  }
  if (bounding_solver_ != nullptr) {
    for (const auto& body : softs_) bounding_solver_->attach(body.get());
  }
}

SoftWorld::~SoftWorld() {
  if (world_) {
    for (const auto& body : softs_) world_->removeSoftBody(body.get());
    for (int p = 0; p < geometry_.part_count; ++p) {
      if (parts_in_world_) world_->removeRigidBody(parts_[static_cast<std::size_t>(p)].get());
    }
    world_->removeRigidBody(ground_.get());
  }
}

void SoftWorld::add_solver_contact(SoftContactConstraint* contact, int body) {
  if (fem_) {
    fem_->add_solver_contact(body, contact);
    return;
  }
  if (bounding_solver_ == nullptr) throw std::invalid_argument("contact_response = \"in_solver\" needs the instrumented soft-body solver (HostSimulationOptions::solver_node_bounds)");
  const btSoftBody& soft = *bodies_[static_cast<std::size_t>(body)];
  // The contact is solved in the NodeBoundsSolver's own copy of Bullet's position block, which it
  // runs only for a body it can reproduce (node_bounds_solver.cpp).
  if (soft.m_clusters.size() != 0 || soft.m_cfg.diterations != 0 || soft.m_cfg.piterations <= 0)
    throw std::invalid_argument("contact_response = \"in_solver\" needs a soft body with position iterations, no clusters and no drift iterations");
  bounding_solver_->add_contact(contact, body);
}

void SoftWorld::set_part_pose(int part, const ToolPose& pose) noexcept {
  btRigidBody& body = *parts_[static_cast<std::size_t>(part)];
  body.getMotionState()->setWorldTransform(bt(pose));
  if (!parts_in_world_) body.setWorldTransform(bt(pose));  // not stepped by the world
}

void SoftWorld::teleport_part(int part, const ToolPose& pose) noexcept {
  btRigidBody& body = *parts_[static_cast<std::size_t>(part)];
  const btTransform transform = bt(pose);
  body.getMotionState()->setWorldTransform(transform);
  body.setWorldTransform(transform);
  // A kinematic body's velocity for the next step is (motion-state pose − this pose) / dt
  // (btRigidBody::saveKinematicState): both at the new pose, it starts from rest.
  body.setInterpolationWorldTransform(transform);
  body.setLinearVelocity(btVector3(0, 0, 0));
  body.setAngularVelocity(btVector3(0, 0, 0));
  body.setInterpolationLinearVelocity(btVector3(0, 0, 0));
  body.setInterpolationAngularVelocity(btVector3(0, 0, 0));
}

void SoftWorld::step(double h_s) noexcept {
  if (fem_) {
    // Bullet's deformable step ends with m_q = m_x (btDeformableBodySolver's integration), and the
    // thin-body sweep reads m_q as where a node started the step: without this, a node's own
    // motion over the step would be invisible to it (a body springing back through a thin tool at
    // 10 m/s crossed it: 15 nodes on a 147-node block). end_step() gives Bullet its m_q back.
    std::size_t i = 0;
    for (const btSoftBody* body : bodies_) {
      for (int n = 0; n < body->m_nodes.size(); ++n) fem_start_x_[i++] = body->m_nodes[n].m_x;
    }
    const double substep_s = h_s / fem_substeps_;
    for (int k = 0; k < fem_substeps_; ++k) fem_->step(substep_s);
    i = 0;
    for (btSoftBody* body : bodies_) {
      for (int n = 0; n < body->m_nodes.size(); ++n) body->m_nodes[n].m_q = fem_start_x_[i++];
    }
    return;
  }
  if (probe_ != nullptr) probe_->clear();
  const auto h = static_cast<btScalar>(h_s);
  world_->stepSimulation(h, 1, h);
  // The sparse SDF caches cells per shape; drop the ones not used for a while (as Bullet's
  // demos do every frame) so a long run does not hit the cell cap and reset.
  world_->getWorldInfo().m_sparsesdf.GarbageCollect();
}

void SoftWorld::end_step() noexcept {
  if (!fem_) return;
  // The next deformable step evaluates the elastic force at m_q, which its integration left at
  // m_x (x_n): as it was, with the contact's placement of the nodes.
  for (btSoftBody* body : bodies_) {
    for (int n = 0; n < body->m_nodes.size(); ++n) body->m_nodes[n].m_q = body->m_nodes[n].m_x;
  }
}

void SoftWorld::copy_node_positions(std::vector<Eigen::Vector3d>& out) const {
  out.resize(static_cast<std::size_t>(first_nodes_.back()));
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const btSoftBody& body = *bodies_[b];
    const auto first = static_cast<std::size_t>(first_nodes_[b]);
    for (int i = 0; i < body.m_nodes.size(); ++i) {
      const btVector3& x = body.m_nodes[i].m_x;
      out[first + static_cast<std::size_t>(i)] = Eigen::Vector3d(x.x(), x.y(), x.z());
    }
  }
}

}  // namespace fissure::host
