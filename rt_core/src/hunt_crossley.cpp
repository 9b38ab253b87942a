#include "fissure/rt_core/hunt_crossley.hpp"

#include <algorithm>
#include <cmath>

namespace fissure::rt {
namespace {

// xⁿ without std::pow for the exponents the brief names (1 flat punch, 1.5 Hertz, 2):
// pow costs ~20–40 ns, and with 8 patches that is most of the tick budget.
double power(double x, double n) noexcept {
  if (n == 1.0) return x;
  if (n == 1.5) return x * std::sqrt(x);
  if (n == 2.0) return x * x;
  return std::pow(x, n);
}

}  // namespace

double hunt_crossley_force_n(double x, double x_dot, double k, double lambda, double n) noexcept {
  if (!(x > 0.0)) return 0.0;
  const double x_n = power(x, n);
  return std::max(0.0, k * x_n + lambda * x_n * x_dot);
}

ContactEvaluation evaluate_proxy(const ContactProxy& proxy, const DeviceMapping& mapping, const ToolState& tool,
                                 PartForces& forces, const DampingCap& cap, PartNormalLoad* load) noexcept {
  forces.clear();
  if (load != nullptr) *load = PartNormalLoad{};
  ContactEvaluation evaluation;
  evaluation.max_penetration_m = -1.0;  // "no patch": any real penetration is larger
  const int count = std::min<int>(proxy.patch_count, static_cast<int>(kMaxContactPatches));
  for (int i = 0; i < count; ++i) {
    const ContactPatch& patch = proxy.patches[i];
    const auto part_index = static_cast<std::size_t>(patch.tool_part);
    if (part_index >= forces.force_world_n.size()) continue;  // validate() rejects these anyway
    const PartMotion motion = part_motion(mapping, tool, patch.tool_part);
    const Eigen::Map<const Eigen::Vector3d> normal = as_eigen(patch.normal_world);
    const double x = (as_eigen(patch.plane_point_world_m) - motion.p_world_m).dot(normal);
    evaluation.max_penetration_m = std::max(evaluation.max_penetration_m, x);
    if (!(x > 0.0)) continue;
    const double x_dot = -motion.v_world_m_per_s.dot(normal);
    const double k = patch.stiffness_k;
    const double n = patch.exponent_n;
    const double x_n = power(x, n);
    // Colgate–Schenkel (header): the damping λ·xⁿ at most b − n·k·xⁿ⁻¹·T/2, as a λ for this x.
    const double tangent_stiffness = n * k * x_n / x;
    const double max_damping = std::max(0.0, cap.device_damping_world_n_s_per_m - 0.5 * tangent_stiffness * cap.period_s);
    const double lambda = std::min(patch.damping_lambda, max_damping / x_n);
    forces.force_world_n[part_index] += std::max(0.0, k * x_n + lambda * x_n * x_dot) * normal;
    if (load != nullptr) {
      load->elastic_force_world_n[part_index] += k * x_n * normal;
      load->elastic_sum_n[part_index] += k * x_n;
    }
    evaluation.stored_energy_world_j += k * x_n * x / (n + 1.0);
    ++evaluation.patches_in_contact;
  }
  return evaluation;
}

}  // namespace fissure::rt
