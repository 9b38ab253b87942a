#include "fissure/shared/message_validation.hpp"

#include <cmath>

namespace fissure {
namespace {

bool finite3(const Vec3& v) noexcept { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); }
bool within(const Vec3& v, double bound) noexcept {
  return std::fabs(v[0]) <= bound && std::fabs(v[1]) <= bound && std::fabs(v[2]) <= bound;
}

ProxyError validate_patch(const ContactPatch& p) noexcept {
  if (!finite3(p.plane_point_world_m) || !finite3(p.normal_world) || !std::isfinite(p.stiffness_k) ||
      !std::isfinite(p.damping_lambda) || !std::isfinite(p.exponent_n) ||
      !finite3(p.reference_tool_position_world_m) || !std::isfinite(p.reference_tool_orientation_world[0]) ||
      !std::isfinite(p.reference_tool_orientation_world[1]) || !std::isfinite(p.reference_tool_orientation_world[2]) ||
      !std::isfinite(p.reference_tool_orientation_world[3])) {
    return ProxyError::kNonFinite;
  }
  if (!within(p.plane_point_world_m, ProxyLimits::kMaxCoordinate_m) ||
      !within(p.reference_tool_position_world_m, ProxyLimits::kMaxCoordinate_m)) {
    return ProxyError::kCoordinateOutOfRange;
  }
  const double norm = as_eigen(p.normal_world).norm();
  if (std::fabs(norm - 1.0) > ProxyLimits::kUnitNormalTolerance) return ProxyError::kNormalNotUnit;
  if (p.stiffness_k < 0.0 || p.stiffness_k > ProxyLimits::kMaxStiffness) return ProxyError::kStiffnessOutOfRange;
  if (p.damping_lambda < 0.0 || p.damping_lambda > ProxyLimits::kMaxDamping) return ProxyError::kDampingOutOfRange;
  if (p.exponent_n < ProxyLimits::kMinExponent || p.exponent_n > ProxyLimits::kMaxExponent) {
    return ProxyError::kExponentOutOfRange;
  }
  const auto part = static_cast<std::uint32_t>(p.tool_part);
  if (part > static_cast<std::uint32_t>(ToolPart::kJawB)) return ProxyError::kBadToolPart;
  return ProxyError::kNone;
}

ProxyError validate_friction(const PartFriction& f) noexcept {
  if (!finite3(f.host_force_world_n) || !finite3(f.reference_part_position_world_m) ||
      !finite3(f.surface_velocity_world_m_per_s) || !std::isfinite(f.static_ratio) || !std::isfinite(f.kinetic_ratio)) {
    return ProxyError::kNonFinite;
  }
  if (f.static_ratio < 0.0 || f.static_ratio > ProxyLimits::kMaxFrictionRatio || f.kinetic_ratio < 0.0 ||
      f.kinetic_ratio > f.static_ratio || as_eigen(f.host_force_world_n).norm() > ProxyLimits::kMaxFrictionForce_n ||
      !within(f.reference_part_position_world_m, ProxyLimits::kMaxCoordinate_m) ||
      !within(f.surface_velocity_world_m_per_s, ProxyLimits::kMaxSurfaceSpeed_m_per_s)) {
    return ProxyError::kFrictionOutOfRange;
  }
  return ProxyError::kNone;
}

}  // namespace

const char* to_string(ProxyError error) noexcept {
  switch (error) {
    case ProxyError::kNone: return "ok";
    case ProxyError::kWrongVersion: return "protocol version mismatch";
    case ProxyError::kTooManyPatches: return "patch_count exceeds kMaxContactPatches";
    case ProxyError::kNonFinite: return "non-finite value (NaN/inf)";
    case ProxyError::kCoordinateOutOfRange: return "coordinate out of range";
    case ProxyError::kNormalNotUnit: return "normal is not a unit vector";
    case ProxyError::kStiffnessOutOfRange: return "stiffness k out of range";
    case ProxyError::kDampingOutOfRange: return "damping lambda out of range";
    case ProxyError::kExponentOutOfRange: return "exponent n out of range";
    case ProxyError::kBadToolPart: return "unknown tool part";
    case ProxyError::kFrictionOutOfRange: return "part friction out of range (ratio outside [0, 2], kinetic above static, force or position too large)";
  }
  return "unknown proxy error";
}

ProxyError validate(const ContactProxy& proxy, int* bad_patch) noexcept {
  if (bad_patch != nullptr) *bad_patch = -1;
  if (proxy.protocol_version != kProtocolVersion) return ProxyError::kWrongVersion;
  if (proxy.patch_count > kMaxContactPatches) return ProxyError::kTooManyPatches;
  for (std::uint16_t i = 0; i < proxy.patch_count; ++i) {
    const ProxyError error = validate_patch(proxy.patches[i]);
    if (error != ProxyError::kNone) {
      if (bad_patch != nullptr) *bad_patch = i;
      return error;
    }
  }
  for (std::size_t part = 0; part < proxy.friction.size(); ++part) {
    if ((proxy.flags & proxy_friction_bit(static_cast<ToolPart>(part))) == 0u) continue;
    const ProxyError error = validate_friction(proxy.friction[part]);
    if (error != ProxyError::kNone) return error;
  }
  return ProxyError::kNone;
}

bool is_finite(const DeviceState& state) noexcept {
  return finite3(state.position_device_m) && finite3(state.velocity_device_m_per_s) &&
         std::isfinite(state.closing_axis_m);
}

}  // namespace fissure
