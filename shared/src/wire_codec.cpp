#include "fissure/shared/wire_codec.hpp"

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

#include "fissure/shared/crc32c.hpp"

namespace fissure::wire {
namespace {

// ---- little-endian byte cursor (explicit shifts: the wire order does not depend on the CPU)

class ByteWriter {
 public:
  explicit ByteWriter(std::uint8_t* out) noexcept : out_(out) {}
  void u8(std::uint8_t v) noexcept { out_[at_++] = v; }
  void u16(std::uint16_t v) noexcept {
    for (int i = 0; i < 2; ++i) out_[at_++] = static_cast<std::uint8_t>(v >> (8 * i));
  }
  void u32(std::uint32_t v) noexcept {
    for (int i = 0; i < 4; ++i) out_[at_++] = static_cast<std::uint8_t>(v >> (8 * i));
  }
  void u64(std::uint64_t v) noexcept {
    for (int i = 0; i < 8; ++i) out_[at_++] = static_cast<std::uint8_t>(v >> (8 * i));
  }
  void i64(std::int64_t v) noexcept { u64(static_cast<std::uint64_t>(v)); }
  void f32(float v) noexcept { u32(std::bit_cast<std::uint32_t>(v)); }
  void f32(double v) noexcept { f32(to_float32(v)); }
  void vec3(const Vec3& v) noexcept {
    for (const double c : v) f32(c);
  }
  [[nodiscard]] std::size_t size() const noexcept { return at_; }

  /// double → float32 without the undefined behaviour of converting an out-of-range value:
  /// beyond ±FLT_MAX becomes ±inf (rejected by the receiver's validation), NaN stays NaN.
  static float to_float32(double v) noexcept {
    constexpr double kMax = static_cast<double>(std::numeric_limits<float>::max());
    if (std::isnan(v)) return std::numeric_limits<float>::quiet_NaN();
    if (v > kMax) return std::numeric_limits<float>::infinity();
    if (v < -kMax) return -std::numeric_limits<float>::infinity();
    return static_cast<float>(v);
  }

 private:
  std::uint8_t* out_;
  std::size_t at_ = 0;
};

class ByteReader {
 public:
  explicit ByteReader(const std::uint8_t* in) noexcept : in_(in) {}
  std::uint8_t u8() noexcept { return in_[at_++]; }
  std::uint16_t u16() noexcept {
    std::uint16_t v = 0;
    for (int i = 0; i < 2; ++i) v = static_cast<std::uint16_t>(v | (static_cast<std::uint16_t>(in_[at_++]) << (8 * i)));
    return v;
  }
  std::uint32_t u32() noexcept {
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(in_[at_++]) << (8 * i);
    return v;
  }
  std::uint64_t u64() noexcept {
    std::uint64_t v = 0;
    for (int i = 0; i < 8; ++i) v |= static_cast<std::uint64_t>(in_[at_++]) << (8 * i);
    return v;
  }
  std::int64_t i64() noexcept { return static_cast<std::int64_t>(u64()); }
  float f32() noexcept { return std::bit_cast<float>(u32()); }
  double f64_from_f32() noexcept { return static_cast<double>(f32()); }
  Vec3 vec3() noexcept {
    Vec3 v;
    for (double& c : v) c = f64_from_f32();
    return v;
  }

