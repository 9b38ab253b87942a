// Proxy builder: contact records → ≤ 8 Hunt-Crossley patches (see the header for the derivation).
#include "fissure/host_sim/proxy_builder.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "fissure/shared/message_validation.hpp"

namespace fissure::host {
namespace {

// Below this group force the patch normal is taken from the face instead of the (zero) force
// vector. 1 µN is far under the Falcon's force resolution (~1 mN per motor count).
constexpr double kNegligibleForce_n = 1.0e-6;
// Depths below this are "touching, not deformed": 1 nm is well under float precision of Bullet's
// single-precision node positions at scene scale (~10 nm at 0.1 m).
constexpr double kNegligibleDepth_m = 1.0e-9;

}  // namespace

ProxyBuilder::ProxyBuilder(const ProxyBuilderModel& model) : model_(model) {
  if (model.jaw_count < 1 || model.jaw_count > kMaxProxyJaws) {
    throw std::invalid_argument("proxy builder: jaw_count " + std::to_string(model.jaw_count) + " outside [1, " +
                                std::to_string(kMaxProxyJaws) + "]");
  }
  if (!(model.hunt_crossley.n > 0.0) || !std::isfinite(model.hunt_crossley.n)) {
    throw std::invalid_argument("proxy builder: Hunt-Crossley exponent n must be finite and > 0");
  }
  if (!(model.hunt_crossley.k >= 0.0) || !(model.hunt_crossley.lambda >= 0.0)) {
    throw std::invalid_argument("proxy builder: Hunt-Crossley k and lambda must be >= 0");
  }
  if (!(model.friction_static_ratio >= 0.0 && model.friction_static_ratio <= ProxyLimits::kMaxFrictionRatio) ||
      !(model.friction_kinetic_ratio >= 0.0 && model.friction_kinetic_ratio <= model.friction_static_ratio)) {
    throw std::invalid_argument("proxy builder: friction ratios must satisfy 0 <= kinetic <= static <= 2, got static " +
                                std::to_string(model.friction_static_ratio) + ", kinetic " +
                                std::to_string(model.friction_kinetic_ratio));
  }
  int total = 0;
  for (int jaw = 0; jaw < model.jaw_count; ++jaw) {
    const auto j = static_cast<std::size_t>(jaw);
    if (model.plane_count[j] < 0) {
      throw std::invalid_argument("proxy builder: plane_count of jaw " + std::to_string(jaw) + " is negative");
    }
    const auto part = static_cast<std::uint32_t>(model.part_of_jaw[j]);
    if (part > static_cast<std::uint32_t>(ToolPart::kJawB)) {
      throw std::invalid_argument("proxy builder: part_of_jaw[" + std::to_string(jaw) + "] is not a ToolPart");
    }
    group_offset_[j] = total;
    total += model.plane_count[j];
  }
  groups_.resize(static_cast<std::size_t>(total));
  active_groups_.reserve(static_cast<std::size_t>(total));
}

void ProxyBuilder::reset_groups() noexcept {
  for (const int g : active_groups_) groups_[static_cast<std::size_t>(g)] = Group{};
  active_groups_.clear();
}

const ProxyBuildReport& ProxyBuilder::build(const std::vector<ContactRecord>& contacts, const ToolPose& tool_pose,
                                            const ProxyPartMotion& parts, TimeNs host_time_ns,
                                            ContactProxy& out) noexcept {
  reset_groups();
  report_ = ProxyBuildReport{};
  const double n = model_.hunt_crossley.n;

  // 1. Sums per (jaw, plane).
  for (const ContactRecord& record : contacts) {
    if (record.jaw < 0 || record.jaw >= model_.jaw_count || record.tool_plane < 0 ||
        record.tool_plane >= model_.plane_count[static_cast<std::size_t>(record.jaw)] ||
        !std::isfinite(record.penetration_m) || !std::isfinite(record.force_n) || !record.normal_world.allFinite()) {
      ++report_.skipped_records;
      continue;
    }
    const int index = group_offset_[static_cast<std::size_t>(record.jaw)] + record.tool_plane;
    Group& group = groups_[static_cast<std::size_t>(index)];
    if (!group.active) {
      group.active = true;
      group.part = model_.part_of_jaw[static_cast<std::size_t>(record.jaw)];
      // The host pushes the tool along the inward normal of the face (hunt_crossley_force.cpp).
      group.face_force_direction = -record.normal_world.normalized();
      active_groups_.push_back(index);
    }
    const double x = std::max(0.0, record.penetration_m);
    group.force_world_n += record.force_n * group.face_force_direction;
    group.force_sum_n += record.force_n;
    group.sum_w += record.weight;
    if (x > 0.0) {
      const double x_pow_n1 = std::pow(x, n - 1.0);
      group.sum_w_xn += record.weight * x_pow_n1 * x;
      group.sum_w_xn1 += record.weight * x_pow_n1;
    }
  }
  report_.groups = static_cast<int>(active_groups_.size());

  // 2. Fit into kMaxContactPatches.
  merge_to_fit();

  // 3. One patch per remaining group, strongest first (deterministic order: ties by index).
  std::sort(active_groups_.begin(), active_groups_.end(), [this](int a, int b) {
    const Group& ga = groups_[static_cast<std::size_t>(a)];
    const Group& gb = groups_[static_cast<std::size_t>(b)];
    const bool a_live = ga.merged_into < 0;
    const bool b_live = gb.merged_into < 0;
    if (a_live != b_live) return a_live;
    if (ga.force_sum_n != gb.force_sum_n) return ga.force_sum_n > gb.force_sum_n;
    return a < b;
  });
  out = ContactProxy{};
  out.sequence = ++sequence_;
  out.host_time_ns = host_time_ns;
  out.protocol_version = kProtocolVersion;
  out.flags = kProxyValid;
  std::uint16_t count = 0;
  for (const int g : active_groups_) {
    const Group& group = groups_[static_cast<std::size_t>(g)];
    if (group.merged_into >= 0 || count >= kMaxContactPatches) continue;
    ContactPatch& patch = out.patches[count++];
    write_patch(group, parts, patch);
    patch.reference_tool_position_world_m = to_vec3(tool_pose.position_world_m);
    const Eigen::Quaterniond q = tool_pose.orientation_world.normalized();
    patch.reference_tool_orientation_world = {q.w(), q.x(), q.y(), q.z()};
    patch.reference_time_ns = host_time_ns;
  }
  out.patch_count = count;
  if (count > 0) out.flags |= kProxyHostInContact;
  // Friction for each part a patch pushes (rt_core renders none where no patch is).
  if (model_.friction_static_ratio > 0.0) {
    for (std::uint16_t i = 0; i < count; ++i) {
      const ToolPart part = out.patches[i].tool_part;
      const auto p = static_cast<std::size_t>(part);
      if ((out.flags & proxy_friction_bit(part)) != 0u) continue;
      out.flags |= proxy_friction_bit(part);
      PartFriction& friction = out.friction[p];
      Eigen::Vector3d force = parts.friction_force_world_n[p];
      // Keep it inside what rt_core accepts (message_validation.hpp): only a host bug gets there.
      if (!force.allFinite()) force.setZero();
      if (force.norm() > ProxyLimits::kMaxFrictionForce_n) force *= ProxyLimits::kMaxFrictionForce_n / force.norm();
      friction.host_force_world_n = to_vec3(force);
      friction.reference_part_position_world_m = to_vec3(parts.p_world_m[p]);
      Eigen::Vector3d surface_velocity = parts.surface_velocity_world_m_per_s[p];
      if (!surface_velocity.allFinite()) surface_velocity.setZero();
      friction.surface_velocity_world_m_per_s =
          to_vec3(surface_velocity.cwiseMax(-ProxyLimits::kMaxSurfaceSpeed_m_per_s).cwiseMin(ProxyLimits::kMaxSurfaceSpeed_m_per_s));
      friction.static_ratio = model_.friction_static_ratio;
      friction.kinetic_ratio = model_.friction_kinetic_ratio;
    }
  }
  return report_;
}

void ProxyBuilder::merge_to_fit() noexcept {
  auto live_count = [this] {
    std::size_t live = 0;
    for (const int g : active_groups_) live += groups_[static_cast<std::size_t>(g)].merged_into < 0 ? 1 : 0;
    return live;
  };
  while (live_count() > kMaxContactPatches) {
    // The weakest live group goes ...
    int weakest = -1;
    for (const int g : active_groups_) {
      const Group& group = groups_[static_cast<std::size_t>(g)];
      if (group.merged_into >= 0) continue;
      if (weakest < 0 || group.force_sum_n < groups_[static_cast<std::size_t>(weakest)].force_sum_n) weakest = g;
    }
    Group& from = groups_[static_cast<std::size_t>(weakest)];
    // ... into the live group of the same part whose force direction is closest to its own.
    int partner = -1;
    double best_cosine = 0.0;
    for (const int g : active_groups_) {
      const Group& group = groups_[static_cast<std::size_t>(g)];
      if (g == weakest || group.merged_into >= 0 || group.part != from.part) continue;
      const double cosine = group.face_force_direction.dot(from.face_force_direction);
      if (cosine > best_cosine) {
        best_cosine = cosine;
        partner = g;
      }
    }
    if (partner < 0) {
      // Nothing pushes the same part in a compatible direction: folding it in would cancel force.
      ++report_.dropped_groups;
      report_.dropped_force_n += from.force_world_n.norm();
      from.merged_into = weakest;  // marks it dead
      continue;
    }
    Group& into = groups_[static_cast<std::size_t>(partner)];
    // The partner's patch acts along its own normal: the merged triangles count with the cosine
    // of their face to it (their elastic share along the patch normal).
    into.force_world_n += from.force_world_n;
    into.force_sum_n += from.force_sum_n;
    into.sum_w_xn += best_cosine * from.sum_w_xn;
    into.sum_w_xn1 += best_cosine * from.sum_w_xn1;
    into.sum_w += best_cosine * from.sum_w;
    from.merged_into = partner;
    ++report_.merged_groups;
  }
}

void ProxyBuilder::write_patch(const Group& group, const ProxyPartMotion& parts, ContactPatch& patch) const noexcept {
  const HuntCrossleyParams& hc = model_.hunt_crossley;
  const double n = hc.n;
  const double force_n = group.force_world_n.norm();
  const Eigen::Vector3d normal =
      force_n > kNegligibleForce_n ? Eigen::Vector3d(group.force_world_n / force_n) : group.face_force_direction;
  const auto part_index = static_cast<std::size_t>(group.part);
  const Eigen::Vector3d& q_host = parts.p_world_m[part_index];
  const double x_dot_host = -parts.v_world_m_per_s[part_index].dot(normal);

  double depth_m = 0.0;
  double k = hc.k * group.sum_w;
  double lambda = hc.lambda * group.sum_w;
  if (group.sum_w_xn1 > 0.0 && group.sum_w_xn > 0.0) depth_m = group.sum_w_xn / group.sum_w_xn1;
  if (depth_m > kNegligibleDepth_m) {
    const double depth_pow_n = std::pow(depth_m, n);
    lambda = hc.lambda * group.sum_w_xn / depth_pow_n;
    k = (force_n - lambda * depth_pow_n * x_dot_host) / depth_pow_n;
    if (k < 0.0) {
      // Only when the tool pushes in (ẋ > 0) while the host's force is below its damping share.
      k = 0.0;
      lambda = x_dot_host > 0.0 ? force_n / (depth_pow_n * x_dot_host) : 0.0;
    }
  } else {
    depth_m = 0.0;
  }
  // Keep the patch inside what rt_core accepts (message_validation.hpp); reaching these limits
  // would take a sub-nanometre depth carrying newtons, i.e. a host bug.
  k = std::min(k, ProxyLimits::kMaxStiffness);
  lambda = std::min(lambda, ProxyLimits::kMaxDamping);

  patch.plane_point_world_m = to_vec3(q_host + depth_m * normal);
  patch.normal_world = to_vec3(normal);
  patch.stiffness_k = k;
  patch.damping_lambda = lambda;
  patch.exponent_n = n;
  patch.tool_part = group.part;
  patch.reserved = 0;
}

}  // namespace fissure::host
