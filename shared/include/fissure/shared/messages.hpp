#pragma once
// The messages rt_core and host_sim exchange (BRIEF §2). Fixed size, trivially copyable,
// layout pinned by static_assert so that the in-process exchange, the wire codec and a
// memcpy all agree. SI units everywhere; every vector names its frame:
//   *_device : the Falcon's kinematic frame (libnifalcon's): origin at the centre of the
//              base, z pointing out of the device towards the user, y up, x to the right.
//   *_world  : the scene's frame (host_sim, Bullet), y up.
// The device→world mapping (scale, offset, axis permutation, clamp mode) is part of the
// session configuration and applied by rt_core; the host receives device-frame samples.
//
// Changing any struct below changes its size or meaning: bump kProtocolVersion.
#include <array>
#include <cstddef>
#include <cstdint>
#include <type_traits>

#include <Eigen/Core>

#include "fissure/shared/time.hpp"

namespace fissure {

/// Version of the layouts below and of the wire codec built on them. The transport
/// handshake refuses a peer with a different version (naming both).
/// 2: DeviceState::status_flags bits 24..31 carry the position epoch (below).
/// 3: the Hello carries the session fingerprint and scene name, and a closing flag
///    (wire_codec.hpp, wire_handshake.hpp).
/// 4: the ContactProxy carries friction per tool part (PartFriction: μ and the host's friction
///    force at its reference pose) for rt_core's friction cone.
inline constexpr std::uint16_t kProtocolVersion = 4;

/// One patch per tool face or jaw is enough for the paper's tools (spatula: 2 faces,
/// clamp: 2 jaws × 2 faces); 8 leaves room for a convex tool's rim.
inline constexpr std::size_t kMaxContactPatches = 8;

using Vec3 = std::array<double, 3>;
using Quat = std::array<double, 4>;  // unit quaternion, (w, x, y, z)

inline Eigen::Map<const Eigen::Vector3d> as_eigen(const Vec3& v) noexcept { return Eigen::Map<const Eigen::Vector3d>(v.data()); }
inline Eigen::Map<Eigen::Vector3d> as_eigen(Vec3& v) noexcept { return Eigen::Map<Eigen::Vector3d>(v.data()); }
inline Vec3 to_vec3(const Eigen::Vector3d& v) noexcept { return {v.x(), v.y(), v.z()}; }

/// Device status and fault bits carried in DeviceState::status_flags.
enum DeviceStatusBits : std::uint32_t {
  kDeviceHomed = 1u << 0,            ///< all three arms report homed
  kDeviceSimulated = 1u << 1,        ///< the sample comes from SimFalcon, not USB
  kDeviceFaultTimeout = 1u << 8,     ///< no reply within the I/O deadline
  kDeviceFaultDisconnected = 1u << 9,///< USB device gone / transport closed
  kDeviceFaultTornPacket = 1u << 10, ///< reply failed to parse this tick (resynchronising)
  kDeviceFaultEncoderJump = 1u << 11,///< encoder moved faster than the mechanism can
  kDeviceFaultNonFinite = 1u << 12,  ///< kinematics produced NaN/inf or did not converge
  kDeviceFaultMask = 0xFFFFu << 8,
};

/// Bits 24..31 of DeviceState::status_flags: the *position epoch*, a counter rt_core advances
/// each time the position it publishes is not continuous with the one it published before —
/// the first accepted sample after rejected ones (an encoder jump, a non-finite sample, an I/O
/// fault or timeout) and the very first sample. Why: after an encoder jump rt_core accepts the
/// jumped reading as the new truth (lost counts cannot be told from a re-home until the next
/// homing), so position_device_m may step by centimetres between two samples, on a tick whose
/// fault bits the host cannot rely on seeing. That step is not motion of the hand; a host that
/// swept its tool along it would drag the soft body through itself (the stress case
/// encoder_jumps turned the ball inside out). A host re-seats its tool, without sweeping, when
/// the epoch differs from the last one it applied. A counter, not a one-tick flag, so that a
/// lost or reordered DeviceState (UDP/CAN at 50 % loss) cannot hide the discontinuity: any later
/// sample still carries the new value. Epoch 0 = no accepted sample yet (position_device_m is
/// not a reading); it wraps 255 → 1, so only 255 discontinuities between two samples the host
/// receives could alias. It sits in status bits no flag uses (kDeviceFaultMask is 8..23), so the
/// struct's layout and the wire codec (which carries status_flags whole) are unchanged.
inline constexpr unsigned kDevicePositionEpochShift = 24;
inline constexpr std::uint32_t kDevicePositionEpochMask = 0xFFu << kDevicePositionEpochShift;

/// The position epoch carried in `status_flags` (0: no accepted sample yet).
constexpr std::uint8_t position_epoch(std::uint32_t status_flags) noexcept {
  return static_cast<std::uint8_t>((status_flags & kDevicePositionEpochMask) >> kDevicePositionEpochShift);
}
/// `status_flags` with its epoch bits replaced by `epoch`.
constexpr std::uint32_t with_position_epoch(std::uint32_t status_flags, std::uint8_t epoch) noexcept {
  return (status_flags & ~kDevicePositionEpochMask) | (static_cast<std::uint32_t>(epoch) << kDevicePositionEpochShift);
}
/// The epoch after `epoch`: 1 … 255, then 1 again (0 is reserved for "no accepted sample").
constexpr std::uint8_t next_position_epoch(std::uint8_t epoch) noexcept {
  return epoch == 0xFFu ? std::uint8_t{1} : static_cast<std::uint8_t>(epoch + 1u);
}
static_assert((kDevicePositionEpochMask & kDeviceFaultMask) == 0u, "the epoch must not overlap a fault bit");
static_assert(next_position_epoch(0xFFu) == 1u && next_position_epoch(0u) == 1u);

/// One sample of the haptic device as rt_core saw it (rt_core → host_sim, and telemetry).
struct DeviceState {
  std::uint64_t sequence = 0;        ///< +1 per published sample; gaps mean lost samples
  TimeNs sample_time_ns = 0;         ///< when the encoders were read (shared timeline)
  Vec3 position_device_m{};          ///< end-effector position, device frame [m]
  Vec3 velocity_device_m_per_s{};    ///< filtered end-effector velocity, device frame [m/s]
  double closing_axis_m = 0.0;       ///< clamp mode: rt::jaw_closing_m of this sample [m], the host's jaw closing; else 0
  std::uint32_t buttons = 0;         ///< bit i = grip button i pressed (Falcon: 4 buttons)
  std::uint32_t status_flags = 0;    ///< DeviceStatusBits; bits 24..31: position epoch (position_epoch())
};
static_assert(std::is_trivially_copyable_v<DeviceState>);
static_assert(sizeof(DeviceState) == 80);
static_assert(offsetof(DeviceState, position_device_m) == 16);
static_assert(offsetof(DeviceState, buttons) == 72);

/// Which rigid part of the tool a patch acts on; the clamp's jaws get separate force sums.
enum class ToolPart : std::uint32_t { kTool = 0, kJawA = 1, kJawB = 2 };

/// A local model of one contact region (BRIEF §5): a plane that moves with the soft
/// surface, and the Hunt-Crossley law that reproduces the host's force for that region.
/// rt_core evaluates it against the *current* tool position p_tool_world:
///   x = (plane_point_world_m − p_tool_world) · normal_world   (penetration, m)
///   F = max(0, k·xⁿ + λ·xⁿ·ẋ) · normal_world  for x > 0, else 0
/// Friction is per tool part, not per patch (PartFriction below).
struct ContactPatch {
  Vec3 plane_point_world_m{};        ///< a point on the zero-penetration plane, world frame [m]
  Vec3 normal_world{};               ///< unit normal, world frame: direction of the force on the tool
  double stiffness_k = 0.0;          ///< Hunt-Crossley k [N/mⁿ]
  double damping_lambda = 0.0;       ///< Hunt-Crossley λ [N·s/m⁽ⁿ⁺¹⁾]
  double exponent_n = 1.0;           ///< Hunt-Crossley n [-], 1 (flat punch) … 2
  Vec3 reference_tool_position_world_m{};  ///< tool origin when the host built the patch [m]
  Quat reference_tool_orientation_world{1.0, 0.0, 0.0, 0.0};  ///< tool orientation then
  TimeNs reference_time_ns = 0;      ///< host simulation time of that tool pose
  ToolPart tool_part = ToolPart::kTool;
  std::uint32_t reserved = 0;        ///< zero; keeps the layout 8-byte aligned
};
static_assert(std::is_trivially_copyable_v<ContactPatch>);
static_assert(sizeof(ContactPatch) == 144);

/// Coulomb friction on one tool part (rt_core/friction_cone.hpp). rt_core renders, at the current
/// position, the host's friction force continued by a stick spring to the tissue surface, which
/// moves on at the surface's velocity, inside the cone μ × the patches' normal force — so a part
/// sliding over tissue feels μ_k·F_n from the first tick, and a part holding tissue that moves with
/// it (a lifted vessel) feels what the tissue pulls, not a phantom slide.
struct PartFriction {
  Vec3 host_force_world_n{};               ///< the host's friction force on the part at its reference pose [N]
  Vec3 reference_part_position_world_m{};  ///< the part's position then (tool origin or jaw, rt's convention) [m]
  Vec3 surface_velocity_world_m_per_s{};   ///< velocity of the tissue under the part then (force-weighted) [m/s]
  double static_ratio = 0.0;               ///< Coulomb μ_s of the tool–tissue pair [-], 0 … 2
  double kinetic_ratio = 0.0;              ///< Coulomb μ_k [-], 0 … μ_s
};
static_assert(std::is_trivially_copyable_v<PartFriction>);
static_assert(sizeof(PartFriction) == 88);

enum ContactProxyBits : std::uint32_t {
  kProxyValid = 1u << 0,             ///< host asserts the content is usable
  kProxyHostInContact = 1u << 1,     ///< host saw contact at the reference pose
  /// Bits 2..4: ContactProxy::friction[part] is meaningful (part = bit − 2); a part without its
  /// bit has no friction. Only these parts' friction travels on the wire.
  kProxyFrictionTool = 1u << 2,
  kProxyFrictionJawA = 1u << 3,
  kProxyFrictionJawB = 1u << 4,
};
inline constexpr unsigned kProxyFrictionShift = 2;
/// The flag bit that says part `part`'s friction is present.
constexpr std::uint32_t proxy_friction_bit(ToolPart part) noexcept {
  return 1u << (kProxyFrictionShift + static_cast<std::uint32_t>(part));
}

/// The contact proxy host_sim publishes after each step (host_sim → rt_core).
struct ContactProxy {
  std::uint64_t sequence = 0;        ///< +1 per host step that published
  TimeNs host_time_ns = 0;           ///< host simulation time of the step
  std::uint16_t protocol_version = kProtocolVersion;
  std::uint16_t patch_count = 0;     ///< patches[0, patch_count) are meaningful
  std::uint32_t flags = 0;           ///< ContactProxyBits
  std::array<ContactPatch, kMaxContactPatches> patches{};
  std::array<PartFriction, 3> friction{};  ///< indexed by ToolPart; meaningful where flags has proxy_friction_bit
};
static_assert(std::is_trivially_copyable_v<ContactProxy>);
static_assert(offsetof(ContactProxy, patches) == 24);
static_assert(sizeof(ContactProxy) == 24 + kMaxContactPatches * sizeof(ContactPatch) + 3 * sizeof(PartFriction));

}  // namespace fissure
