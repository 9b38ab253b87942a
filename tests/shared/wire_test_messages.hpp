#pragma once
// Deterministic test messages for the wire suites, and the exact value each one has after
// the float32 wire encoding (so "received == sent" can be asserted exactly, not loosely).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "fissure/shared/messages.hpp"
#include "fissure/shared/wire_reassembler.hpp"

namespace fissure::test {

/// Small deterministic PRNG for message contents (splitmix64).
class ContentRandom {
 public:
  explicit ContentRandom(std::uint64_t seed) : state_(seed) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform(double lo, double hi) { return lo + (hi - lo) * static_cast<double>(next() >> 11) * 0x1.0p-53; }

 private:
  std::uint64_t state_;
};

/// A valid proxy whose every field depends on `sequence`: two different proxies never agree,
/// so a mix of two cannot pass for either. `friction_mask`: bit p = part p carries friction;
/// < 0: the parts follow from `sequence` (every combination of the three occurs).
inline ContactProxy make_proxy(std::uint64_t sequence, std::uint16_t patch_count, int friction_mask = -1) {
  ContentRandom random(sequence * 7919 + patch_count);
  ContactProxy proxy;
  proxy.sequence = sequence;
  proxy.host_time_ns = static_cast<TimeNs>(sequence) * 1'000'000 + 17;
  proxy.patch_count = patch_count;
  proxy.flags = kProxyValid | (sequence % 2 == 0 ? kProxyHostInContact : 0u);
  for (std::uint16_t i = 0; i < patch_count; ++i) {
    ContactPatch& patch = proxy.patches[i];
    patch.plane_point_world_m = {random.uniform(-0.1, 0.1), random.uniform(-0.1, 0.1), random.uniform(-0.1, 0.1)};
    Eigen::Vector3d normal(random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(0.2, 1));
    normal.normalize();
    patch.normal_world = to_vec3(normal);
    patch.stiffness_k = random.uniform(100.0, 3000.0);
    patch.damping_lambda = random.uniform(0.0, 5.0);
    patch.exponent_n = random.uniform(1.0, 2.0);
    patch.reference_tool_position_world_m = {random.uniform(-0.05, 0.05), random.uniform(-0.05, 0.05),
                                             random.uniform(-0.05, 0.05)};
    Eigen::Vector4d q(random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1));
    q.normalize();
    patch.reference_tool_orientation_world = {q[0], q[1], q[2], q[3]};
    patch.reference_time_ns = proxy.host_time_ns - static_cast<TimeNs>(random.next() % 1'000'000);
    patch.tool_part = static_cast<ToolPart>(random.next() % 3);
  }
  const auto mask = static_cast<std::uint32_t>(friction_mask < 0 ? static_cast<int>(sequence % 8) : friction_mask);
  for (std::size_t part = 0; part < proxy.friction.size(); ++part) {
    if ((mask & (1u << part)) == 0u) continue;
    proxy.flags |= proxy_friction_bit(static_cast<ToolPart>(part));
    PartFriction& friction = proxy.friction[part];
    friction.host_force_world_n = {random.uniform(-2, 2), random.uniform(-2, 2), random.uniform(-2, 2)};
    friction.reference_part_position_world_m = {random.uniform(-0.1, 0.1), random.uniform(-0.1, 0.1), random.uniform(-0.1, 0.1)};
    friction.surface_velocity_world_m_per_s = {random.uniform(-0.5, 0.5), random.uniform(-0.5, 0.5), random.uniform(-0.5, 0.5)};
    friction.static_ratio = random.uniform(0.0, 2.0);
    friction.kinetic_ratio = random.uniform(0.0, friction.static_ratio);
  }
  return proxy;
}

inline DeviceState make_device_state(std::uint64_t sequence) {
  ContentRandom random(sequence * 104729 + 3);
  DeviceState state;
  state.sequence = sequence;
  state.sample_time_ns = static_cast<TimeNs>(sequence) * 1'000'000 + 5;
  state.position_device_m = {random.uniform(-0.06, 0.06), random.uniform(-0.06, 0.06), random.uniform(0.07, 0.18)};
  state.velocity_device_m_per_s = {random.uniform(-1, 1), random.uniform(-1, 1), random.uniform(-1, 1)};
  state.closing_axis_m = random.uniform(-0.01, 0.01);
  state.buttons = static_cast<std::uint32_t>(random.next() & 0xF);
  state.status_flags = kDeviceHomed | kDeviceSimulated;
  return state;
}

/// The value a double has after a float32 round trip. The volatile is deliberate: GCC 12 at
/// -O2 vectorises three inlined (double)(float)x conversions in a brace initialiser and drops
/// the rounding of the first two (seen in this suite); a volatile float forces the real store.
inline double as_float32(double v) {
  volatile float rounded = static_cast<float>(v);
  return static_cast<double>(rounded);
}
inline Vec3 as_float32(const Vec3& v) { return {as_float32(v[0]), as_float32(v[1]), as_float32(v[2])}; }

/// Orientation precision after "smallest three" float32: components within this of the sent ones.
inline constexpr double kOrientationTolerance = 2e-7;

