// Bullet's deformable world with FEM bodies (fem_world.hpp).
#include "fissure/host_sim/fem_world.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Geometry>

// Bullet's deformable headers define inline code (btReducedVector, btAlignedObjectArray::resize
// of default-constructed btVector3) that GCC 12 flags as maybe-uninitialised once inlined here.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletSoftBody/btDeformableBodySolver.h>
#include <BulletSoftBody/btDeformableGravityForce.h>
#include <BulletSoftBody/btDeformableLinearElasticityForce.h>
#include <BulletSoftBody/btDeformableMultiBodyConstraintSolver.h>
#include <BulletSoftBody/btDeformableMultiBodyDynamicsWorld.h>
#include <BulletSoftBody/btDeformableNeoHookeanForce.h>
#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <btBulletDynamicsCommon.h>

#include "fem_smoothed_strain_force.hpp"
#pragma GCC diagnostic pop

#include "fissure/host_sim/node_bounds_solver.hpp"

namespace fissure::host {

namespace {

// Newton residual norm below which the implicit step stops early [N·s] (Bullet's default 1e-4
// is for bodies of ~1 kg and 100+ N; a tissue specimen carries ~0.01–1 N).
constexpr btScalar kNewtonTolerance = 1e-9f;

btVector3 bt(const Eigen::Vector3d& v) { return {static_cast<btScalar>(v.x()), static_cast<btScalar>(v.y()), static_cast<btScalar>(v.z())}; }

}  // namespace

// The Newton iteration count and its stopping residual, and the CG solver's iteration cap, are
// protected members of Bullet's solver (default 1, 1e-4 and 300); a subclass is the only way to
// set them. It also hosts the in-solver contacts (SoftContactConstraint) in the implicit step.
//
// How a position projection enters Bullet's velocity solve: the implicit step solves for
// dv = v_{n+1} − v_n and ends with x_{n+1} = x_n + h·(v_n + dv) (+ the split velocity of its rigid
// contacts; applyTransforms). So the contact sees the step as the classic solver shows it — m_q
// the node's start x_n, m_x its predicted end x_n + h·v — and whatever it does to m_x comes back
// as dv = (m_x − x_n)/h − v_n, so Bullet's move puts the node where the projection did (a
// velocity the contact writes itself replaces v after that move: applyTransforms). begin_solve runs on the prediction from Bullet's initial guess (v_n, its rigid
// contacts' dv), and project after every Newton iteration: the next iteration's residual is
// evaluated at the projected positions, so the elastic response of the body around a held node
// is solved with it, as the classic solver's links are iterated with the contact.
class FemBodySolver final : public btDeformableBodySolver {
 public:
  void set_newton(int iterations, btScalar tolerance) {
    m_maxNewtonIterations = iterations;
    m_newtonTolerance = tolerance;
  }
  void set_cg(int max_iterations, btScalar tolerance) {
    m_cg = btConjugateGradient<btDeformableBackwardEulerObjective>(max_iterations);
    m_cg.setTolerance(tolerance);
  }
  void add_contact(btSoftBody* body, SoftContactConstraint* contact) { contacts_.push_back({body, contact}); }

  void solveDeformableConstraints(btScalar h) override {
    velocity_overrides_.clear();
    if (contacts_.empty() || !m_implicit) {
      btDeformableBodySolver::solveDeformableConstraints(h);
      return;
    }
    // Bullet's Newton loop (btDeformableBodySolver::solveDeformableConstraints, implicit, without
    // line search: FemWorld turns it off), each iteration followed by the contacts' projection.
    updateVelocity();
    with_contact_positions(h, [](btSoftBody& body, SoftContactConstraint& contact) {
      contact.begin_solve(body);
      contact.project(body);
    });
    for (int i = 0; i < m_maxNewtonIterations; ++i) {
      updateState();
      int counter = 0;
      for (int k = 0; k < m_softBodies.size(); ++k) {
        btSoftBody* psb = m_softBodies[k];
        for (int j = 0; j < psb->m_nodes.size(); ++j, ++counter) {
          if (psb->m_nodes[j].m_im > 0) m_residual[counter] = (-1. / psb->m_nodes[j].m_im) * m_dv[counter];
        }
      }
      m_objective->computeResidual(h, m_residual);
      const bool converged = m_objective->computeNorm(m_residual) < m_newtonTolerance && i > 0;
      if (!converged) {
        m_objective->applyDynamicFriction(m_residual);
        computeStep(m_ddv, m_residual);
        updateDv();
      }
      for (int j = 0; j < m_numNodes; ++j) {
        m_ddv[j].setZero();
        m_residual[j].setZero();
      }
      updateVelocity();
      with_contact_positions(h, [](btSoftBody& body, SoftContactConstraint& contact) { contact.project(body); });
      if (converged) break;
    }
    with_contact_positions(h, [](btSoftBody& body, SoftContactConstraint& contact) { contact.end_solve(body); });
    updateVelocity();
  }

