#include "fissure/shared/wire_codec.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "fissure/shared/wire_reassembler.hpp"
#include "wire_test_messages.hpp"

namespace fissure::wire {
namespace {

using test::expect_wire_equal;
using test::make_device_state;
using test::make_proxy;

/// Pushes every frame of `batch` through a fresh reassembler; returns what completed last.
MessageType deliver(Reassembler& reassembler, const FrameBatch& batch) {
  MessageType completed = MessageType::kNone;
  for (std::size_t i = 0; i < batch.count; ++i) {
    const MessageType type = reassembler.push(batch.frames[i], 0);
    if (type != MessageType::kNone) completed = type;
  }
  return completed;
}

TEST(WireCodec, DeviceStateIsOneFullFdFrameAndRoundTrips) {
  const DeviceState sent = make_device_state(42);
  FrameBatch batch;
  ASSERT_EQ(encode(sent, 7, batch), EncodeStatus::kOk);
  ASSERT_EQ(batch.count, 1u);
  EXPECT_EQ(batch.frames[0].length, 64);
  EXPECT_EQ(batch.frames[0].can_id, 0x102u);
  EXPECT_EQ(batch.frames[0].flags, kCanFdBitRateSwitch);
  EXPECT_EQ(batch.frames[0].data[0], kProtocolVersion);
  EXPECT_EQ(batch.frames[0].data[1], static_cast<std::uint8_t>(MessageType::kDeviceState));
  EXPECT_EQ(batch.frames[0].data[2], 7);
  EXPECT_EQ(batch.frames[0].data[3], 0x00) << "segment 0 of 1";

  Reassembler reassembler;
  ASSERT_EQ(deliver(reassembler, batch), MessageType::kDeviceState);
  expect_wire_equal(sent, reassembler.device_state());
  // The stated precision: float32 rounding, i.e. ≤ 2⁻²⁴ relative (≤ 4 nm in the Falcon's workspace).
  for (int i = 0; i < 3; ++i) {
    EXPECT_LE(std::fabs(reassembler.device_state().position_device_m[i] - sent.position_device_m[i]),
              std::ldexp(std::fabs(sent.position_device_m[i]), -24));
  }
}

// The position epoch rides in status_flags bits 24..31 (messages.hpp): the codec must carry
// them whole and the reassembler must not take them for anything it rejects, or a host behind a
// link would never see rt_core's discontinuities and would sweep its tool along them.
TEST(WireCodec, DeviceStateCarriesThePositionEpochAndTheFaultBitsBesideIt) {
  for (const std::uint8_t epoch : {std::uint8_t{1}, std::uint8_t{0x80}, std::uint8_t{0xFF}}) {
    DeviceState sent = make_device_state(7 + epoch);
    sent.status_flags = with_position_epoch(kDeviceHomed | kDeviceFaultEncoderJump, epoch);
    FrameBatch batch;
    ASSERT_EQ(encode(sent, 1, batch), EncodeStatus::kOk);
    Reassembler reassembler;
    ASSERT_EQ(deliver(reassembler, batch), MessageType::kDeviceState) << "epoch " << int{epoch};
    const DeviceState& got = reassembler.device_state();
    EXPECT_EQ(position_epoch(got.status_flags), epoch);
    EXPECT_EQ(got.status_flags & kDeviceFaultMask, static_cast<std::uint32_t>(kDeviceFaultEncoderJump));
    EXPECT_NE(got.status_flags & kDeviceHomed, 0u);
  }
}

TEST(WireCodec, PositionEpochHelpersKeepTheOtherBitsAndSkipZeroOnWrap) {
  const std::uint32_t flags = kDeviceHomed | kDeviceSimulated | kDeviceFaultTimeout;
  EXPECT_EQ(position_epoch(flags), 0u);
  const std::uint32_t with = with_position_epoch(flags, 0xA5);
  EXPECT_EQ(position_epoch(with), 0xA5u);
  EXPECT_EQ(with & ~kDevicePositionEpochMask, flags);
  EXPECT_EQ(with_position_epoch(with, 3) & ~kDevicePositionEpochMask, flags);
  EXPECT_EQ(next_position_epoch(0), 1u);
  EXPECT_EQ(next_position_epoch(41), 42u);
  EXPECT_EQ(next_position_epoch(0xFF), 1u) << "0 means no accepted sample: never reached by wrapping";
}

TEST(WireCodec, FullProxyTakesTenFramesAndRoundTrips) {
  const ContactProxy sent = make_proxy(1234, kMaxContactPatches, 0);
  FrameBatch batch;
  ASSERT_EQ(encode(sent, 3, batch), EncodeStatus::kOk);
  ASSERT_EQ(batch.count, 10u);
  for (std::size_t i = 0; i < batch.count; ++i) {
    EXPECT_EQ(batch.frames[i].can_id, 0x103u);
    EXPECT_EQ(batch.frames[i].data[3], static_cast<std::uint8_t>((9u << 4) | i)) << "index/last nibbles";
  }
  Reassembler reassembler;
  ASSERT_EQ(deliver(reassembler, batch), MessageType::kContactProxy);
  expect_wire_equal(sent, reassembler.contact_proxy());
  EXPECT_EQ(validate(reassembler.contact_proxy()), ProxyError::kNone);
}

TEST(WireCodec, FrictionTravelsOnlyForThePartsItsFlagsName) {
  for (int mask = 0; mask < 8; ++mask) {
    ContactProxy sent = make_proxy(500 + static_cast<std::uint64_t>(mask), 2, mask);
    // Garbage in a part without its flag must not travel (and must not come back).
    for (std::size_t part = 0; part < sent.friction.size(); ++part) {
      if ((mask & (1 << part)) == 0) sent.friction[part].static_ratio = 99.0;
    }
    FrameBatch batch;
    ASSERT_EQ(encode(sent, static_cast<std::uint8_t>(mask), batch), EncodeStatus::kOk);
    const std::size_t parts = friction_parts_in(sent.flags);
    EXPECT_EQ(parts, static_cast<std::size_t>(__builtin_popcount(static_cast<unsigned>(mask))));
    EXPECT_EQ(batch.count, segments_for(proxy_message_bytes(2, parts))) << "mask " << mask;
    Reassembler reassembler;
    ASSERT_EQ(deliver(reassembler, batch), MessageType::kContactProxy) << "mask " << mask;
    ContactProxy expected = sent;
    for (std::size_t part = 0; part < sent.friction.size(); ++part) {
      if ((mask & (1 << part)) == 0) expected.friction[part] = PartFriction{};
    }
    expect_wire_equal(expected, reassembler.contact_proxy());
    EXPECT_EQ(validate(reassembler.contact_proxy()), ProxyError::kNone) << "mask " << mask;
  }
  // A clamp's full proxy with both jaws' friction: 654 B, 11 frames.
  const ContactProxy clamp = make_proxy(77, kMaxContactPatches, 0b110);
  FrameBatch batch;
  ASSERT_EQ(encode(clamp, 1, batch), EncodeStatus::kOk);
  EXPECT_EQ(batch.count, 11u);
  Reassembler reassembler;
  ASSERT_EQ(deliver(reassembler, batch), MessageType::kContactProxy);
  expect_wire_equal(clamp, reassembler.contact_proxy());
}

TEST(WireCodec, FrictionRatiosRoundToTenThousandthsKeepingKineticAtMostStatic) {
  EXPECT_EQ(friction_ratio_to_wire(0.0), 0u);
  EXPECT_EQ(friction_ratio_to_wire(2.0), 20000u);
  EXPECT_EQ(friction_ratio_from_wire(20000), 2.0);
  EXPECT_EQ(friction_ratio_from_wire(friction_ratio_to_wire(0.4)), 0.4);
  EXPECT_EQ(friction_ratio_to_wire(-1.0), 0u);
  EXPECT_EQ(friction_ratio_to_wire(std::numeric_limits<double>::quiet_NaN()), 0xFFFFu) << "rejected by validation (> 2)";
  EXPECT_EQ(friction_ratio_to_wire(1e9), 0xFFFFu);
  for (double mu = 0.0; mu < 2.0; mu += 0.00137) {
    EXPECT_LE(friction_ratio_to_wire(mu * 0.999), friction_ratio_to_wire(mu));
    EXPECT_NEAR(friction_ratio_from_wire(friction_ratio_to_wire(mu)), mu, 0.5e-4 + 1e-12);
  }
}

TEST(WireCodec, PartialProxySendsOnlyItsPatches) {
  // Frames per patch count: the table in docs/wire_protocol.md.
  constexpr std::array<std::size_t, 9> kFramesForPatches{1, 2, 3, 4, 5, 7, 8, 9, 10};
  for (std::uint16_t n = 0; n <= kMaxContactPatches; ++n) {
    ContactProxy sent = make_proxy(100 + n, n, 0);
    // Garbage beyond patch_count must not travel (and must not come back).
    for (std::size_t i = n; i < kMaxContactPatches; ++i) sent.patches[i].stiffness_k = 99.0;
    FrameBatch batch;
    ASSERT_EQ(encode(sent, static_cast<std::uint8_t>(n), batch), EncodeStatus::kOk);
    EXPECT_EQ(batch.count, kFramesForPatches[n]) << n << " patches";
    EXPECT_EQ(proxy_message_bytes(n), 22u + 69u * n);
    Reassembler reassembler;
    ASSERT_EQ(deliver(reassembler, batch), MessageType::kContactProxy) << n << " patches";
    ContactProxy expected = sent;
    for (std::size_t i = n; i < kMaxContactPatches; ++i) expected.patches[i] = ContactPatch{};
    expect_wire_equal(expected, reassembler.contact_proxy());
  }
}

TEST(WireCodec, OrientationKeepsItsSignAndIsNormalised) {
  ContactProxy sent = make_proxy(5, 3);
  sent.patches[0].reference_tool_orientation_world = {-0.1, 0.2, -0.9, 0.3};  // largest negative
  sent.patches[1].reference_tool_orientation_world = {1.0, 0.0, 0.0, 0.0};    // identity: exact
  sent.patches[2].reference_tool_orientation_world = {0.0, 0.0, 0.0, 2.0};    // not unit: normalised
  FrameBatch batch;
  ASSERT_EQ(encode(sent, 0, batch), EncodeStatus::kOk);
  Reassembler reassembler;
  ASSERT_EQ(deliver(reassembler, batch), MessageType::kContactProxy);
  const ContactProxy& got = reassembler.contact_proxy();
  const Eigen::Vector4d q0 = Eigen::Vector4d(-0.1, 0.2, -0.9, 0.3).normalized();
  for (int c = 0; c < 4; ++c) EXPECT_NEAR(got.patches[0].reference_tool_orientation_world[c], q0[c], 2e-7);
  EXPECT_EQ(got.patches[1].reference_tool_orientation_world, (Quat{1.0, 0.0, 0.0, 0.0}));
  EXPECT_EQ(got.patches[2].reference_tool_orientation_world, (Quat{0.0, 0.0, 0.0, 1.0}));
}

TEST(WireCodec, OutOfFloatRangeAndNonFiniteValuesArriveAsRejectedMessages) {
  Reassembler reassembler;
  ContactProxy huge = make_proxy(1, 1);
  huge.patches[0].stiffness_k = 1e300;  // beyond float32: must not be undefined behaviour, must be rejected
  FrameBatch batch;
  ASSERT_EQ(encode(huge, 0, batch), EncodeStatus::kOk);
  EXPECT_EQ(deliver(reassembler, batch), MessageType::kNone);
  EXPECT_EQ(reassembler.stats().messages_invalid, 1u);
  EXPECT_EQ(reassembler.last_invalid_reason(), ProxyError::kNonFinite);

  ContactProxy zero_orientation = make_proxy(2, 1);
  zero_orientation.patches[0].reference_tool_orientation_world = {0.0, 0.0, 0.0, 0.0};
  ASSERT_EQ(encode(zero_orientation, 1, batch), EncodeStatus::kOk);
  EXPECT_EQ(deliver(reassembler, batch), MessageType::kNone);
  EXPECT_EQ(reassembler.stats().messages_invalid, 2u);
}

TEST(WireCodec, RefusesWhatTheWireCannotCarry) {
  FrameBatch batch;
  ContactProxy proxy = make_proxy(1, 1);
  proxy.patch_count = kMaxContactPatches + 1;
  EXPECT_EQ(encode(proxy, 0, batch), EncodeStatus::kTooManyPatches);
  proxy = make_proxy(1, 1);
  proxy.flags = 0x100;
  EXPECT_EQ(encode(proxy, 0, batch), EncodeStatus::kFlagsNotEncodable);
  proxy = make_proxy(1, 1);
  proxy.patches[0].tool_part = static_cast<ToolPart>(16);
  EXPECT_EQ(encode(proxy, 0, batch), EncodeStatus::kBadToolPart);
  EXPECT_STREQ(to_string(EncodeStatus::kBadToolPart), "tool_part does not fit 4 bits");
}

TEST(WireCodec, HelloRoundTripsWhateverItsVersion) {
  Hello sent;
  sent.protocol_version = 513;  // a future version: the Hello's prefix is frozen, so it still decodes
  sent.role = Role::kHost;
  sent.flags = kHelloPeerSeen | kHelloClosing;
  sent.session_id = 0xDEADBEEF;
  sent.publish_rate_hz = 250.0f;
  sent.session_fingerprint = 0x0123456789ABCDEFull;
  const std::string name = "clamp-vessel";
  std::copy(name.begin(), name.end(), sent.scene_name.begin());
  FrameBatch batch;
  ASSERT_EQ(encode(sent, 9, batch), EncodeStatus::kOk);
  ASSERT_EQ(batch.count, 1u);
  EXPECT_EQ(batch.frames[0].length, 64);  // 52 B body + 4 B CRC + 4 B header, padded
  Reassembler reassembler;
  ASSERT_EQ(deliver(reassembler, batch), MessageType::kHello);
  const Hello& got = reassembler.hello();
  EXPECT_EQ(got.protocol_version, 513);
  EXPECT_EQ(got.role, Role::kHost);
  EXPECT_EQ(got.flags, kHelloPeerSeen | kHelloClosing);
  EXPECT_EQ(got.session_id, 0xDEADBEEFu);
  EXPECT_EQ(got.publish_rate_hz, 250.0f);
  EXPECT_EQ(got.session_fingerprint, 0x0123456789ABCDEFull);
  EXPECT_STREQ(got.scene_name.data(), "clamp-vessel");
}

TEST(WireCodec, AVersionTwoHelloIsTheFrozenPrefixAndStillDecodes) {
  // A peer of the previous release sends the 12-byte Hello: it decodes, so the handshake can
  // name both versions instead of dropping it as malformed.
  Hello sent;
  sent.protocol_version = 2;
  sent.role = Role::kRt;
  sent.session_id = 77;
  sent.session_fingerprint = 0xFFFF;  // not on the wire before version 3
  FrameBatch batch;
  ASSERT_EQ(encode(sent, 1, batch), EncodeStatus::kOk);
  EXPECT_EQ(batch.frames[0].length, 20);
  Reassembler reassembler;
  ASSERT_EQ(deliver(reassembler, batch), MessageType::kHello);
  EXPECT_EQ(reassembler.hello().protocol_version, 2);
  EXPECT_EQ(reassembler.hello().session_id, 77u);
  EXPECT_EQ(reassembler.hello().session_fingerprint, 0u);
}

TEST(CanFdFrame, PadsToValidDataLengths) {
  EXPECT_EQ(can_fd_padded_length(0), 0u);
  EXPECT_EQ(can_fd_padded_length(8), 8u);
  EXPECT_EQ(can_fd_padded_length(9), 12u);
  EXPECT_EQ(can_fd_padded_length(33), 48u);
  EXPECT_EQ(can_fd_padded_length(49), 64u);
  EXPECT_EQ(can_fd_padded_length(64), 64u);
}

double message_bus_time_us(const FrameBatch& batch, bool worst_case) {
  double total_s = 0.0;
  for (std::size_t i = 0; i < batch.count; ++i) {
    total_s += can_fd_frame_bus_time_s(batch.frames[i].length, CanFdBitRates{}, worst_case);
  }
  return total_s * 1e6;
}

TEST(CanFdBusTime, SixtyFourByteFrameMatchesTheBriefsRange) {
  // BRIEF §8: "A 64-byte FD frame at 1/5 Mbit/s takes ~140–170 µs on the wire".
  EXPECT_NEAR(can_fd_frame_bus_time_s(64, CanFdBitRates{}, false) * 1e6, 139.6, 0.05);
  EXPECT_NEAR(can_fd_frame_bus_time_s(64, CanFdBitRates{}, true) * 1e6, 169.4, 0.05);
  // Classic-rate sanity: an 8-byte frame without BRS speedup is slower per byte.
  EXPECT_GT(can_fd_frame_bus_time_s(8, CanFdBitRates{1e6, 1e6}, false), can_fd_frame_bus_time_s(8, CanFdBitRates{}, false));
}

TEST(CanFdBusTime, PerMessageFiguresOfTheProtocolDocument) {
  // These are the numbers in docs/wire_protocol.md; this test keeps the two in step.
  struct Row {
    std::uint16_t patches;
    double best_us;
    double worst_us;
  };
  constexpr std::array<Row, 9> kRows{{{0, 88.4, 105.4},
                                      {1, 253.6, 306.8},
                                      {2, 393.2, 476.2},
                                      {3, 558.4, 677.6},
                                      {4, 698.0, 847.0},
                                      {5, 893.0, 1080.8},
                                      {6, 1046.4, 1267.2},
                                      {7, 1205.2, 1460.6},
                                      {8, 1370.4, 1662.0}}};
  FrameBatch batch;
  for (const Row& row : kRows) {
    ASSERT_EQ(encode(make_proxy(1, row.patches, 0), 0, batch), EncodeStatus::kOk);
    EXPECT_NEAR(message_bus_time_us(batch, false), row.best_us, 0.05) << row.patches << " patches";
    EXPECT_NEAR(message_bus_time_us(batch, true), row.worst_us, 0.05) << row.patches << " patches";
  }
  // With friction: the spatula's two patches and its one part; a clamp's full proxy, both jaws.
  struct FrictionRow {
    std::uint16_t patches;
    int friction_mask;
    std::size_t bytes;
    double best_us;
    double worst_us;
  };
  constexpr std::array<FrictionRow, 2> kFrictionRows{{{2, 0b001, 200, 494.4, 597.6}, {8, 0b110, 654, 1535.6, 1863.4}}};
  for (const FrictionRow& row : kFrictionRows) {
    ASSERT_EQ(encode(make_proxy(1, row.patches, row.friction_mask), 0, batch), EncodeStatus::kOk);
    EXPECT_EQ(proxy_message_bytes(row.patches, friction_parts_in(make_proxy(1, row.patches, row.friction_mask).flags)), row.bytes);
    EXPECT_NEAR(message_bus_time_us(batch, false), row.best_us, 0.05) << row.patches << " patches, friction " << row.friction_mask;
    EXPECT_NEAR(message_bus_time_us(batch, true), row.worst_us, 0.05) << row.patches << " patches, friction " << row.friction_mask;
  }
  // The clamp's full proxy stays within CRC-32C's Hamming distance 6 (≤ 5243 bits, wire_codec.hpp).
  EXPECT_LE(8 * proxy_message_bytes(kMaxContactPatches, 2), 5243u);
  ASSERT_EQ(encode(make_device_state(1), 0, batch), EncodeStatus::kOk);
  EXPECT_NEAR(message_bus_time_us(batch, false), 139.6, 0.05);
  EXPECT_NEAR(message_bus_time_us(batch, true), 169.4, 0.05);
  ASSERT_EQ(encode(Hello{}, 0, batch), EncodeStatus::kOk);
  EXPECT_NEAR(message_bus_time_us(batch, false), 139.6, 0.05);
  EXPECT_NEAR(message_bus_time_us(batch, true), 169.4, 0.05);
}

}  // namespace
}  // namespace fissure::wire
