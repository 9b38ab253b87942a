// Corotated linear elasticity with face-smoothed deviatoric and node-smoothed volumetric strain
// (fem_smoothed_strain_force.hpp).
#include "fem_smoothed_strain_force.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <utility>

namespace fissure::host {
namespace {

// Bullet's scatter of a tetrahedron's stress onto its nodes: node 0 takes minus the sum of the
// other three columns (the gradient of the first shape function is (−1, −1, −1)).
const btVector3 kFirstShapeGradient(-1, -1, -1);

double trace(const btMatrix3x3& m) { return m[0][0] + m[1][1] + m[2][2]; }

btMatrix3x3 symmetric_part(const btMatrix3x3& m) { return (m + m.transpose()) * btScalar(0.5); }

btMatrix3x3 deviatoric_part(const btMatrix3x3& m) { return m - btMatrix3x3::getIdentity() * btScalar(trace(m) / 3.0); }

double squared_norm(const btMatrix3x3& m) { return m[0].length2() + m[1].length2() + m[2].length2(); }

std::size_t local_index(const btSoftBody& body, const btSoftBody::Node* node) { return static_cast<std::size_t>(node - &body.m_nodes[0]); }

void scatter(const std::array<int, 4>& stack_index, const btMatrix3x3& force_on_node123, btScalar weight, btDeformableLagrangianForce::TVStack& out) {
  out[stack_index[0]] -= weight * (force_on_node123 * kFirstShapeGradient);
  out[stack_index[1]] -= weight * force_on_node123.getColumn(0);
  out[stack_index[2]] -= weight * force_on_node123.getColumn(1);
  out[stack_index[3]] -= weight * force_on_node123.getColumn(2);
}

// A face as its three sorted node indices packed in 21 bits each (bodies under 2M nodes).
std::uint64_t face_key(std::size_t a, std::size_t b, std::size_t c) {
  if (a > b) std::swap(a, b);
  if (b > c) std::swap(b, c);
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(a) << 42) | (static_cast<std::uint64_t>(b) << 21) | static_cast<std::uint64_t>(c);
}

// Face k of a tetrahedron is the one opposite its node k.
constexpr std::array<std::array<int, 3>, 4> kFaceNodes{{{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}}};

// The corotated small strain sym(Rᵀ F) − I of tetrahedron j at the current positions.
btMatrix3x3 corotated_strain(const btSoftBody& body, int j) {
  const btSoftBody::TetraScratch& t = body.m_tetraScratches[j];
  return symmetric_part(t.m_corotation.transpose() * t.m_F) - btMatrix3x3::getIdentity();
}

}  // namespace

SmoothedStrainElasticityForce::SmoothedStrainElasticityForce(btScalar mu, btScalar lambda, btScalar damping_alpha, btScalar damping_beta)
    : btDeformableLinearElasticityForce(mu, lambda, damping_alpha, damping_beta) {}

SmoothedStrainElasticityForce::BodyScratch& SmoothedStrainElasticityForce::scratch_for(const btSoftBody& body) {
  for (BodyScratch& s : scratch_) {
    if (s.body == &body && s.node_volume_m3.size() == static_cast<std::size_t>(body.m_nodes.size()) &&
        s.face_neighbours.size() == static_cast<std::size_t>(body.m_tetras.size()))
      return s;
  }
  BodyScratch fresh;
  fresh.body = &body;
  const auto nodes = static_cast<std::size_t>(body.m_nodes.size()), tetras = static_cast<std::size_t>(body.m_tetras.size());
  fresh.node_volume_m3.assign(nodes, 0.0);
  fresh.node_volumetric_strain.assign(nodes, 0.0);
  fresh.element_strain.assign(tetras, btMatrix3x3::getIdentity());
  fresh.face_neighbours.assign(tetras, {-1, -1, -1, -1});
  std::unordered_map<std::uint64_t, int> open_faces;
  open_faces.reserve(2 * tetras);
  for (std::size_t j = 0; j < tetras; ++j) {
    const btSoftBody::Tetra& tetra = body.m_tetras[static_cast<int>(j)];
    for (const btSoftBody::Node* node : tetra.m_n) fresh.node_volume_m3[local_index(body, node)] += 0.25 * tetra.m_element_measure;
    for (std::size_t k = 0; k < 4; ++k) {
      const std::array<int, 3>& f = kFaceNodes[k];
      const std::uint64_t key = face_key(local_index(body, tetra.m_n[f[0]]), local_index(body, tetra.m_n[f[1]]), local_index(body, tetra.m_n[f[2]]));
      const auto [it, inserted] = open_faces.try_emplace(key, static_cast<int>(4 * j + k));
      if (inserted) continue;
      // The face's other tetrahedron: link both ways. A third tetrahedron on one face (a
      // non-manifold mesh, refused by the mesh checks) would only be linked to the first.
      const auto other = static_cast<std::size_t>(it->second);
      fresh.face_neighbours[j][k] = static_cast<int>(other / 4);
      fresh.face_neighbours[other / 4][other % 4] = static_cast<int>(j);
      open_faces.erase(it);
    }
  }
  fresh.stack_index.assign(nodes, 0);
  fresh.tetra_nodes.resize(tetras);
  for (std::size_t j = 0; j < tetras; ++j) {
    for (std::size_t k = 0; k < 4; ++k) fresh.tetra_nodes[j][k] = static_cast<int>(local_index(body, body.m_tetras[static_cast<int>(j)].m_n[k]));
  }
  fresh.own_weight.assign(tetras, 0.0);
  fresh.neighbour_weight.assign(tetras, {0.0F, 0.0F, 0.0F, 0.0F});
  for (std::size_t j = 0; j < tetras; ++j) {
    const double own_volume = body.m_tetras[static_cast<int>(j)].m_element_measure;
    for (std::size_t k = 0; k < 4; ++k) {
      const int n = fresh.face_neighbours[j][k];
      if (n < 0) {
        fresh.own_weight[j] += 1.0;
        continue;
      }
      const double other_volume = body.m_tetras[n].m_element_measure;
      fresh.own_weight[j] += own_volume / (own_volume + other_volume);
      fresh.neighbour_weight[j][k] = static_cast<float>(other_volume / (own_volume + other_volume));
    }
  }
  for (BodyScratch& s : scratch_) {
    if (s.body == &body) {
      s = std::move(fresh);
      return s;
    }
  }
  scratch_.push_back(std::move(fresh));
  return scratch_.back();
}