 private:
  const std::uint8_t* in_;
  std::size_t at_ = 0;
};

// Part byte of a patch: bits 0–3 tool part, bits 4–5 which quaternion component was
// omitted (the largest in magnitude), bit 6 its sign.
constexpr std::uint8_t kPartMask = 0x0F;
constexpr int kOmittedIndexShift = 4;
constexpr std::uint8_t kOmittedNegativeBit = 0x40;

/// "Smallest three": drop the largest-magnitude component of the (normalised) quaternion
/// and rebuild it from the unit norm. The dropped one is ≥ 0.5 in magnitude, so rebuilding
/// it loses no precision (d/dx √(1−x²) stays ≤ 1·|x|/0.5); its sign travels in the part byte.
/// A zero or non-finite quaternion is sent as NaN so the receiver's validation rejects it.
std::uint8_t write_orientation(ByteWriter& writer, const Quat& q) noexcept {
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!std::isfinite(norm) || norm <= 0.0) {
    for (int i = 0; i < 3; ++i) writer.f32(std::numeric_limits<float>::quiet_NaN());
    return 0;
  }
  std::size_t largest = 0;
  for (std::size_t i = 1; i < 4; ++i) {
    if (std::fabs(q[i]) > std::fabs(q[largest])) largest = i;
  }
  for (std::size_t i = 0; i < 4; ++i) {
    if (i != largest) writer.f32(q[i] / norm);
  }
  std::uint8_t bits = static_cast<std::uint8_t>(largest << kOmittedIndexShift);
  if (q[largest] < 0.0) bits |= kOmittedNegativeBit;
  return bits;
}

Quat read_orientation(ByteReader& reader, std::uint8_t part_byte) noexcept {
  const std::size_t omitted = (part_byte >> kOmittedIndexShift) & 0x3u;
  Quat q{};
  double sum_of_squares = 0.0;
  for (std::size_t i = 0; i < 4; ++i) {
    if (i == omitted) continue;
    q[i] = reader.f64_from_f32();
    sum_of_squares += q[i] * q[i];
  }
  const double magnitude = std::sqrt(std::fmax(0.0, 1.0 - sum_of_squares));  // NaN propagates
  q[omitted] = (part_byte & kOmittedNegativeBit) != 0 ? -magnitude : magnitude;
  return q;
}

void write_crc(std::uint8_t version, MessageType type, std::uint8_t transfer_id, std::uint8_t segment_count,
               std::uint8_t* message, std::size_t message_bytes) noexcept {
  const std::uint8_t prefix[4] = {version, static_cast<std::uint8_t>(type), transfer_id, segment_count};
  std::uint32_t crc = crc32c_update(kCrc32cInit, prefix, sizeof prefix);
  crc = crc32c_finish(crc32c_update(crc, message, message_bytes - kCrcBytes));
  ByteWriter writer(message + message_bytes - kCrcBytes);
  writer.u32(crc);
}

/// Splits a finished message into frames.
void segment(std::uint8_t version, MessageType type, std::uint8_t transfer_id, std::uint8_t* message,
             std::size_t message_bytes, FrameBatch& out) noexcept {
  const std::size_t count = segments_for(message_bytes);
  write_crc(version, type, transfer_id, static_cast<std::uint8_t>(count), message, message_bytes);
  for (std::size_t index = 0; index < count; ++index) {
    CanFdFrame& frame = out.frames[index];
    const std::size_t offset = index * kSegmentBytes;
    const std::size_t chunk = message_bytes - offset < kSegmentBytes ? message_bytes - offset : kSegmentBytes;
    frame.can_id = can_id_for(type);
    frame.flags = kCanFdBitRateSwitch;
    frame.length = static_cast<std::uint8_t>(can_fd_padded_length(kFrameHeaderBytes + chunk));
    frame.data.fill(0);
    frame.data[0] = version;
    frame.data[1] = static_cast<std::uint8_t>(type);
    frame.data[2] = transfer_id;
    frame.data[3] = static_cast<std::uint8_t>(((count - 1) << 4) | index);
    std::memcpy(frame.data.data() + kFrameHeaderBytes, message + offset, chunk);
  }
  out.count = count;
}

}  // namespace

const char* to_string(Role role) noexcept {
  switch (role) {
    case Role::kRt: return "rt";
    case Role::kHost: return "host";
  }
  return "unknown role";
}

const char* to_string(EncodeStatus status) noexcept {
  switch (status) {
    case EncodeStatus::kOk: return "ok";
    case EncodeStatus::kTooManyPatches: return "patch_count exceeds kMaxContactPatches";
    case EncodeStatus::kFlagsNotEncodable: return "proxy flags use bits above 7";
    case EncodeStatus::kBadToolPart: return "tool_part does not fit 4 bits";
  }
  return "unknown encode status";
}

EncodeStatus encode(const DeviceState& state, std::uint8_t transfer_id, FrameBatch& out) noexcept {
  std::array<std::uint8_t, kDeviceStateMessageBytes> message{};
  ByteWriter writer(message.data());
  writer.u64(state.sequence);
  writer.i64(state.sample_time_ns);
  writer.vec3(state.position_device_m);
  writer.vec3(state.velocity_device_m_per_s);
  writer.f32(state.closing_axis_m);
  writer.u32(state.buttons);
  writer.u32(state.status_flags);
  segment(static_cast<std::uint8_t>(kProtocolVersion), MessageType::kDeviceState, transfer_id, message.data(),
          message.size(), out);
  return EncodeStatus::kOk;
}

