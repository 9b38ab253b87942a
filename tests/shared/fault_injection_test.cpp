// The fault-injecting carrier itself, and the codec + reassembly + link over it: at 1 %, 10 %
// and 50 % loss / reorder / corruption / duplication / delay, over ≥ 10⁴ proxies, every applied
// proxy equals one that was sent (never a mix of two) and every frame and message is counted.
#include "fissure/shared/fault_injecting_carrier.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdio>
#include <string>
#include <vector>

#include "fissure/shared/loopback_carrier.hpp"
#include "fissure/shared/wire_link.hpp"
#include "wire_test_messages.hpp"

namespace fissure::transport {
namespace {

CanFdFrame numbered_frame(std::uint32_t n) {
  CanFdFrame frame;
  frame.can_id = 0x103;
  frame.length = 64;
  for (std::size_t i = 0; i < frame.data.size(); ++i) frame.data[i] = static_cast<std::uint8_t>(n + i);
  frame.data[0] = static_cast<std::uint8_t>(n);
  frame.data[1] = static_cast<std::uint8_t>(n >> 8);
  return frame;
}

std::uint32_t number_of(const CanFdFrame& frame) { return frame.data[0] | (static_cast<std::uint32_t>(frame.data[1]) << 8); }

/// Sends `count` numbered frames through a faulty receive path; returns what came out, in order.
std::vector<CanFdFrame> run(const FaultConfig& config, int count, FaultCounts* counts = nullptr) {
  LockstepClock clock;
  LoopbackLink link(clock);
  FaultInjectingCarrier faulty(link.b(), clock, config);
  std::vector<CanFdFrame> out;
  for (int n = 0; n < count; ++n) {
    EXPECT_EQ(link.a().try_send(numbered_frame(static_cast<std::uint32_t>(n))), CarrierStatus::kOk);
    ReceivedFrame received;
    while (faulty.try_receive(received) == CarrierStatus::kOk) out.push_back(received.frame);
    clock.advance(100'000);
  }
  clock.advance(config.max_delay_ns + 1);
  faulty.release_all();
  ReceivedFrame received;
  while (faulty.try_receive(received) == CarrierStatus::kOk) out.push_back(received.frame);
  EXPECT_EQ(faulty.held_frames(), 0u);
  if (counts != nullptr) *counts = faulty.counts();
  return out;
}

TEST(FaultInjectingCarrier, NoFaultsIsATransparentPipe) {
  const std::vector<CanFdFrame> out = run(FaultConfig{}, 200);
  ASSERT_EQ(out.size(), 200u);
  for (std::uint32_t n = 0; n < 200; ++n) EXPECT_EQ(number_of(out[n]), n);
}

TEST(FaultInjectingCarrier, SameSeedSameDamageOtherSeedOtherDamage) {
  FaultConfig config{.drop_probability = 0.1, .duplicate_probability = 0.1, .reorder_probability = 0.1,
                     .corrupt_probability = 0.1, .delay_probability = 0.1, .seed = 77};
  const std::vector<CanFdFrame> first = run(config, 500);
  const std::vector<CanFdFrame> second = run(config, 500);
  ASSERT_EQ(first.size(), second.size());
  for (std::size_t i = 0; i < first.size(); ++i) EXPECT_EQ(first[i].data, second[i].data) << i;
  config.seed = 78;
  const std::vector<CanFdFrame> other = run(config, 500);
  bool differs = other.size() != first.size();
  for (std::size_t i = 0; !differs && i < first.size(); ++i) differs = other[i].data != first[i].data;
  EXPECT_TRUE(differs);
}

TEST(FaultInjectingCarrier, EachFaultDoesWhatItSays) {
  FaultCounts counts;
  EXPECT_TRUE(run(FaultConfig{.drop_probability = 1.0}, 50, &counts).empty());
  EXPECT_EQ(counts.dropped, 50u);

  std::vector<CanFdFrame> out = run(FaultConfig{.duplicate_probability = 1.0}, 50, &counts);
  ASSERT_EQ(out.size(), 100u);
  for (std::uint32_t n = 0; n < 50; ++n) {
    EXPECT_EQ(number_of(out[2 * n]), n);
    EXPECT_EQ(number_of(out[2 * n + 1]), n) << "the copy follows the original";
  }

  out = run(FaultConfig{.corrupt_probability = 1.0, .max_bit_flips = 3}, 50, &counts);
  ASSERT_EQ(out.size(), 50u);
  for (std::uint32_t n = 0; n < 50; ++n) {
    const CanFdFrame original = numbered_frame(n);
    int flipped_bits = 0;
    for (std::size_t i = 0; i < original.data.size(); ++i) flipped_bits += std::popcount(static_cast<unsigned>(original.data[i] ^ out[n].data[i]));
    EXPECT_GE(flipped_bits, 1);
    EXPECT_LE(flipped_bits, 3);
  }

  out = run(FaultConfig{.reorder_probability = 0.5, .max_reorder_depth = 3}, 400, &counts);
  ASSERT_EQ(out.size(), 400u) << "reordering loses nothing";
  int inversions = 0;
  for (std::size_t i = 1; i < out.size(); ++i) inversions += number_of(out[i]) < number_of(out[i - 1]) ? 1 : 0;
  EXPECT_GT(inversions, 50);
  EXPECT_GT(counts.reordered, 100u);
}

TEST(FaultInjectingCarrier, DelayedFramesWaitForTheClock) {
  LockstepClock clock;
  LoopbackLink link(clock);
  FaultInjectingCarrier faulty(link.b(), clock, FaultConfig{.delay_probability = 1.0, .max_delay_ns = 1'000'000});
  ASSERT_EQ(link.a().try_send(numbered_frame(1)), CarrierStatus::kOk);
  ReceivedFrame received;
  EXPECT_EQ(faulty.try_receive(received), CarrierStatus::kEmpty);
  EXPECT_EQ(faulty.held_frames(), 1u);
  clock.advance(1'000'001);
  ASSERT_EQ(faulty.try_receive(received), CarrierStatus::kOk);
  EXPECT_EQ(number_of(received.frame), 1u);
  EXPECT_EQ(faulty.counts().delayed, 1u);
}

// ---- the codec over a damaged link ------------------------------------------------------

struct Scenario {
  const char* name;
  FaultConfig faults;
};

std::string scenario_name(const testing::TestParamInfo<Scenario>& info) { return info.param.name; }

class WireOverFaultyLink : public testing::TestWithParam<Scenario> {};

TEST_P(WireOverFaultyLink, AppliedProxiesAreExactlyOnesThatWereSentAndCountsAddUp) {
  constexpr std::uint64_t kMessages = 10'000;
  const Scenario& scenario = GetParam();
  LockstepClock clock;
  LoopbackLink link(clock);
  FaultInjectingCarrier faulty(link.b(), clock, scenario.faults);
  LinkSender sender(link.a());
  // One frame per poll, so every message that completes is seen here (poll() otherwise keeps
  // only the newest of several completing in one call, which is right for the rt tick).
  LinkReceiver receiver(faulty, clock, nullptr, LinkReceiverConfig{.max_frames_per_poll = 1});

  std::vector<ContactProxy> sent;  // index = sequence − 1
  sent.reserve(kMessages);
  std::uint64_t applied = 0;
  std::uint64_t last_applied_sequence = 0;
  const auto check_new = [&] {
    ContactProxy got;
    if (!receiver.try_take_proxy(got)) return;
    ASSERT_GE(got.sequence, 1u);
    ASSERT_LE(got.sequence, sent.size());
    ASSERT_GT(got.sequence, last_applied_sequence) << "applied proxies only move forward";
    test::expect_wire_equal(sent[got.sequence - 1], got);
    last_applied_sequence = got.sequence;
    ++applied;
  };
  for (std::uint64_t sequence = 1; sequence <= kMessages; ++sequence) {
    sent.push_back(test::make_proxy(sequence, static_cast<std::uint16_t>(sequence % (kMaxContactPatches + 1))));
    ASSERT_EQ(sender.publish(sent.back()), wire::EncodeStatus::kOk);
    sender.service();
    ASSERT_TRUE(sender.idle()) << "the loopback never pushes back at this rate";
    clock.advance(1'000'000);  // a 1 kHz host
    while (receiver.poll().frames > 0) check_new();
  }
  clock.advance(scenario.faults.max_delay_ns + 1);
  faulty.release_all();
  while (receiver.poll().frames > 0) check_new();
  clock.advance(1'000'000'000);  // past the assembly timeout: what is still pending is incomplete
  receiver.poll();

  const wire::WireStats& stats = receiver.wire_stats();
  const FaultCounts& faults = faulty.counts();
  test::expect_counts_add_up(receiver.reassembler());
  EXPECT_EQ(stats.frames_received, faults.frames_delivered) << "every delivered frame reached the reassembler";
  EXPECT_EQ(faults.frames_in, sender.stats().frames_sent) << "nothing lost inside the loopback";
  EXPECT_EQ(stats.proxies_applied, applied);
  EXPECT_EQ(receiver.reassembler().pending_assemblies(), 0u);
  // Every sent message is either applied or accounted for as not applied; nothing was applied twice.
  EXPECT_LE(applied, kMessages);
  RecordProperty("applied", static_cast<int>(applied));
  std::printf("%-22s applied %5llu/%llu  frames in %6llu delivered %6llu | crc %llu malformed %llu invalid %llu "
              "dup %llu ooo %llu incomplete %llu superseded %llu | dup-seg %llu stale %llu bad-seg %llu "
              "wrong-ver %llu unknown %llu\n",
              scenario.name, static_cast<unsigned long long>(applied), static_cast<unsigned long long>(kMessages),
              static_cast<unsigned long long>(faults.frames_in), static_cast<unsigned long long>(faults.frames_delivered),
              static_cast<unsigned long long>(stats.messages_crc_error), static_cast<unsigned long long>(stats.messages_malformed),
              static_cast<unsigned long long>(stats.messages_invalid), static_cast<unsigned long long>(stats.messages_duplicate),
              static_cast<unsigned long long>(stats.messages_out_of_order), static_cast<unsigned long long>(stats.messages_incomplete),
              static_cast<unsigned long long>(stats.messages_superseded), static_cast<unsigned long long>(stats.frames_duplicate_segment),
              static_cast<unsigned long long>(stats.frames_stale), static_cast<unsigned long long>(stats.frames_bad_segment),
              static_cast<unsigned long long>(stats.frames_wrong_version), static_cast<unsigned long long>(stats.frames_unknown_type));

  const FaultConfig& f = scenario.faults;
  const bool destructive = f.drop_probability > 0.0 || f.corrupt_probability > 0.0;
  if (!destructive) {
    // Reordering, duplication and delay alone never destroy a message (nothing fails a CRC or
    // misses a segment for good); a proxy overtaken by a newer one is superseded: newest wins.
    EXPECT_EQ(stats.messages_crc_error + stats.messages_malformed + stats.messages_invalid + stats.messages_incomplete, 0u);
    if (f.reorder_probability == 0.0 && f.delay_probability == 0.0) {
      EXPECT_EQ(applied, kMessages) << "duplicates alone lose nothing";
    }
  }
  if (f.duplicate_probability > 0.0) {
    EXPECT_GT(stats.frames_duplicate_segment + stats.frames_stale + stats.messages_duplicate, 0u);
  }
  if (f.corrupt_probability > 0.0) {
    EXPECT_GT(faults.corrupted, 0u);
    EXPECT_GT(stats.messages_crc_error, 0u);
  }
  if (f.drop_probability > 0.0) {
    EXPECT_GT(stats.messages_incomplete + stats.messages_superseded, 0u);
  }
  if (f.reorder_probability > 0.0 || f.delay_probability > 0.0) {
    EXPECT_GT(stats.messages_superseded + stats.frames_stale + stats.messages_out_of_order, 0u);
  }
  // At 1 % frame damage a proxy (5.4 frames on average) gets through ~95 % of the time.
  if (std::max(f.drop_probability, f.corrupt_probability) <= 0.01 && f.reorder_probability == 0.0 &&
      f.delay_probability == 0.0) {
    EXPECT_GT(applied, kMessages * 90 / 100);
  }
  EXPECT_GT(applied, 0u);
}

constexpr FaultConfig faults(double drop, double duplicate, double reorder, double corrupt, double delay, std::uint64_t seed) {
  FaultConfig config;
  config.drop_probability = drop;
  config.duplicate_probability = duplicate;
  config.reorder_probability = reorder;
  config.corrupt_probability = corrupt;
  config.delay_probability = delay;
  config.seed = seed;
  return config;
}

INSTANTIATE_TEST_SUITE_P(
    LossReorderCorruption, WireOverFaultyLink,
    testing::Values(Scenario{"clean", faults(0, 0, 0, 0, 0, 1)},
                    Scenario{"drop_1pct", faults(0.01, 0, 0, 0, 0, 2)},
                    Scenario{"drop_10pct", faults(0.10, 0, 0, 0, 0, 3)},
                    Scenario{"drop_50pct", faults(0.50, 0, 0, 0, 0, 4)},
                    Scenario{"reorder_1pct", faults(0, 0, 0.01, 0, 0, 5)},
                    Scenario{"reorder_10pct", faults(0, 0, 0.10, 0, 0, 6)},
                    Scenario{"reorder_50pct", faults(0, 0, 0.50, 0, 0, 7)},
                    Scenario{"corrupt_1pct", faults(0, 0, 0, 0.01, 0, 8)},
                    Scenario{"corrupt_10pct", faults(0, 0, 0, 0.10, 0, 9)},
                    Scenario{"corrupt_50pct", faults(0, 0, 0, 0.50, 0, 10)},
                    Scenario{"duplicate_10pct", faults(0, 0.10, 0, 0, 0, 11)},
                    Scenario{"duplicate_50pct", faults(0, 0.50, 0, 0, 0, 12)},
                    Scenario{"delay_10pct", faults(0, 0, 0, 0, 0.10, 13)},
                    Scenario{"everything_1pct", faults(0.01, 0.01, 0.01, 0.01, 0.01, 14)},
                    Scenario{"everything_10pct", faults(0.10, 0.10, 0.10, 0.10, 0.10, 15)},
                    Scenario{"everything_50pct", faults(0.50, 0.50, 0.50, 0.50, 0.50, 16)}),
    scenario_name);

}  // namespace
}  // namespace fissure::transport