template <class Strain>
void SmoothedStrainElasticityForce::store_strains(const btSoftBody& body, BodyScratch& s, Strain strain) {
  for (int a = 0; a < body.m_nodes.size(); ++a) s.stack_index[static_cast<std::size_t>(a)] = body.m_nodes[a].index;
  std::fill(s.node_volumetric_strain.begin(), s.node_volumetric_strain.end(), 0.0);
  for (int j = 0; j < body.m_tetras.size(); ++j) {
    const auto t = static_cast<std::size_t>(j);
    const btMatrix3x3 e = strain(j);
    s.element_strain[t] = e;
    const double quarter_volume_trace = 0.25 * body.m_tetras[j].m_element_measure * trace(e);
    for (const int a : s.tetra_nodes[t]) s.node_volumetric_strain[static_cast<std::size_t>(a)] += quarter_volume_trace;
  }
  for (std::size_t a = 0; a < s.node_volumetric_strain.size(); ++a) {
    if (s.node_volume_m3[a] > 0.0) s.node_volumetric_strain[a] /= s.node_volume_m3[a];
  }
}

template <class Strain, class Rotation>
void SmoothedStrainElasticityForce::add_smoothed_stress_forces(btScalar scale, double mu, double lambda, Strain strain, Rotation rotation, TVStack& out) {
  const double bulk = lambda + 2.0 * mu / 3.0;
  for (int i = 0; i < m_softBodies.size(); ++i) {
    btSoftBody* body = m_softBodies[i];
    if (!body->isActive()) continue;
    BodyScratch& s = scratch_for(*body);
    const auto stack_indices = [&s](std::size_t t) {
      const std::array<int, 4>& local = s.tetra_nodes[t];
      return std::array<int, 4>{s.stack_index[static_cast<std::size_t>(local[0])], s.stack_index[static_cast<std::size_t>(local[1])],
                                s.stack_index[static_cast<std::size_t>(local[2])], s.stack_index[static_cast<std::size_t>(local[3])]};
    };
    store_strains(*body, s, [&](int j) { return strain(*body, j, stack_indices(static_cast<std::size_t>(j))); });
    for (int j = 0; j < body->m_tetras.size(); ++j) {
      const btSoftBody::Tetra& tetra = body->m_tetras[j];
      const auto t = static_cast<std::size_t>(j);
      btMatrix3x3 face_mean = s.element_strain[t] * btScalar(s.own_weight[t]);
      for (std::size_t k = 0; k < 4; ++k) {
        const int n = s.face_neighbours[t][k];
        if (n >= 0) face_mean += s.element_strain[static_cast<std::size_t>(n)] * s.neighbour_weight[t][k];
      }
      double node_mean = 0.0;
      for (const int a : s.tetra_nodes[t]) node_mean += 0.25 * s.node_volumetric_strain[static_cast<std::size_t>(a)];
      const btMatrix3x3 stress = deviatoric_part(face_mean * btScalar(0.25)) * btScalar(2.0 * mu) + btMatrix3x3::getIdentity() * btScalar(bulk * node_mean);
      scatter(stack_indices(t), rotation(*body, j) * stress * tetra.m_Dm_inverse.transpose(), scale * tetra.m_element_measure, out);
    }
  }
}