EncodeStatus encode(const ContactProxy& proxy, std::uint8_t transfer_id, FrameBatch& out) noexcept {
  if (proxy.patch_count > kMaxContactPatches) return EncodeStatus::kTooManyPatches;
  if (proxy.flags > 0xFFu) return EncodeStatus::kFlagsNotEncodable;
  for (std::size_t i = 0; i < proxy.patch_count; ++i) {
    if (static_cast<std::uint32_t>(proxy.patches[i].tool_part) > kPartMask) return EncodeStatus::kBadToolPart;
  }
  std::array<std::uint8_t, kMaxMessageBytes> message{};
  ByteWriter writer(message.data());
  writer.u64(proxy.sequence);
  writer.i64(proxy.host_time_ns);
  writer.u8(static_cast<std::uint8_t>(proxy.patch_count));
  writer.u8(static_cast<std::uint8_t>(proxy.flags));
  for (std::size_t i = 0; i < proxy.patch_count; ++i) {
    const ContactPatch& patch = proxy.patches[i];
    writer.vec3(patch.plane_point_world_m);
    writer.vec3(patch.normal_world);
    writer.f32(patch.stiffness_k);
    writer.f32(patch.damping_lambda);
    writer.f32(patch.exponent_n);
    writer.vec3(patch.reference_tool_position_world_m);
    const std::uint8_t orientation_bits = write_orientation(writer, patch.reference_tool_orientation_world);
    writer.i64(patch.reference_time_ns);
    writer.u8(static_cast<std::uint8_t>(static_cast<std::uint32_t>(patch.tool_part) | orientation_bits));
  }
  for (std::size_t part = 0; part < proxy.friction.size(); ++part) {
    if ((proxy.flags & proxy_friction_bit(static_cast<ToolPart>(part))) == 0u) continue;
    const PartFriction& friction = proxy.friction[part];
    writer.vec3(friction.host_force_world_n);
    writer.vec3(friction.reference_part_position_world_m);
    writer.vec3(friction.surface_velocity_world_m_per_s);
    writer.u16(friction_ratio_to_wire(friction.static_ratio));
    writer.u16(friction_ratio_to_wire(friction.kinetic_ratio));
  }
  const std::size_t message_bytes = writer.size() + kCrcBytes;
  segment(static_cast<std::uint8_t>(kProtocolVersion), MessageType::kContactProxy, transfer_id, message.data(),
          message_bytes, out);
  return EncodeStatus::kOk;
}

EncodeStatus encode(const Hello& hello, std::uint8_t transfer_id, FrameBatch& out) noexcept {
  std::array<std::uint8_t, kHelloMessageBytes> message{};
  ByteWriter writer(message.data());
  writer.u16(hello.protocol_version);
  writer.u8(static_cast<std::uint8_t>(hello.role));
  writer.u8(hello.flags);
  writer.u32(hello.session_id);
  writer.f32(hello.publish_rate_hz);
  if (hello.protocol_version >= kHelloFingerprintVersion) {
    writer.u64(hello.session_fingerprint);
    for (const char c : hello.scene_name) writer.u8(static_cast<std::uint8_t>(c));
  }
  // The Hello carries the full 16-bit version in its body; the header byte is its low byte
  // (informative only: a Hello is decoded whatever the header's version says).
  segment(static_cast<std::uint8_t>(hello.protocol_version), MessageType::kHello, transfer_id, message.data(),
          hello_message_bytes(hello.protocol_version), out);
  return EncodeStatus::kOk;
}

FrameHeader parse_header(const CanFdFrame& frame) noexcept {
  FrameHeader header;
  header.version = frame.data[0];
  header.type = frame.data[1];
  header.transfer_id = frame.data[2];
  header.segment_index = frame.data[3] & 0x0Fu;
  header.segment_count = static_cast<std::uint8_t>((frame.data[3] >> 4) + 1);
  return header;
}

std::size_t max_segments_for(MessageType type) noexcept {
  switch (type) {
    case MessageType::kHello: return segments_for(kHelloMessageBytes);
    case MessageType::kDeviceState: return segments_for(kDeviceStateMessageBytes);
    case MessageType::kContactProxy: return segments_for(kMaxMessageBytes);
    case MessageType::kNone: break;
  }
  return 0;
}

