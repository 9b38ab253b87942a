#include "fissure/shared/wire_reassembler.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "wire_test_messages.hpp"

namespace fissure::wire {
namespace {

using test::expect_counts_add_up;
using test::expect_wire_equal;
using test::make_device_state;
using test::make_proxy;

FrameBatch encoded(const ContactProxy& proxy, std::uint8_t transfer_id) {
  FrameBatch batch;
  EXPECT_EQ(encode(proxy, transfer_id, batch), EncodeStatus::kOk);
  return batch;
}

FrameBatch encoded(const DeviceState& state, std::uint8_t transfer_id) {
  FrameBatch batch;
  EXPECT_EQ(encode(state, transfer_id, batch), EncodeStatus::kOk);
  return batch;
}

int applied_count(const Reassembler& r) {
  return static_cast<int>(r.stats().proxies_applied + r.stats().device_states_applied);
}

TEST(Reassembler, SegmentsInAnyOrderMakeTheSameMessage) {
  const ContactProxy sent = make_proxy(9, 5);
  const FrameBatch batch = encoded(sent, 0);
  ASSERT_EQ(batch.count, 7u);
  Reassembler r;
  const std::size_t order[] = {6, 0, 3, 5, 1, 4, 2};
  for (std::size_t i = 0; i < batch.count; ++i) {
    const MessageType type = r.push(batch.frames[order[i]], 0);
    EXPECT_EQ(type, i + 1 == batch.count ? MessageType::kContactProxy : MessageType::kNone);
  }
  expect_wire_equal(sent, r.contact_proxy());
  expect_counts_add_up(r);
}

TEST(Reassembler, DuplicateSegmentIsCountedAndTheMessageAppliedOnce) {
  const FrameBatch batch = encoded(make_proxy(1, 3), 0);
  Reassembler r;
  r.push(batch.frames[0], 0);
  r.push(batch.frames[0], 0);  // duplicate while in flight
  for (std::size_t i = 1; i < batch.count; ++i) r.push(batch.frames[i], 0);
  r.push(batch.frames[2], 0);  // late duplicate after completion
  EXPECT_EQ(r.stats().proxies_applied, 1u);
  EXPECT_EQ(r.stats().frames_duplicate_segment, 1u);
  EXPECT_EQ(r.stats().frames_stale, 1u);
  expect_counts_add_up(r);
}

TEST(Reassembler, DuplicateAndReorderedOneFrameMessagesAreCounted) {
  Reassembler r;
  EXPECT_EQ(r.push(encoded(make_device_state(5), 5).frames[0], 0), MessageType::kDeviceState);
  EXPECT_EQ(r.push(encoded(make_device_state(5), 5).frames[0], 0), MessageType::kNone);
  EXPECT_EQ(r.push(encoded(make_device_state(4), 4).frames[0], 0), MessageType::kNone);
  EXPECT_EQ(r.stats().messages_duplicate, 1u);
  EXPECT_EQ(r.stats().messages_out_of_order, 1u);
  EXPECT_EQ(r.device_state().sequence, 5u) << "the newest good sample stays";
  expect_counts_add_up(r);
}

TEST(Reassembler, OlderProxyArrivingAfterANewerOneIsDiscarded) {
  const FrameBatch older = encoded(make_proxy(10, 2), 0);
  const FrameBatch newer = encoded(make_proxy(11, 2), 1);
  Reassembler r;
  // Older one half there, newer one complete, then the rest of the older one.
  r.push(older.frames[0], 0);
  for (std::size_t i = 0; i < newer.count; ++i) r.push(newer.frames[i], 0);
  for (std::size_t i = 1; i < older.count; ++i) EXPECT_EQ(r.push(older.frames[i], 0), MessageType::kNone);
  EXPECT_EQ(r.contact_proxy().sequence, 11u);
  EXPECT_EQ(r.stats().proxies_applied, 1u);
  EXPECT_EQ(r.stats().messages_superseded, 1u);
  EXPECT_EQ(r.stats().frames_stale, older.count - 1);
  EXPECT_EQ(r.pending_assemblies(), 0u);
  expect_counts_add_up(r);
}

TEST(Reassembler, OlderSequenceInANewerTransferIsOutOfOrder) {
  // A proxy that completes later but carries an older sequence number (e.g. the sender
  // reordered): judged by sequence, not by arrival.
  Reassembler r;
  for (const auto& [sequence, transfer] : {std::pair{20u, 0}, std::pair{19u, 1}}) {
    const FrameBatch batch = encoded(make_proxy(sequence, 1), static_cast<std::uint8_t>(transfer));
    for (std::size_t i = 0; i < batch.count; ++i) r.push(batch.frames[i], 0);
  }
  EXPECT_EQ(r.stats().proxies_applied, 1u);
  EXPECT_EQ(r.stats().messages_out_of_order, 1u);
  EXPECT_EQ(r.contact_proxy().sequence, 20u);
  expect_counts_add_up(r);
}

TEST(Reassembler, MissingSegmentMeansNothingIsAppliedAndTheTimeoutCountsIt) {
  const FrameBatch batch = encoded(make_proxy(3, 4), 0);
  Reassembler r(ReassemblerConfig{.assembly_timeout_ns = 50'000'000});
  for (std::size_t i = 0; i + 1 < batch.count; ++i) EXPECT_EQ(r.push(batch.frames[i], 1000), MessageType::kNone);
  EXPECT_EQ(r.pending_assemblies(), 1u);
  r.expire(1000 + 50'000'000);
  EXPECT_EQ(r.pending_assemblies(), 1u) << "not yet past the timeout";
  r.expire(1001 + 50'000'000);
  EXPECT_EQ(r.pending_assemblies(), 0u);
  EXPECT_EQ(r.stats().messages_incomplete, 1u);
  EXPECT_EQ(r.stats().proxies_applied, 0u);
  expect_counts_add_up(r);
}

TEST(Reassembler, AllSlotsBusyEvictsTheOldestAssembly) {
  Reassembler r;
  for (std::uint8_t t = 0; t <= Reassembler::kSlots; ++t) {
    const FrameBatch batch = encoded(make_proxy(100 + t, 3), t);
    r.push(batch.frames[0], 0);  // only the first segment of each
  }
  EXPECT_EQ(r.pending_assemblies(), Reassembler::kSlots);
  EXPECT_EQ(r.stats().messages_incomplete, 1u);
  // The newest one can still complete.
  const FrameBatch last = encoded(make_proxy(100 + Reassembler::kSlots, 3), Reassembler::kSlots);
  for (std::size_t i = 1; i < last.count; ++i) r.push(last.frames[i], 0);
  EXPECT_EQ(r.stats().proxies_applied, 1u);
  EXPECT_EQ(r.stats().messages_superseded, Reassembler::kSlots - 1) << "older ones are superseded by it";
  expect_counts_add_up(r);
}

TEST(Reassembler, CorruptBodyOrCrcFailsTheCrc) {
  Reassembler r;
  for (std::size_t byte : {4u, 30u, 63u}) {  // first body byte, middle, a byte of the last full segment
    FrameBatch batch = encoded(make_proxy(7, 2), static_cast<std::uint8_t>(byte));
    batch.frames[1].data[byte] ^= 0x10;
    for (std::size_t i = 0; i < batch.count; ++i) EXPECT_EQ(r.push(batch.frames[i], 0), MessageType::kNone);
  }
  FrameBatch state = encoded(make_device_state(1), 0);
  state.frames[0].data[56] ^= 0x01;  // inside the stored CRC itself
  EXPECT_EQ(r.push(state.frames[0], 0), MessageType::kNone);
  FrameBatch corrupt_id = encoded(make_device_state(2), 3);
  corrupt_id.frames[0].data[2] ^= 0x04;  // the transfer id is covered too
  EXPECT_EQ(r.push(corrupt_id.frames[0], 0), MessageType::kNone);
  EXPECT_EQ(r.stats().messages_crc_error, 5u);
  EXPECT_EQ(applied_count(r), 0);
  expect_counts_add_up(r);
}

TEST(Reassembler, UnknownTypeWrongVersionShortAndBadSegmentFramesAreCounted) {
  Reassembler r;
  FrameBatch batch = encoded(make_device_state(1), 0);
  CanFdFrame unknown = batch.frames[0];
  unknown.data[1] = 9;
  CanFdFrame wrong_version = batch.frames[0];
  wrong_version.data[0] = static_cast<std::uint8_t>(kProtocolVersion + 1);
  CanFdFrame too_short = batch.frames[0];
  too_short.length = 3;
  CanFdFrame bad_index = batch.frames[0];
  bad_index.data[3] = 0x12;  // index 2 of 2 segments
  CanFdFrame too_many = encoded(make_proxy(1, 1), 0).frames[0];
  too_many.data[3] = 0xF0;   // a proxy never has 16 segments
  for (const CanFdFrame& frame : {unknown, wrong_version, too_short, bad_index, too_many}) {
    EXPECT_EQ(r.push(frame, 0), MessageType::kNone);
  }
  EXPECT_EQ(r.stats().frames_unknown_type, 1u);
  EXPECT_EQ(r.stats().frames_wrong_version, 1u);
  EXPECT_EQ(r.stats().frames_too_short, 1u);
  EXPECT_EQ(r.stats().frames_bad_segment, 2u);
  EXPECT_EQ(r.stats().messages_started, 0u);
  expect_counts_add_up(r);
  EXPECT_EQ(r.push(batch.frames[0], 0), MessageType::kDeviceState) << "the good frame still goes through";
}

TEST(Reassembler, CorruptPatchCountIsMalformedNotMisread) {
  FrameBatch batch = encoded(make_proxy(1, 2), 0);
  batch.frames[0].data[kFrameHeaderBytes + 16] = 1;  // claims 1 patch while 3 segments came
  Reassembler r;
  for (std::size_t i = 0; i < batch.count; ++i) r.push(batch.frames[i], 0);
  batch.frames[0].data[kFrameHeaderBytes + 16] = 200;  // more than kMaxContactPatches
  for (std::size_t i = 0; i < batch.count; ++i) r.push(batch.frames[i], 0);
  EXPECT_EQ(r.stats().messages_malformed, 2u);
  EXPECT_EQ(r.stats().proxies_applied, 0u);
  expect_counts_add_up(r);
}

TEST(Reassembler, InvalidContentIsRejectedWithItsReason) {
  ContactProxy proxy = make_proxy(1, 2);
  proxy.patches[1].stiffness_k = std::numeric_limits<double>::quiet_NaN();
  Reassembler r;
  const FrameBatch batch = encoded(proxy, 0);
  for (std::size_t i = 0; i < batch.count; ++i) EXPECT_EQ(r.push(batch.frames[i], 0), MessageType::kNone);
  EXPECT_EQ(r.stats().messages_invalid, 1u);
  EXPECT_EQ(r.last_invalid_reason(), ProxyError::kNonFinite);
  DeviceState state = make_device_state(1);
  state.velocity_device_m_per_s[2] = std::numeric_limits<double>::infinity();
  EXPECT_EQ(r.push(encoded(state, 0).frames[0], 0), MessageType::kNone);
  EXPECT_EQ(r.stats().messages_invalid, 2u);
  expect_counts_add_up(r);
}

TEST(Reassembler, TransferIdsWrapAroundWithoutLosingMessages) {
  Reassembler r;
  for (std::uint64_t sequence = 1; sequence <= 700; ++sequence) {
    const ContactProxy sent = make_proxy(sequence, static_cast<std::uint16_t>(sequence % 3 + 1));
    const FrameBatch batch = encoded(sent, static_cast<std::uint8_t>(sequence));
    MessageType last = MessageType::kNone;
    for (std::size_t i = 0; i < batch.count; ++i) last = r.push(batch.frames[i], static_cast<TimeNs>(sequence));
    ASSERT_EQ(last, MessageType::kContactProxy) << "sequence " << sequence;
  }
  EXPECT_EQ(r.stats().proxies_applied, 700u);
  expect_counts_add_up(r);
}

TEST(Reassembler, ResetSequencesAcceptsARestartedPeer) {
  Reassembler r;
  EXPECT_EQ(r.push(encoded(make_device_state(500), 0).frames[0], 0), MessageType::kDeviceState);
  EXPECT_EQ(r.push(encoded(make_device_state(1), 0).frames[0], 0), MessageType::kNone) << "looks old";
  r.reset_sequences();
  EXPECT_EQ(r.push(encoded(make_device_state(1), 0).frames[0], 0), MessageType::kDeviceState);
  expect_counts_add_up(r);
}

}  // namespace
}  // namespace fissure::wire
