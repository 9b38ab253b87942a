// host_sim/src/fem_smoothed_strain_force.cpp: the smoothed-strain corotated force — no force
// under a rigid motion beyond Bullet's corotation residual; Bullet's force and damping under a
// homogeneous strain and strain rate; the force the gradient of its energy and the differential
// the derivative of the force (finite differences); a body that bends where Bullet's
// per-element force locks.
#include "fem_smoothed_strain_force.hpp"

#include <cmath>
#include <memory>
#include <random>

#include <BulletSoftBody/btDeformableLinearElasticityForce.h>
#include <BulletSoftBody/btSoftBody.h>
#include <gtest/gtest.h>

#include "fissure/host_sim/fem_body.hpp"
#include "fissure/host_sim/fem_material.hpp"
#include "fissure/host_sim/tet_box.hpp"

namespace fissure::host {
namespace {

using TVStack = btDeformableLagrangianForce::TVStack;

// Tissue-like Lamé parameters (E = 5 kPa, ν = 0.45).
constexpr double kYoungsPa = 5000.0;
constexpr double kPoisson = 0.45;

struct Body {
  btSoftBodyWorldInfo info;
  std::unique_ptr<btSoftBody> soft;
  std::vector<btVector3> rest;
};

// A 20 mm block of 2 × 2 × 2 Kuhn-split cubes (48 tetrahedra, 27 nodes: one interior node).
std::unique_ptr<Body> make_block() {
  auto b = std::make_unique<Body>();
  const VolumeMesh mesh = make_tet_box(even_coordinates(0.0, 0.02, 2), even_coordinates(0.0, 0.02, 2), even_coordinates(0.0, 0.02, 2));
  b->soft.reset(create_fem_body(b->info, mesh, FemMaterial{}, FemContact{}));
  for (int i = 0; i < b->soft->m_nodes.size(); ++i) {
    b->soft->m_nodes[i].index = i;
    b->rest.push_back(b->soft->m_nodes[i].m_x);
  }
  return b;
}

// Places the nodes (Bullet's deformation reads m_q) and updates F and the corotation.
void place(btSoftBody& soft, const std::vector<btVector3>& positions) {
  for (int i = 0; i < soft.m_nodes.size(); ++i) soft.m_nodes[i].m_x = soft.m_nodes[i].m_q = positions[static_cast<std::size_t>(i)];
  soft.updateDeformation();
}

TVStack zero_stack(int n) {
  TVStack s;
  s.resize(n);
  for (int i = 0; i < n; ++i) s[i].setZero();
  return s;
}

TVStack elastic_force(btDeformableLinearElasticityForce& force, int n) {
  TVStack f = zero_stack(n);
  force.addScaledElasticForce(1, f);
  return f;
}

double largest(const TVStack& s) {
  double m = 0.0;
  for (int i = 0; i < s.size(); ++i) m = std::max(m, static_cast<double>(s[i].length()));
  return m;
}

btMatrix3x3 rotation_about(const btVector3& axis, double angle_rad) {
  btMatrix3x3 r;
  r.setRotation(btQuaternion(axis.normalized(), static_cast<btScalar>(angle_rad)));
  return r;
}

std::vector<btVector3> transformed(const std::vector<btVector3>& rest, const btMatrix3x3& linear, const btVector3& shift) {
  std::vector<btVector3> out;
  for (const btVector3& p : rest) out.push_back(linear * p + shift);
  return out;
}

class SmoothedStrainForceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    block_ = make_block();
    FemMaterial material;
    material.youngs_modulus_pa = kYoungsPa;
    material.poisson_ratio = kPoisson;
    const LameParameters lame = lame_parameters(material);
    smoothed_ = std::make_unique<SmoothedStrainElasticityForce>(static_cast<btScalar>(lame.mu_pa), static_cast<btScalar>(lame.lambda_pa), 0, 0);
    bullet_ = std::make_unique<btDeformableLinearElasticityForce>(static_cast<btScalar>(lame.mu_pa), static_cast<btScalar>(lame.lambda_pa), 0, 0);
    smoothed_->addSoftBody(block_->soft.get());
    bullet_->addSoftBody(block_->soft.get());
  }
  int nodes() const { return block_->soft->m_nodes.size(); }

  std::unique_ptr<Body> block_;
  std::unique_ptr<SmoothedStrainElasticityForce> smoothed_;
  std::unique_ptr<btDeformableLinearElasticityForce> bullet_;
};