/// Asserts `received` is exactly `sent` as the wire represents it: integers and times exact,
/// every float32 field equal to the sent double rounded to float32, orientation within
/// kOrientationTolerance, unsent patches default.
inline void expect_wire_equal(const ContactProxy& sent, const ContactProxy& received) {
  ASSERT_EQ(received.sequence, sent.sequence);
  EXPECT_EQ(received.host_time_ns, sent.host_time_ns);
  EXPECT_EQ(received.protocol_version, kProtocolVersion);
  ASSERT_EQ(received.patch_count, sent.patch_count);
  EXPECT_EQ(received.flags, sent.flags);
  for (std::size_t i = 0; i < kMaxContactPatches; ++i) {
    const ContactPatch& a = sent.patches[i];
    const ContactPatch& b = received.patches[i];
    if (i >= sent.patch_count) {
      const ContactPatch empty{};
      EXPECT_EQ(b.plane_point_world_m, empty.plane_point_world_m) << "patch " << i;
      EXPECT_EQ(b.stiffness_k, empty.stiffness_k) << "patch " << i;
      EXPECT_EQ(b.reference_tool_orientation_world, empty.reference_tool_orientation_world) << "patch " << i;
      continue;
    }
    EXPECT_EQ(b.plane_point_world_m, as_float32(a.plane_point_world_m)) << "patch " << i;
    EXPECT_EQ(b.normal_world, as_float32(a.normal_world)) << "patch " << i;
    EXPECT_EQ(b.stiffness_k, as_float32(a.stiffness_k)) << "patch " << i;
    EXPECT_EQ(b.damping_lambda, as_float32(a.damping_lambda)) << "patch " << i;
    EXPECT_EQ(b.exponent_n, as_float32(a.exponent_n)) << "patch " << i;
    EXPECT_EQ(b.reference_tool_position_world_m, as_float32(a.reference_tool_position_world_m)) << "patch " << i;
    for (int c = 0; c < 4; ++c) {
      EXPECT_NEAR(b.reference_tool_orientation_world[c], a.reference_tool_orientation_world[c], kOrientationTolerance)
          << "patch " << i << " component " << c;
    }
    EXPECT_EQ(b.reference_time_ns, a.reference_time_ns) << "patch " << i;
    EXPECT_EQ(b.tool_part, a.tool_part) << "patch " << i;
    EXPECT_EQ(b.reserved, 0u);
  }
  for (std::size_t part = 0; part < sent.friction.size(); ++part) {
    const PartFriction& a = sent.friction[part];
    const PartFriction& b = received.friction[part];
    if ((sent.flags & proxy_friction_bit(static_cast<ToolPart>(part))) == 0u) {
      const PartFriction empty{};
      EXPECT_EQ(b.host_force_world_n, empty.host_force_world_n) << "part " << part;
      EXPECT_EQ(b.static_ratio, empty.static_ratio) << "part " << part;
      continue;
    }
    EXPECT_EQ(b.host_force_world_n, as_float32(a.host_force_world_n)) << "part " << part;
    EXPECT_EQ(b.reference_part_position_world_m, as_float32(a.reference_part_position_world_m)) << "part " << part;
    EXPECT_EQ(b.surface_velocity_world_m_per_s, as_float32(a.surface_velocity_world_m_per_s)) << "part " << part;
    // μ travels in steps of 10⁻⁴ (wire_codec.hpp).
    EXPECT_EQ(b.static_ratio, ::fissure::wire::friction_ratio_from_wire(::fissure::wire::friction_ratio_to_wire(a.static_ratio))) << "part " << part;
    EXPECT_EQ(b.kinetic_ratio, ::fissure::wire::friction_ratio_from_wire(::fissure::wire::friction_ratio_to_wire(a.kinetic_ratio))) << "part " << part;
    EXPECT_NEAR(b.static_ratio, a.static_ratio, 0.5e-4) << "part " << part;
    EXPECT_LE(b.kinetic_ratio, b.static_ratio) << "part " << part;
  }
}

inline void expect_wire_equal(const DeviceState& sent, const DeviceState& received) {
  EXPECT_EQ(received.sequence, sent.sequence);
  EXPECT_EQ(received.sample_time_ns, sent.sample_time_ns);
  EXPECT_EQ(received.position_device_m, as_float32(sent.position_device_m));
  EXPECT_EQ(received.velocity_device_m_per_s, as_float32(sent.velocity_device_m_per_s));
  EXPECT_EQ(received.closing_axis_m, as_float32(sent.closing_axis_m));
  EXPECT_EQ(received.buttons, sent.buttons);
  EXPECT_EQ(received.status_flags, sent.status_flags);
}

/// The two bookkeeping identities documented in wire_reassembler.hpp.
inline void expect_counts_add_up(const wire::Reassembler& reassembler) {
  const wire::WireStats& s = reassembler.stats();
  EXPECT_EQ(s.frames_received, s.frames_accepted + s.frames_discarded()) << "every frame counted exactly once";
  EXPECT_EQ(s.messages_started, s.hellos_received + s.device_states_applied + s.proxies_applied +
                                    s.messages_discarded() + reassembler.pending_assemblies())
      << "every started message ends in exactly one counter";
}

}  // namespace fissure::test