  // Bullet moves every node by h·v; a velocity the contact wrote itself (end_solve: the rim's
  // inelastic velocities) is what the node carries into the next step, not how far it moves in
  // this one, so it replaces v after the move.
  void applyTransforms(btScalar h) override {
    btDeformableBodySolver::applyTransforms(h);
    for (const VelocityOverride& o : velocity_overrides_) {
      o.node->m_v = o.velocity;
      o.node->m_vn = o.velocity;
    }
    velocity_overrides_.clear();
  }

 private:
  // Runs `call` on every contact with m_q = x_n and m_x = x_n + h·(v + split v) of its body, then
  // takes back the positions it changed into m_dv and the velocities it wrote into the overrides
  // (see the class comment) and restores m_x = x_n; m_v is left at v_n + dv (updateVelocity's),
  // m_q at the prediction (updateState's). The scratch vectors keep their capacity from step to step.
  template <class Call>
  void with_contact_positions(btScalar h, Call call) {
    int offset = 0;
    for (int k = 0; k < m_softBodies.size(); ++k) {
      btSoftBody* psb = m_softBodies[k];
      const int count = psb->m_nodes.size();
      bool has_contact = false;
      for (const auto& c : contacts_) has_contact = has_contact || c.body == psb;
      if (!has_contact || !psb->isActive()) {
        offset += count;
        continue;
      }
      start_x_.resize(static_cast<std::size_t>(count));
      predicted_x_.resize(static_cast<std::size_t>(count));
      velocity_.resize(static_cast<std::size_t>(count));
      for (int j = 0; j < count; ++j) {
        btSoftBody::Node& n = psb->m_nodes[j];
        const auto u = static_cast<std::size_t>(j);
        start_x_[u] = n.m_x;
        velocity_[u] = n.m_v;
        predicted_x_[u] = n.m_x + h * (n.m_v + n.m_splitv);
        n.m_q = n.m_x;
        n.m_x = predicted_x_[u];
      }
      for (const auto& c : contacts_) {
        if (c.body == psb) call(*psb, *c.contact);
      }
      const btScalar inverse_h = 1 / h;
      for (int j = 0; j < count; ++j) {
        btSoftBody::Node& n = psb->m_nodes[j];
        const auto u = static_cast<std::size_t>(j);
        if (n.m_im > 0) {
          if (n.m_x != predicted_x_[u]) m_dv[offset + j] = (n.m_x - start_x_[u]) * inverse_h - n.m_splitv - m_backupVelocity[offset + j];
          if (n.m_v != velocity_[u]) velocity_overrides_.push_back({&n, n.m_v});
        }
        n.m_x = start_x_[u];
        n.m_q = predicted_x_[u];
        n.m_v = velocity_[u];
      }
      offset += count;
    }
    updateVelocity();
  }

