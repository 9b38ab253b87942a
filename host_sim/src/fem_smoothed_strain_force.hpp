#pragma once
// Corotated linear elasticity on linear tetrahedra with smoothed strains — the selective
// face-/node-based smoothed FEM (FS/NS-FEM) of Jiang, Liu et al. (2014, Comput. Methods Appl.
// Mech. Eng. 280:289; the node-averaged volumetric part is the average-nodal-pressure
// tetrahedron of Bonet & Burton 1998, Commun. Numer. Meth. Eng. 14:437), in the corotated
// small-strain setting of Bullet's btDeformableLinearElasticityForce.
//
// Why: a linear tetrahedron has one constant strain. With ν near ½ each element must keep its own
// volume, and a constant shear cannot follow a bending curvature: a Kuhn-split grid hardly bends.
// `fissure bench tissue`'s cantilever sags 40 % short of Euler–Bernoulli at 4 cells across its
// section with Bullet's force at ν = 0.45, and the vessel's wall flattens 66 % short of Roark's
// ring (docs/decisions.md, "Tissue (issue 24)"). Averaging the volumetric strain over the
// tetrahedra around each node leaves one volume constraint per node instead of ~5; averaging
// the deviatoric strain over the two tetrahedra of each face lets the strain vary across an
// element's neighbourhood. Both keep the element's own rotation, so the body is still
// corotated: a rigid motion strains no element beyond what Bullet's polar rotation leaves (it
// stops at 0.01 rad: a residual strain ≤ 5e-5, the same in Bullet's own force).
//
// Energy, with ε_t = sym(R_tᵀ F_t) − I the corotated strain of tetrahedron t (rest volume V_t),
// K = λ + 2μ/3 the bulk modulus, V_a = Σ_{t∋a} V_t/4 the rest volume of node a, and for each face
// f the volume-weighted strain ε̄_f of its one or two tetrahedra, V_f = Σ_{t∋f} V_t/4:
//   E = Σ_f V_f μ ‖dev ε̄_f‖²  +  Σ_a V_a (K/2) θ_a²,     θ_a = Σ_{t∋a} (V_t/4) tr ε_t / V_a.
// Holding each R_t fixed (as Bullet's force does), ∂E/∂ε_t = V_t P_t with
//   P_t = 2μ dev(¼ Σ_{f of t} ε̄_f) + K · (mean of θ_a over t's four nodes) · I,
// so each tetrahedron scatters P_t exactly as Bullet's force scatters its own stress: the force,
// its differential (the implicit step's matrix-free Hessian product) and the stiffness-
// proportional damping are Bullet's with that one stress swapped. A homogeneous strain is
// unchanged by either average, so a uniform compression gives Bullet's force to rounding.
#include <BulletSoftBody/btDeformableLinearElasticityForce.h>

#include <array>
#include <vector>

namespace fissure::host {

class SmoothedStrainElasticityForce final : public btDeformableLinearElasticityForce {
 public:
  SmoothedStrainElasticityForce(btScalar mu, btScalar lambda, btScalar damping_alpha, btScalar damping_beta);

  void addScaledElasticForce(btScalar scale, TVStack& force) override;
  void addScaledElasticForceDifferential(btScalar scale, const TVStack& dx, TVStack& df) override;
  void addScaledDampingForce(btScalar scale, TVStack& force) override;
  void addScaledDampingForceDifferential(btScalar scale, const TVStack& dv, TVStack& df) override;
  double totalElasticEnergy(btScalar dt) override;

 private:
  // Per body: the rest geometry the averages need (node volumes V_a, each tetrahedron's face
  // neighbours, −1 on the surface) and scratch for the per-element and nodal strains. Built the
  // first time a body is evaluated; the force runs on the host, not in rt_core.
  struct BodyScratch {
    const btSoftBody* body = nullptr;
    std::vector<double> node_volume_m3;
    std::vector<std::array<int, 4>> face_neighbours;
    // Σ over a tetrahedron's faces of its face strains ε̄_f = own_weight·ε_t + Σ_f
    // neighbour_weight[f]·ε_n(f), the weights V/(V_t + V_n) of each shared face (a surface face
    // is ε_t alone): precomputed, because reading a neighbour's volume from Bullet's Tetra (one
    // cache line of 288 bytes per random neighbour) took half the time of an evaluation.
    std::vector<double> own_weight;
    // Each tetrahedron's nodes as indices into the body, and the body's nodes' indices into the
    // solver's stacks (Node::index, refreshed per evaluation): the per-tetrahedron loops read
    // these small arrays instead of following four Node pointers twice.
    std::vector<std::array<int, 4>> tetra_nodes;
    std::vector<int> stack_index;
    std::vector<std::array<float, 4>> neighbour_weight;
    std::vector<double> node_volumetric_strain;
    std::vector<btMatrix3x3> element_strain;
  };
  BodyScratch& scratch_for(const btSoftBody& body);
  // Adds −scale·V_t·R_t P_t Dm⁻ᵀ for the per-element symmetric strains strain(body, j, stack
  // indices of its nodes) (in each
  // element's corotated frame) with moduli (μ, λ): the elastic force, its differential and the
  // damping all go through here.
  // The first pass, shared by the forces and the energy: each tetrahedron's strain(j) into
  // element_strain, its volume-weighted trace averaged at each node into node_volumetric_strain
  // (θ_a), and the nodes' stack indices refreshed.
  template <class Strain>
  static void store_strains(const btSoftBody& body, BodyScratch& s, Strain strain);
  template <class Strain, class Rotation>
  void add_smoothed_stress_forces(btScalar scale, double mu, double lambda, Strain strain, Rotation rotation, TVStack& out);

  std::vector<BodyScratch> scratch_;
};

}  // namespace fissure::host