// A rigid motion strains no element beyond what Bullet's own corotation leaves: its polar
// rotation (btSoftBody::updateDeformation) stops iterating at 0.01 rad, a residual strain of at
// most δ²/2 = 5e-5 in both forces. So the bounds are relative to a strain of 1e-3: force ≤ 5 %,
// energy ≤ 0.25 %, and the smoothing adds nothing to Bullet's residual. (Bullet's btScalar is
// float here: positions of 20 mm carry ~1e-9 m of rounding, a strain of ~1e-7.)
TEST_F(SmoothedStrainForceTest, ARigidMotionHasNoForceBeyondBulletsCorotationResidual) {
  btMatrix3x3 strained(1.001, 0, 0, 0, 1, 0, 0, 0, 1);
  place(*block_->soft, transformed(block_->rest, strained, btVector3(0, 0, 0)));
  const double reference_force = largest(elastic_force(*smoothed_, nodes())), reference_energy = smoothed_->totalElasticEnergy(0);
  ASSERT_GT(reference_force, 0.0);
  place(*block_->soft, transformed(block_->rest, rotation_about(btVector3(1, 2, 3), 0.7), btVector3(0.01, -0.02, 0.005)));
  const double ours = largest(elastic_force(*smoothed_, nodes())), bullets = largest(elastic_force(*bullet_, nodes()));
  EXPECT_LT(ours, 0.05 * reference_force);
  EXPECT_LT(smoothed_->totalElasticEnergy(0), 2.5e-3 * reference_energy);
  EXPECT_NEAR(ours, bullets, 0.02 * bullets);
  // Without a rotation the rest state is exact to rounding.
  place(*block_->soft, transformed(block_->rest, btMatrix3x3::getIdentity(), btVector3(0.01, -0.02, 0.005)));
  EXPECT_LT(largest(elastic_force(*smoothed_, nodes())), 1e-3 * reference_force);
}

TEST_F(SmoothedStrainForceTest, AHomogeneousStrainGivesBulletsForce) {
  btMatrix3x3 stretch(1.03, 0.01, 0.0, 0.01, 0.98, 0.004, 0.0, 0.004, 1.01);
  place(*block_->soft, transformed(block_->rest, rotation_about(btVector3(0, 1, 1), 0.4) * stretch, btVector3(0, 0, 0)));
  const TVStack ours = elastic_force(*smoothed_, nodes()), bullets = elastic_force(*bullet_, nodes());
  ASSERT_GT(largest(bullets), 1e-3);
  for (int i = 0; i < nodes(); ++i) EXPECT_LT((ours[i] - bullets[i]).length(), 1e-4 * largest(bullets)) << "node " << i;
}

// The damping (Bullet's: stiffness-proportional β on the strain rate, mass-proportional α) goes
// through the same smoothed stress: under a homogeneous velocity gradient it is Bullet's, and so
// is its differential along a homogeneous direction.
TEST_F(SmoothedStrainForceTest, DampingIsBulletsUnderAHomogeneousVelocityGradient) {
  const LameParameters lame = lame_parameters([] {
    FemMaterial m;
    m.youngs_modulus_pa = kYoungsPa;
    m.poisson_ratio = kPoisson;
    return m;
  }());
  const auto mu = static_cast<btScalar>(lame.mu_pa), lambda = static_cast<btScalar>(lame.lambda_pa);
  SmoothedStrainElasticityForce smoothed(mu, lambda, 3.0F, 0.02F);
  btDeformableLinearElasticityForce bullet(mu, lambda, 3.0F, 0.02F);
  smoothed.addSoftBody(block_->soft.get());
  bullet.addSoftBody(block_->soft.get());
  const btMatrix3x3 rotation = rotation_about(btVector3(1, 1, 0), 0.3);
  place(*block_->soft, transformed(block_->rest, rotation, btVector3(0, 0, 0)));
  const btMatrix3x3 velocity_gradient(0.5, 0.1, 0.0, 0.1, -0.2, 0.05, 0.0, 0.05, 0.3);  // [1/s]
  TVStack direction = zero_stack(nodes());
  for (int i = 0; i < nodes(); ++i) {
    block_->soft->m_nodes[i].m_v = velocity_gradient * block_->soft->m_nodes[i].m_x;
    direction[i] = block_->soft->m_nodes[i].m_v;
  }
  TVStack ours = zero_stack(nodes()), bullets = zero_stack(nodes());
  smoothed.addScaledDampingForce(1, ours);
  bullet.addScaledDampingForce(1, bullets);
  ASSERT_GT(largest(bullets), 0.0);
  for (int i = 0; i < nodes(); ++i) EXPECT_LT((ours[i] - bullets[i]).length(), 1e-4 * largest(bullets)) << "node " << i;
  TVStack our_differential = zero_stack(nodes()), bullets_differential = zero_stack(nodes());
  smoothed.addScaledDampingForceDifferential(1, direction, our_differential);
  bullet.addScaledDampingForceDifferential(1, direction, bullets_differential);
  ASSERT_GT(largest(bullets_differential), 0.0);
  for (int i = 0; i < nodes(); ++i)
    EXPECT_LT((our_differential[i] - bullets_differential[i]).length(), 1e-4 * largest(bullets_differential)) << "node " << i;
}

