// Bullet's soft-body solve with the per-block node bounds fused into its last node loop
// (node_bounds_solver.hpp says why).
#include "fissure/host_sim/node_bounds_solver.hpp"

#include <algorithm>

#if defined(__SSE__)
#include <xmmintrin.h>
#endif

#include <BulletSoftBody/btSoftBody.h>

namespace fissure::host {

NodeBoundsSolver::~NodeBoundsSolver() = default;

int NodeBoundsSolver::attach(btSoftBody* soft) {
  auto body = std::make_unique<AttachedBody>();
  body->soft = soft;
  SoftNodeBounds& bounds = body->bounds;
  bounds.node_count = soft->m_nodes.size();
  const int blocks = (bounds.node_count + SoftNodeBounds::kNodesPerBlock - 1) / SoftNodeBounds::kNodesPerBlock;
  bounds.block_lo.assign(static_cast<std::size_t>(blocks), btVector3(0, 0, 0));
  bounds.block_hi.assign(static_cast<std::size_t>(blocks), btVector3(0, 0, 0));
  bounds.valid = false;
  bodies_.push_back(std::move(body));
  return static_cast<int>(bodies_.size()) - 1;
}

void NodeBoundsSolver::clear_contacts() noexcept {
  for (auto& body : bodies_) body->contacts.clear();
}

void NodeBoundsSolver::solveConstraints(btScalar /*solver_dt*/) {
  for (auto& attached : bodies_) attached->bounds.valid = false;
  // btDefaultSoftBodySolver::solveConstraints: every active body, in the world's order.
  for (int i = 0; i < m_softBodySet.size(); ++i) {
    btSoftBody* body = m_softBodySet[i];
    if (!body->isActive()) continue;
    // A scene has at most kMaxSoftBodies bodies: a linear search is the cheap lookup.
    AttachedBody* attached = nullptr;
    for (auto& a : bodies_) {
      if (a->soft == body) attached = a.get();
    }
    // The fused path reproduces btSoftBody::solveConstraints only where its cluster passes do
    // nothing and no drift pass follows the velocity update (drift rewrites m_q and m_v after it).
    const bool reproducible = attached != nullptr && body->m_clusters.size() == 0 && body->m_cfg.diterations == 0 &&
                              body->m_cfg.piterations > 0 && body->m_nodes.size() == attached->bounds.node_count;
    if (reproducible) {
      solve_with_bounds(*attached);
    } else {
      body->solveConstraints();
    }
  }
}

void NodeBoundsSolver::solve_with_bounds(AttachedBody& body) {
  btSoftBody& sb = *body.soft;
  // 1. Bullet's own solveConstraints with its position block switched off: cluster passes (no-ops
  //    without clusters), link and anchor preparation, the velocity iterations.
  const int position_iterations = sb.m_cfg.piterations;
  sb.m_cfg.piterations = 0;
  sb.solveConstraints();
  sb.m_cfg.piterations = position_iterations;
  // 2. The contacts decide this step's contact set on the predicted positions; their broad phase
  //    reads the bounds of m_q and the predicted m_x.
  if (!body.contacts.empty()) {
    take_bounds(sb, body.bounds, false);
    for (SoftContactConstraint* contact : body.contacts) contact->begin_solve(sb);
  }
  // 3. Its position block, verbatim: the same solvers in the same order with the same ti, each
  //    iteration followed by the contacts' projection.
  for (int isolve = 0; isolve < position_iterations; ++isolve) {
    const btScalar ti = isolve / static_cast<btScalar>(position_iterations);
    for (int iseq = 0; iseq < sb.m_cfg.m_psequence.size(); ++iseq) btSoftBody::getSolver(sb.m_cfg.m_psequence[iseq])(&sb, 1, ti);
    for (SoftContactConstraint* contact : body.contacts) contact->project(sb);
  }
  // 4. Its velocity update with the bounds taken in the same pass; what follows it in Bullet
  //    (drift: excluded above; dampClusters / applyClusters(true): no-ops without clusters, and
  //    already run in step 1).
  take_bounds(sb, body.bounds, true);
  for (SoftContactConstraint* contact : body.contacts) contact->end_solve(sb);
}

void NodeBoundsSolver::take_bounds(btSoftBody& sb, SoftNodeBounds& bounds, bool velocity_update) {
  // Bullet's velocity update (the same float operations per component, so the same results), with
  // the bounds of m_q and m_x taken in the same pass, one block of nodes at a time. Bullet's
  // btVector3 arithmetic is scalar here (Linux builds leave BT_USE_SSE_IN_API off): written with
  // btVector3::setMin/setMax the bounds cost ~50 instructions a node (callgrind); on SSE four
  // lanes at a time they cost 4.
  const btScalar vc = sb.m_sst.isdt * (1 - sb.m_cfg.kDP);
  const int count = sb.m_nodes.size();
  btVector3 all_lo(BT_LARGE_FLOAT, BT_LARGE_FLOAT, BT_LARGE_FLOAT), all_hi(-BT_LARGE_FLOAT, -BT_LARGE_FLOAT, -BT_LARGE_FLOAT);
  for (int b = 0, first = 0; first < count; ++b, first += SoftNodeBounds::kNodesPerBlock) {
    const int last = std::min(count, first + SoftNodeBounds::kNodesPerBlock);
    btVector3 lo, hi;
#if defined(__SSE__)
    const __m128 vc4 = _mm_set1_ps(vc);
    __m128 lo4 = _mm_load_ps(sb.m_nodes[first].m_x.m_floats), hi4 = lo4;
    for (int i = first; i < last; ++i) {
      btSoftBody::Node& n = sb.m_nodes[i];
      const __m128 x = _mm_load_ps(n.m_x.m_floats), q = _mm_load_ps(n.m_q.m_floats);
      if (velocity_update) {
        _mm_store_ps(n.m_v.m_floats, _mm_mul_ps(_mm_sub_ps(x, q), vc4));
        _mm_store_ps(n.m_f.m_floats, _mm_setzero_ps());
      }
      lo4 = _mm_min_ps(lo4, _mm_min_ps(x, q));
      hi4 = _mm_max_ps(hi4, _mm_max_ps(x, q));
    }
    _mm_store_ps(lo.m_floats, lo4);
    _mm_store_ps(hi.m_floats, hi4);
#else
    lo = sb.m_nodes[first].m_x;
    hi = lo;
    for (int i = first; i < last; ++i) {
      btSoftBody::Node& n = sb.m_nodes[i];
      if (velocity_update) {
        n.m_v = (n.m_x - n.m_q) * vc;
        n.m_f = btVector3(0, 0, 0);
      }
      lo.setMin(n.m_x);
      lo.setMin(n.m_q);
      hi.setMax(n.m_x);
      hi.setMax(n.m_q);
    }
#endif
    bounds.block_lo[static_cast<std::size_t>(b)] = lo;
    bounds.block_hi[static_cast<std::size_t>(b)] = hi;
    all_lo.setMin(lo);
    all_hi.setMax(hi);
  }
  bounds.all_lo = all_lo;
  bounds.all_hi = all_hi;
  bounds.valid = count > 0;
}

}  // namespace fissure::host
