// Bullet's SDF_RS baseline and the exact measurement of its contact reaction
// (bullet_collision.hpp).
#include "fissure/host_sim/bullet_collision.hpp"

#include <algorithm>
#include <cmath>

#include <BulletCollision/CollisionDispatch/btCollisionObjectWrapper.h>
#include <BulletSoftBody/btSoftBody.h>

namespace fissure::host {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

Eigen::Vector3d e3(const btVector3& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

void ContactProbeSolver::attach(btSoftBody* soft, const std::array<const btCollisionObject*, kMaxToolParts>& tool_parts) {
  soft_ = soft;
  parts_ = tool_parts;
  const auto n = static_cast<std::size_t>(soft->m_nodes.size());
  node_mass_displacement_.assign(n, Eigen::Vector3d::Zero());
  before_.assign(n, Eigen::Vector3d::Zero());
  node_part_.assign(n, -1);
  touched_.reserve(n);
  sequence_.reserve(8);
}

void ContactProbeSolver::clear() noexcept {
  for (auto& m : mass_displacement_) m.setZero();
  for (int i : touched_) {
    node_mass_displacement_[static_cast<std::size_t>(i)].setZero();
    node_part_[static_cast<std::size_t>(i)] = -1;
  }
  touched_.clear();
  seconds_detection_ = 0.0;
  seconds_response_ = 0.0;
}

int ContactProbeSolver::part_of(const btCollisionObject* object) const noexcept {
  for (int p = 0; p < kMaxToolParts; ++p) {
    if (parts_[static_cast<std::size_t>(p)] != nullptr && parts_[static_cast<std::size_t>(p)] == object) return p;
  }
  return -1;
}

void ContactProbeSolver::processCollision(btSoftBody* soft, const btCollisionObjectWrapper* other) {
  const bool is_tool = soft == soft_ && part_of(other->getCollisionObject()) >= 0;
  const Clock::time_point start = Clock::now();
  btDefaultSoftBodySolver::processCollision(soft, other);
  if (is_tool) seconds_detection_ += seconds_since(start);
}

void ContactProbeSolver::solveConstraints(btScalar solver_dt) {
  if (soft_ == nullptr || !soft_->isActive()) {
    btDefaultSoftBodySolver::solveConstraints(solver_dt);
    return;
  }
  btSoftBody& sb = *soft_;
  btSoftBody::Node* const first = sb.m_nodes.size() > 0 ? &sb.m_nodes[0] : nullptr;
  // Which nodes touch which tool part (contacts were found by processCollision).
  for (int c = 0; c < sb.m_rcontacts.size(); ++c) {
    const int part = part_of(sb.m_rcontacts[c].m_cti.m_colObj);
    if (part < 0) continue;
    const auto i = static_cast<std::size_t>(sb.m_rcontacts[c].m_node - first);
    if (node_part_[i] < 0) touched_.push_back(static_cast<int>(i));
    node_part_[i] = part;
  }
  last_step_s_ = static_cast<double>(sb.m_sst.sdt);
  if (touched_.empty()) {
    btDefaultSoftBodySolver::solveConstraints(solver_dt);  // stock path, nothing to measure
    return;
  }
  // Bullet's solveConstraints runs, per position iteration, the solvers of m_psequence in
  // order; everything else in it (link preparation from m_q, the final velocity update) is
  // idempotent. So one call per (iteration, solver) with piterations = 1 reproduces it, and
  // lets us observe the rigid-contact pass alone.
  const int iterations = sb.m_cfg.piterations;
  sequence_.clear();
  for (int s = 0; s < sb.m_cfg.m_psequence.size(); ++s) sequence_.push_back(sb.m_cfg.m_psequence[s]);
  sb.m_cfg.piterations = 1;
  sb.m_cfg.m_psequence.resize(1);
  for (int it = 0; it < iterations; ++it) {
    for (int solver : sequence_) {
      sb.m_cfg.m_psequence[0] = static_cast<btSoftBody::ePSolver::_>(solver);
      const bool contacts = solver == btSoftBody::ePSolver::RContacts;
      Clock::time_point start{};
      if (contacts) {
        for (int i : touched_) before_[static_cast<std::size_t>(i)] = e3(sb.m_nodes[i].m_x);
        start = Clock::now();
      }
      sb.solveConstraints();
      if (contacts) {
        seconds_response_ += seconds_since(start);
        for (int i : touched_) {
          const auto k = static_cast<std::size_t>(i);
          const btScalar inverse_mass = sb.m_nodes[i].m_im;
          if (inverse_mass <= 0) continue;
          const Eigen::Vector3d m_dx = (e3(sb.m_nodes[i].m_x) - before_[k]) / static_cast<double>(inverse_mass);
          node_mass_displacement_[k] += m_dx;
          mass_displacement_[static_cast<std::size_t>(node_part_[k])] += m_dx;
        }
      }
    }
  }
  sb.m_cfg.piterations = iterations;
  sb.m_cfg.m_psequence.resize(0);
  for (int solver : sequence_) sb.m_cfg.m_psequence.push_back(static_cast<btSoftBody::ePSolver::_>(solver));
}

BulletCollision::BulletCollision(const ContactProbeSolver& probe, const btCollisionObject& part_object, int part)
    : probe_(probe), part_object_(part_object), part_(part) {}

void BulletCollision::step(const ToolPose& /*previous*/, const ToolPose& /*current*/, double /*dt_s*/, btSoftBody& soft,
                           CollisionStepResult& out) {
  out.contacts.clear();
  out.colliding_tool_nodes = 0;
  out.excluded_pairs = 0;
  out.both_face_contacts = 0;
  out.guard_corrections = 0;
  out.seconds_broad = 0.0;
  out.seconds_force = 0.0;
  out.seconds_narrow = probe_.seconds_detection();
  out.seconds_response = probe_.seconds_response();
  const double h = probe_.last_step_s();
  out.force_on_tool_world_n = h > 0.0 ? Eigen::Vector3d(-probe_.momentum_displacement(part_) / (h * h)) : Eigen::Vector3d::Zero();
  // The contact set: one record per soft node touching this part (Bullet tests nodes only).
  const btSoftBody::Node* const first = soft.m_nodes.size() > 0 ? &soft.m_nodes[0] : nullptr;
  int displaced = 0;
  for (int c = 0; c < soft.m_rcontacts.size(); ++c) {
    const btSoftBody::RContact& rc = soft.m_rcontacts[c];
    if (rc.m_cti.m_colObj != &part_object_) continue;
    const auto i = static_cast<std::size_t>(rc.m_node - first);
    ContactRecord record;
    record.soft_face = -1;
    record.tool_node = -1;
    record.tool_plane = -1;
    record.jaw = part_;
    record.point_world_m = e3(rc.m_node->m_x);
    record.normal_world = e3(rc.m_cti.m_normal);  // SDF gradient: out of the tool, towards the node
    record.penetration_m = std::max(0.0, -static_cast<double>(btDot(rc.m_node->m_x, rc.m_cti.m_normal) + rc.m_cti.m_offset));
    record.weight = 1.0;
    record.force_n = h > 0.0 ? probe_.node_mass_displacement()[i].norm() / (h * h) : 0.0;
    if (out.contacts.size() < out.contacts.capacity()) out.contacts.push_back(record);
    ++displaced;
  }
  out.contacted_triangles = 0;
  out.displaced_soft_nodes = displaced;
  out.broad_phase_hit = displaced > 0;
}

void BulletCollision::reset_rest_state(const btSoftBody& /*soft*/) {}  // Bullet's contacts keep no rest state

}  // namespace fissure::host