std::size_t message_bytes_for(MessageType type, const std::uint8_t* message, std::size_t available) noexcept {
  switch (type) {
    case MessageType::kHello:
      if (available < 2) return 0;
      return hello_message_bytes(static_cast<std::uint16_t>(message[0] | (message[1] << 8)));
    case MessageType::kDeviceState: return kDeviceStateMessageBytes;
    case MessageType::kContactProxy: {
      constexpr std::size_t kPatchCountOffset = 16;
      constexpr std::size_t kFlagsOffset = 17;
      if (available <= kFlagsOffset) return 0;
      const std::size_t patch_count = message[kPatchCountOffset];
      if (patch_count > kMaxContactPatches) return 0;
      return proxy_message_bytes(patch_count, friction_parts_in(message[kFlagsOffset]));
    }
    case MessageType::kNone: break;
  }
  return 0;
}

bool crc_matches(std::uint8_t version, MessageType type, std::uint8_t transfer_id, std::uint8_t segment_count,
                 const std::uint8_t* message, std::size_t message_bytes) noexcept {
  if (message_bytes < kCrcBytes) return false;
  const std::uint8_t prefix[4] = {version, static_cast<std::uint8_t>(type), transfer_id, segment_count};
  std::uint32_t crc = crc32c_update(kCrc32cInit, prefix, sizeof prefix);
  crc = crc32c_finish(crc32c_update(crc, message, message_bytes - kCrcBytes));
  ByteReader reader(message + message_bytes - kCrcBytes);
  return reader.u32() == crc;
}

void decode_device_state(const std::uint8_t* message, DeviceState& out) noexcept {
  ByteReader reader(message);
  out.sequence = reader.u64();
  out.sample_time_ns = reader.i64();
  out.position_device_m = reader.vec3();
  out.velocity_device_m_per_s = reader.vec3();
  out.closing_axis_m = reader.f64_from_f32();
  out.buttons = reader.u32();
  out.status_flags = reader.u32();
}

void decode_contact_proxy(const std::uint8_t* message, ContactProxy& out) noexcept {
  ByteReader reader(message);
  out.sequence = reader.u64();
  out.host_time_ns = reader.i64();
  out.patch_count = reader.u8();
  out.flags = reader.u8();
  out.protocol_version = kProtocolVersion;  // the frame header's version was checked
  for (std::size_t i = 0; i < kMaxContactPatches; ++i) {
    ContactPatch& patch = out.patches[i];
    if (i >= out.patch_count) {
      patch = ContactPatch{};  // unsent patches read as defaults, never as stale data
      continue;
    }
    patch.plane_point_world_m = reader.vec3();
    patch.normal_world = reader.vec3();
    patch.stiffness_k = reader.f64_from_f32();
    patch.damping_lambda = reader.f64_from_f32();
    patch.exponent_n = reader.f64_from_f32();
    patch.reference_tool_position_world_m = reader.vec3();
    ByteReader orientation_reader = reader;  // the part byte comes after the orientation
    for (int skip = 0; skip < 3; ++skip) (void)reader.f32();
    patch.reference_time_ns = reader.i64();
    const std::uint8_t part_byte = reader.u8();
    patch.reference_tool_orientation_world = read_orientation(orientation_reader, part_byte);
    patch.tool_part = static_cast<ToolPart>(part_byte & kPartMask);
    patch.reserved = 0;
  }
  for (std::size_t part = 0; part < out.friction.size(); ++part) {
    PartFriction& friction = out.friction[part];
    if ((out.flags & proxy_friction_bit(static_cast<ToolPart>(part))) == 0u) {
      friction = PartFriction{};  // absent parts read as defaults, never as stale data
      continue;
    }
    friction.host_force_world_n = reader.vec3();
    friction.reference_part_position_world_m = reader.vec3();
    friction.surface_velocity_world_m_per_s = reader.vec3();
    friction.static_ratio = friction_ratio_from_wire(reader.u16());
    friction.kinetic_ratio = friction_ratio_from_wire(reader.u16());
  }
}

void decode_hello(const std::uint8_t* message, Hello& out) noexcept {
  ByteReader reader(message);
  out.protocol_version = reader.u16();
  out.role = static_cast<Role>(reader.u8());
  out.flags = reader.u8();
  out.session_id = reader.u32();
  out.publish_rate_hz = reader.f32();
  out.session_fingerprint = 0;
  out.scene_name.fill('\0');
  if (out.protocol_version < kHelloFingerprintVersion) return;
  out.session_fingerprint = reader.u64();
  for (char& c : out.scene_name) c = static_cast<char>(reader.u8());
  out.scene_name.back() = '\0';  // a peer's name is printed: always terminated
}

}  // namespace fissure::wire