  struct Contact {
    btSoftBody* body;
    SoftContactConstraint* contact;
  };
  std::vector<Contact> contacts_;
  struct VelocityOverride {
    btSoftBody::Node* node;
    btVector3 velocity;
  };
  std::vector<VelocityOverride> velocity_overrides_;  // end_solve's, applied after the move (applyTransforms)
  std::vector<btVector3> start_x_, predicted_x_, velocity_;  // per node of the body being projected (reused)
};

double thinnest_tetrahedron_m(const VolumeMesh& mesh) noexcept {
  double thinnest = std::numeric_limits<double>::infinity();
  const auto corner = [&mesh](int v) {
    const Vec3& p = mesh.vertices_m[static_cast<std::size_t>(v)];
    return Eigen::Vector3d(p[0], p[1], p[2]);
  };
  for (const auto& t : mesh.tetrahedra) {
    const Eigen::Vector3d a = corner(t[0]), b = corner(t[1]), c = corner(t[2]), d = corner(t[3]);
    const double six_volume = std::abs((b - a).cross(c - a).dot(d - a));
    const double twice_largest_face = std::max({(c - b).cross(d - b).norm(), (c - a).cross(d - a).norm(), (b - a).cross(d - a).norm(), (b - a).cross(c - a).norm()});
    if (twice_largest_face > 0.0) thinnest = std::min(thinnest, six_volume / twice_largest_face);  // 3V / A_max
  }
  return thinnest;
}

double fem_stable_step_s(const VolumeMesh& mesh, const FemMaterial& material, double courant) noexcept {
  return courant * thinnest_tetrahedron_m(mesh) / p_wave_speed_m_per_s(material);
}

FemWorld::FemWorld(const FemWorldConfig& config) : config_(config) {
  configuration_ = std::make_unique<btSoftBodyRigidBodyCollisionConfiguration>();
  dispatcher_ = std::make_unique<btCollisionDispatcher>(configuration_.get());
  broadphase_ = std::make_unique<btDbvtBroadphase>();
  auto solver = std::make_unique<FemBodySolver>();
  fem_solver_ = solver.get();
  solver->set_newton(config.implicit ? std::max(1, config.newton_iterations) : 1, kNewtonTolerance);
  solver->set_cg(config.cg_max_iterations, static_cast<btScalar>(config.cg_tolerance));
  deformable_solver_ = std::move(solver);
  constraint_solver_ = std::make_unique<btDeformableMultiBodyConstraintSolver>();
  constraint_solver_->setDeformableSolver(deformable_solver_.get());
  world_ = std::make_unique<btDeformableMultiBodyDynamicsWorld>(dispatcher_.get(), broadphase_.get(), constraint_solver_.get(), configuration_.get(),
                                                                deformable_solver_.get());
  const btVector3 gravity = bt(config.gravity_world_m_per_s2);
  world_->setGravity(gravity);
  btSoftBodyWorldInfo& info = world_->getWorldInfo();
  info.m_gravity = gravity;
  info.m_sparsesdf.Initialize();  // forces a 0.25 m voxel (BRIEF §3): set ours after it
  info.m_sparsesdf.setDefaultVoxelsz(static_cast<btScalar>(config.sdf_voxel_m));
  info.m_sparsesdf.Reset();
  world_->setImplicit(config.implicit);
  world_->setLineSearch(false);
  // Contacts and fixed nodes as projections in a CG solve (Baraff & Witkin), as Bullet's demos.
  world_->setUseProjection(true);
  if (config.has_ground) {
    const Eigen::Vector3d half(1.0, 0.5, 1.0);
    shapes_.push_back(std::make_unique<btBoxShape>(bt(half)));
    btTransform pose = btTransform::getIdentity();
    pose.setOrigin(btVector3(0, static_cast<btScalar>(config.ground_top_y_m - half.y()), 0));
    motion_states_.push_back(std::make_unique<btDefaultMotionState>(pose));
    rigid_bodies_.push_back(std::make_unique<btRigidBody>(btRigidBody::btRigidBodyConstructionInfo(0, motion_states_.back().get(), shapes_.back().get())));
    rigid_bodies_.back()->setFriction(static_cast<btScalar>(config.ground_friction_ratio));
    world_->addRigidBody(rigid_bodies_.back().get());
  }
}

FemWorld::~FemWorld() {
  for (auto& body : bodies_) world_->removeSoftBody(body.get());
  for (auto& rigid : rigid_bodies_) world_->removeRigidBody(rigid.get());
}

int FemWorld::add_body(const VolumeMesh& mesh, const FemMaterial& material, const FemContact& contact) {
  // Bullet keeps one force object per force type: addForce attaches a later body to the first
  // force of its type (btDeformableMultiBodyDynamicsWorld::addForce), with that force's (μ, λ).
  // Bodies of one world therefore share their material; a different one is refused here rather
  // than silently simulated with the first body's.
  if (!bodies_.empty() && (material.model != materials_.front().model || material.youngs_modulus_pa != materials_.front().youngs_modulus_pa ||
                           material.poisson_ratio != materials_.front().poisson_ratio || material.mass_damping_per_s != materials_.front().mass_damping_per_s ||
                           material.stiffness_damping_s != materials_.front().stiffness_damping_s)) {
    throw std::invalid_argument("FemWorld: Bullet's deformable world keeps one force per type, so every body of a world has the first body's elasticity and damping");
  }
  bodies_.emplace_back(create_fem_body(world_->getWorldInfo(), mesh, material, contact));
  materials_.push_back(material);
  btSoftBody* body = bodies_.back().get();
  world_->addSoftBody(body);
  if (bodies_.size() > 1) {
    // Attached to the first body's forces (the comment above).
    for (btDeformableLagrangianForce* f : first_body_forces_) world_->addForce(body, f);
    elastic_.push_back(elastic_.front());
    return static_cast<int>(bodies_.size()) - 1;
  }
  const LameParameters lame = bullet_lame_parameters(material);
  const auto mu = static_cast<btScalar>(lame.mu_pa), lambda = static_cast<btScalar>(lame.lambda_pa);
  if (material.model == FemModel::kNeoHookean) {
    forces_.push_back(std::make_unique<btDeformableNeoHookeanForce>(mu, lambda, static_cast<btScalar>(material.stiffness_damping_s)));
  } else if (material.model == FemModel::kCorotatedSmoothed) {
    forces_.push_back(std::make_unique<SmoothedStrainElasticityForce>(mu, lambda, static_cast<btScalar>(material.mass_damping_per_s),
                                                                      static_cast<btScalar>(material.stiffness_damping_s)));
  } else {
    forces_.push_back(std::make_unique<btDeformableLinearElasticityForce>(mu, lambda, static_cast<btScalar>(material.mass_damping_per_s),
                                                                         static_cast<btScalar>(material.stiffness_damping_s)));
  }
  elastic_.push_back(forces_.back().get());
  if (material.model == FemModel::kNeoHookean && material.mass_damping_per_s > 0.0) {
    // The Neo-Hookean force has no mass-proportional term: the linear force with zero stiffness
    // and only α supplies it (the only linear force of the world: all bodies share the model).
    forces_.push_back(std::make_unique<btDeformableLinearElasticityForce>(0, 0, static_cast<btScalar>(material.mass_damping_per_s), 0));
  }
  if (!config_.gravity_world_m_per_s2.isZero()) forces_.push_back(std::make_unique<btDeformableGravityForce>(bt(config_.gravity_world_m_per_s2)));
  for (auto& f : forces_) {
    first_body_forces_.push_back(f.get());
    world_->addForce(body, f.get());
  }
  return 0;
}

void FemWorld::fix_nodes(int b, const std::vector<int>& nodes) {
  btSoftBody& body = *bodies_[static_cast<std::size_t>(b)];
  for (int n : nodes) {
    body.setMass(n, 0);
    body.m_nodes[n].m_v.setZero();
  }
}

void FemWorld::move_fixed_node(int b, int node, const Eigen::Vector3d& p) noexcept {
  btSoftBody::Node& n = bodies_[static_cast<std::size_t>(b)]->m_nodes[node];
  n.m_x = bt(p);
  n.m_q = n.m_x;
  n.m_v.setZero();
  n.m_vn.setZero();
}

int FemWorld::add_kinematic_box(const Eigen::Vector3d& half_extents_m, const Eigen::Vector3d& centre_world_m, double friction_ratio) {
  shapes_.push_back(std::make_unique<btBoxShape>(bt(half_extents_m)));
  btTransform pose = btTransform::getIdentity();
  pose.setOrigin(bt(centre_world_m));
  motion_states_.push_back(std::make_unique<btDefaultMotionState>(pose));
  rigid_bodies_.push_back(std::make_unique<btRigidBody>(btRigidBody::btRigidBodyConstructionInfo(0, motion_states_.back().get(), shapes_.back().get())));
  btRigidBody* box = rigid_bodies_.back().get();
  box->setCollisionFlags(box->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
  box->setActivationState(DISABLE_DEACTIVATION);
  box->setFriction(static_cast<btScalar>(friction_ratio));
  world_->addRigidBody(box);
  boxes_.push_back(box);
  return static_cast<int>(boxes_.size()) - 1;
}

void FemWorld::set_box_centre(int box, const Eigen::Vector3d& centre_world_m) noexcept {
  btTransform pose = btTransform::getIdentity();
  pose.setOrigin(bt(centre_world_m));
  boxes_[static_cast<std::size_t>(box)]->getMotionState()->setWorldTransform(pose);
}

void FemWorld::add_solver_contact(int b, SoftContactConstraint* contact) {
  if (!config_.implicit) throw std::logic_error("FemWorld::add_solver_contact: the contact is solved in the implicit step's Newton iterations; this world steps symplectically");
  fem_solver_->add_contact(bodies_[static_cast<std::size_t>(b)].get(), contact);
}

void FemWorld::step(double h_s) noexcept {
  const auto h = static_cast<btScalar>(h_s);
  world_->stepSimulation(h, 1, h);
  world_->getWorldInfo().m_sparsesdf.GarbageCollect();
}

void FemWorld::elastic_forces(int b, std::vector<Eigen::Vector3d>& out) {
  // The force writes each node's share at Node::index, which the solver numbers over all bodies
  // of the world at its first step (0 for every node before it), and one force object may hold
  // several bodies (add_body): number every node of the world 0…N−1, body after body, for the
  // call and put the solver's numbers back.
  std::vector<int> solver_index;
  int offset = 0, first = 0;
  for (std::size_t k = 0; k < bodies_.size(); ++k) {
    btSoftBody& body = *bodies_[k];
    if (static_cast<int>(k) == b) first = offset;
    for (int i = 0; i < body.m_nodes.size(); ++i) {
      solver_index.push_back(body.m_nodes[i].index);
      body.m_nodes[i].index = offset++;
    }
  }
  btAlignedObjectArray<btVector3> force;
  force.resize(offset, btVector3(0, 0, 0));
  // The scratch (deformation gradient, corotation) is evaluated at m_q; a step overwrites both
  // before it reads them (predictMotion sets m_q from m_x, then advanceDeformation).
  for (auto& body : bodies_) {
    for (int i = 0; i < body->m_nodes.size(); ++i) body->m_nodes[i].m_q = body->m_nodes[i].m_x;
    body->updateDeformation();
  }
  elastic_[static_cast<std::size_t>(b)]->addScaledExplicitForce(1, force);  // the elastic force alone, for both models
  std::size_t restore = 0;
  for (auto& body : bodies_) {
    for (int i = 0; i < body->m_nodes.size(); ++i) body->m_nodes[i].index = solver_index[restore++];
  }
  const btSoftBody& body = *bodies_[static_cast<std::size_t>(b)];
  out.resize(static_cast<std::size_t>(body.m_nodes.size()));
  for (int i = 0; i < body.m_nodes.size(); ++i) {
    const btVector3& f = force[first + i];
    out[static_cast<std::size_t>(i)] = Eigen::Vector3d(f.x(), f.y(), f.z());
  }
}

double FemWorld::max_node_speed_m_per_s(int b) const noexcept {
  const btSoftBody& body = *bodies_[static_cast<std::size_t>(b)];
  double v2 = 0.0;
  for (int i = 0; i < body.m_nodes.size(); ++i) v2 = std::max(v2, static_cast<double>(body.m_nodes[i].m_v.length2()));
  return std::sqrt(v2);
}

Eigen::Vector3d FemWorld::node_position_m(int b, int node) const noexcept {
  const btVector3& x = bodies_[static_cast<std::size_t>(b)]->m_nodes[node].m_x;
  return {x.x(), x.y(), x.z()};
}

}  // namespace fissure::host