namespace {

const btMatrix3x3& element_rotation(const btSoftBody& body, int j) { return body.m_tetraScratches[j].m_corotation; }

// Bullet's damping leaves a nearly flat tetrahedron unrotated (its polar rotation is unreliable
// there); its elastic force and differential always rotate. Both are kept as Bullet has them.
btMatrix3x3 damping_rotation(const btSoftBody& body, int j) {
  const btSoftBody::TetraScratch& t = body.m_tetraScratches[j];
  return t.m_J < TETRA_FLAT_THRESHOLD ? btMatrix3x3::getIdentity() : t.m_corotation;
}

// Bullet's mass-proportional damping, −α·m·v per node (or its differential, with dv for v).
template <class Velocity>
void add_mass_damping(const btAlignedObjectArray<btSoftBody*>& bodies, btScalar scaled_alpha, Velocity velocity, btDeformableLagrangianForce::TVStack& out) {
  if (scaled_alpha == 0) return;
  for (int i = 0; i < bodies.size(); ++i) {
    const btSoftBody* body = bodies[i];
    if (!body->isActive()) continue;
    for (int j = 0; j < body->m_nodes.size(); ++j) {
      const btSoftBody::Node& node = body->m_nodes[j];
      if (node.m_im > 0) out[node.index] -= scaled_alpha * velocity(node) / node.m_im;
    }
  }
}

}  // namespace

void SmoothedStrainElasticityForce::addScaledElasticForce(btScalar scale, TVStack& force) {
  add_smoothed_stress_forces(
      scale, m_mu, m_lambda,
      [](const btSoftBody& body, int j, const std::array<int, 4>&) { return corotated_strain(body, j); },
      element_rotation, force);
}

void SmoothedStrainElasticityForce::addScaledElasticForceDifferential(btScalar scale, const TVStack& dx, TVStack& df) {
  add_smoothed_stress_forces(
      scale, m_mu, m_lambda,
      [&](const btSoftBody& body, int j, const std::array<int, 4>& node) {
        const btMatrix3x3 gradient = Ds(node[0], node[1], node[2], node[3], dx) * body.m_tetras[j].m_Dm_inverse;
        return symmetric_part(body.m_tetraScratches[j].m_corotation.transpose() * gradient);
      },
      element_rotation, df);
}

void SmoothedStrainElasticityForce::addScaledDampingForce(btScalar scale, TVStack& force) {
  if (m_damping_beta != 0) {
    add_smoothed_stress_forces(
        scale, m_damping_beta * m_mu, m_damping_beta * m_lambda,
        [&](const btSoftBody& body, int j, const std::array<int, 4>&) {
          const btSoftBody::Tetra& tetra = body.m_tetras[j];
          const btMatrix3x3 gradient = DsFromVelocity(tetra.m_n[0], tetra.m_n[1], tetra.m_n[2], tetra.m_n[3]) * tetra.m_Dm_inverse;
          return symmetric_part(damping_rotation(body, j).transpose() * gradient);
        },
        damping_rotation, force);
  }
  add_mass_damping(m_softBodies, scale * m_damping_alpha, [](const btSoftBody::Node& node) { return node.m_v; }, force);
}

void SmoothedStrainElasticityForce::addScaledDampingForceDifferential(btScalar scale, const TVStack& dv, TVStack& df) {
  if (m_damping_beta != 0) {
    add_smoothed_stress_forces(
        scale, m_damping_beta * m_mu, m_damping_beta * m_lambda,
        [&](const btSoftBody& body, int j, const std::array<int, 4>& node) {
          const btMatrix3x3 gradient = Ds(node[0], node[1], node[2], node[3], dv) * body.m_tetras[j].m_Dm_inverse;
          return symmetric_part(damping_rotation(body, j).transpose() * gradient);
        },
        damping_rotation, df);
  }
  add_mass_damping(m_softBodies, scale * m_damping_alpha, [&dv](const btSoftBody::Node& node) { return dv[node.index]; }, df);
}

double SmoothedStrainElasticityForce::totalElasticEnergy(btScalar) {
  const double bulk = m_lambda + 2.0 * m_mu / 3.0;
  double energy = 0.0;
  for (int i = 0; i < m_softBodies.size(); ++i) {
    btSoftBody* body = m_softBodies[i];
    if (!body->isActive()) continue;
    BodyScratch& s = scratch_for(*body);
    store_strains(*body, s, [body](int j) { return corotated_strain(*body, j); });
    for (int j = 0; j < body->m_tetras.size(); ++j) {
      const auto t = static_cast<std::size_t>(j);
      const double own_volume = body->m_tetras[j].m_element_measure;
      for (const int n : s.face_neighbours[t]) {
        if (n < 0) {
          energy += 0.25 * own_volume * m_mu * squared_norm(deviatoric_part(s.element_strain[t]));
        } else if (static_cast<std::size_t>(n) > t) {  // each shared face once
          const double other_volume = body->m_tetras[n].m_element_measure;
          const btMatrix3x3 mean = (s.element_strain[t] * btScalar(own_volume) + s.element_strain[static_cast<std::size_t>(n)] * btScalar(other_volume)) *
                                   btScalar(1.0 / (own_volume + other_volume));
          energy += 0.25 * (own_volume + other_volume) * m_mu * squared_norm(deviatoric_part(mean));
        }
      }
    }
    for (std::size_t a = 0; a < s.node_volumetric_strain.size(); ++a) {
      const double theta = s.node_volumetric_strain[a];
      energy += s.node_volume_m3[a] * 0.5 * bulk * theta * theta;
    }
  }
  return energy;
}

}  // namespace fissure::host