// A general small deformation under a large rotation: the force is minus the gradient of the
// energy (holding each element's rotation, as the force does, is exact to first order in the
// strain: the polar rotation makes the energy stationary in it only for the unsmoothed element),
// and the differential is the force's derivative along a direction.
TEST_F(SmoothedStrainForceTest, ForceIsTheEnergysGradientAndTheDifferentialItsDerivative) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-2e-5, 2e-5);  // ±0.02 mm on 10 mm cells: strain ~2e-3
  std::vector<btVector3> x = transformed(block_->rest, rotation_about(btVector3(1, 0, 1), 0.9), btVector3(0, 0.01, 0));
  for (btVector3& p : x) p += btVector3(jitter(rng), jitter(rng), jitter(rng));
  place(*block_->soft, x);
  const TVStack force = elastic_force(*smoothed_, nodes());
  const double scale = largest(force);
  ASSERT_GT(scale, 1e-4);

  const double h = 4e-6;  // 0.4 µm: a strain step of 4e-4, well above the float rounding
  double worst_gradient = 0.0;
  for (int i = 0; i < nodes(); ++i) {
    for (int axis = 0; axis < 3; ++axis) {
      std::vector<btVector3> plus = x, minus = x;
      plus[static_cast<std::size_t>(i)][axis] += h;
      minus[static_cast<std::size_t>(i)][axis] -= h;
      place(*block_->soft, plus);
      const double e_plus = smoothed_->totalElasticEnergy(0);
      place(*block_->soft, minus);
      const double e_minus = smoothed_->totalElasticEnergy(0);
      worst_gradient = std::max(worst_gradient, std::abs(-(e_plus - e_minus) / (2 * h) - force[i][axis]));
    }
  }
  EXPECT_LT(worst_gradient, 1e-2 * scale);

  TVStack direction = zero_stack(nodes());
  for (int i = 0; i < nodes(); ++i) direction[i] = btVector3(jitter(rng), jitter(rng), jitter(rng)) * 5e4;  // ~1 m scale
  place(*block_->soft, x);
  TVStack differential = zero_stack(nodes());
  smoothed_->addScaledElasticForceDifferential(1, direction, differential);
  const double step = 2e-6;  // displacements of ~2 µm
  std::vector<btVector3> plus = x, minus = x;
  for (int i = 0; i < nodes(); ++i) {
    plus[static_cast<std::size_t>(i)] += direction[i] * step;
    minus[static_cast<std::size_t>(i)] -= direction[i] * step;
  }
  place(*block_->soft, plus);
  const TVStack f_plus = elastic_force(*smoothed_, nodes());
  place(*block_->soft, minus);
  const TVStack f_minus = elastic_force(*smoothed_, nodes());
  double worst_differential = 0.0;
  for (int i = 0; i < nodes(); ++i) worst_differential = std::max(worst_differential, static_cast<double>(((f_plus[i] - f_minus[i]) / (2 * step) - differential[i]).length()));
  EXPECT_LT(worst_differential, 1e-2 * largest(differential));
}

// The bending mode Bullet's element locks: the block bent about z (displacement u_y = κ x²/2,
// with the rotation of the sections u_x = −κ x y) stores less energy with smoothed strains,
// closer to the continuum's, than with one strain per element.
TEST_F(SmoothedStrainForceTest, BendingStoresLessEnergyThanBulletsElement) {
  const double curvature_per_m = 1.0;  // 20 mm block: 0.2 mm tip rise, strain ≤ 1e-2
  std::vector<btVector3> bent;
  for (const btVector3& p : block_->rest) {
    const double x = p.x(), y = p.y() - 0.01;
    bent.push_back(p + btVector3(static_cast<btScalar>(-curvature_per_m * x * y), static_cast<btScalar>(0.5 * curvature_per_m * x * x), 0));
  }
  place(*block_->soft, bent);
  const double ours = smoothed_->totalElasticEnergy(0), bullets = bullet_->totalElasticEnergy(0);
  // Pure bending of the continuum: E I κ² L / 2 with I = h⁴/12 (plane-stress beam, ν ignored):
  // 5000 · (0.02⁴ / 12) · 1 · 0.02 / 2 = 6.7e-9 J. The Kuhn block with one strain per element
  // adds the locked shear on top.
  EXPECT_GT(ours, 0.0);
  EXPECT_LT(ours, 0.8 * bullets);
}

}  // namespace
}  // namespace fissure::host
