// Device recordings: SimFalcon recorded through RecordingDevice (the HapticDevice interface the
// USB driver implements too) replays through ReplayDevice with the same readings at the same
// times, and so does the USB driver over the fake Falcon, its file laid out byte for byte as
// docs/session.md documents it; the file round-trips; wrong magic, wrong version, truncation, a bad packet and lost
// records are refused naming the file and the byte offset; the RT side never allocates.
#include <unistd.h>

#include <bit>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "fissure/falcon_hw/device_recording.hpp"
#include "fissure/falcon_hw/fake_falcon_transport.hpp"
#include "fissure/falcon_hw/falcon_usb_driver.hpp"
#include "fissure/falcon_hw/recording_device.hpp"
#include "fissure/falcon_hw/replay_device.hpp"
#include "fissure/falcon_hw/sim_falcon.hpp"
#include "allocation_counter.hpp"

namespace fissure::falcon {
namespace {

using ::testing::HasSubstr;

constexpr TimeNs kTick_ns = 1'000'000;
constexpr int kTicks = 600;

SimFalconConfig pressing_hand() {
  SimFalconConfig config;
  HandScript script;
  script.start_position_device_m = {0.0, 0.0, 0.12};
  script.waypoints = {HandWaypoint{{0.0, -0.02, 0.12}, 0.2, 0.2}, HandWaypoint{{0.01, 0.0, 0.13}, 0.1, 0.0}};
  script.button_events = {ButtonEvent{0.25, 0x1}};
  config.hand = script;
  return config;
}

/// A command that depends on the reading, so a replay that answered differently would also
/// command differently.
DeviceCommand command_for(const DeviceReading& reading) {
  DeviceCommand command;
  for (int arm = 0; arm < 3; ++arm) command.motor_counts[static_cast<std::size_t>(arm)] = static_cast<std::int16_t>(reading.encoder_counts[static_cast<std::size_t>(arm)] / 8);
  return command;
}

struct Exchange {
  IoStatus status;
  DeviceReading reading;
};

std::vector<Exchange> drive(HapticDevice& device, LockstepClock& clock, int ticks, TimeNs tick_ns) {
  std::vector<Exchange> out;
  DeviceReading reading;
  for (int k = 0; k < ticks; ++k) {
    const DeviceCommand command = command_for(reading);
    const IoStatus status = device.try_exchange(command, reading);
    out.push_back({status, reading});
    clock.advance(tick_ns);
  }
  return out;
}

class DeviceRecordingTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("fissure_recording_test_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  /// Records kTicks exchanges of SimFalcon with a disconnect-free hand; returns what it answered.
  std::vector<Exchange> record(const std::filesystem::path& path, SimFalconConfig config = pressing_hand()) {
    LockstepClock clock(0);
    SimFalcon sim(config, clock);
    RecordingDevice recording(sim, clock);
    RecordingHeader header;
    header.rt_rate_hz = 1000.0;
    header.device_name = sim.name();
    header.scene_name = "test-scene";
    RecordingWriter writer(path, header);
    std::vector<Exchange> answered;
    DeviceReading reading;
    for (int k = 0; k < kTicks; ++k) {
      const DeviceCommand command = command_for(reading);
      answered.push_back({recording.try_exchange(command, reading), reading});
      clock.advance(kTick_ns);
      if (k % 50 == 49) recording.drain(writer);  // a host step's worth at a time
    }
    recording.drain(writer);
    writer.finish(recording.records_lost(), recording.recording_time(clock.now()));
    return answered;
  }

  std::vector<std::uint8_t> bytes(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  void write_bytes(const std::filesystem::path& path, const std::vector<std::uint8_t>& data) {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(data.data()), static_cast<std::streamsize>(data.size()));
  }

  std::filesystem::path dir_;
};

TEST_F(DeviceRecordingTest, RecordingDeviceIsTransparent) {
  LockstepClock plain_clock(0);
  SimFalcon plain(pressing_hand(), plain_clock);
  const std::vector<Exchange> unrecorded = drive(plain, plain_clock, kTicks, kTick_ns);
  const std::vector<Exchange> recorded = record(dir_ / "a.frec");
  ASSERT_EQ(recorded.size(), unrecorded.size());
  for (std::size_t i = 0; i < recorded.size(); ++i) {
    EXPECT_EQ(recorded[i].status, unrecorded[i].status);
    EXPECT_EQ(recorded[i].reading.encoder_counts, unrecorded[i].reading.encoder_counts) << "exchange " << i;
    EXPECT_EQ(recorded[i].reading.buttons, unrecorded[i].reading.buttons);
    EXPECT_EQ(recorded[i].reading.receive_time_ns, unrecorded[i].reading.receive_time_ns);
  }
  SimFalcon named(pressing_hand(), plain_clock);
  RecordingDevice wrapper(named, plain_clock);
  EXPECT_STREQ(wrapper.name(), "sim-falcon");  // rt_core sees the device it would see unrecorded
}

TEST_F(DeviceRecordingTest, FileRoundTripsEveryExchange) {
  const std::vector<Exchange> answered = record(dir_ / "a.frec");
  const DeviceRecording recording = read_recording(dir_ / "a.frec");
  EXPECT_EQ(recording.header.version, kRecordingVersion);
  EXPECT_EQ(recording.header.device_name, "sim-falcon");
  EXPECT_EQ(recording.header.scene_name, "test-scene");
  EXPECT_EQ(recording.header.rt_rate_hz, 1000.0);
  EXPECT_EQ(recording.session_end_ns, kTicks * kTick_ns);
  ASSERT_EQ(recording.exchanges.size(), answered.size());
  bool buttons_seen = false;
  for (std::size_t i = 0; i < answered.size(); ++i) {
    const RecordedExchange& x = recording.exchanges[i];
    EXPECT_EQ(x.exchange_time_ns, static_cast<TimeNs>(i) * kTick_ns);
    DeviceReading decoded;
    ASSERT_TRUE(decode_reading(x.reply, decoded));
    EXPECT_EQ(decoded.encoder_counts, answered[i].reading.encoder_counts);
    EXPECT_EQ(decoded.buttons, answered[i].reading.buttons);
    buttons_seen = buttons_seen || decoded.buttons != 0;
  }
  EXPECT_TRUE(buttons_seen);
  // The file is exactly header + records + end record: nothing else is stored.
  const std::size_t header_bytes = 8 + 4 + 8 + 2 + std::string("sim-falcon").size() + 2 + std::string("test-scene").size();
  EXPECT_EQ(bytes(dir_ / "a.frec").size(), header_bytes + kTicks * kExchangeRecordBytes + kEndRecordBytes);
}

TEST_F(DeviceRecordingTest, ReplayAtTheRecordedRateAnswersExactlyAsRecorded) {
  const std::vector<Exchange> answered = record(dir_ / "a.frec");
  const DeviceRecording recording = read_recording(dir_ / "a.frec");
  LockstepClock clock(0);
  ReplayDevice replay(recording, clock);
  EXPECT_STREQ(replay.name(), "replay");
  const std::vector<Exchange> replayed = drive(replay, clock, kTicks, kTick_ns);
  for (std::size_t i = 0; i < answered.size(); ++i) {
    EXPECT_EQ(replayed[i].status, answered[i].status);
    EXPECT_EQ(replayed[i].reading.encoder_counts, answered[i].reading.encoder_counts) << "exchange " << i;
    EXPECT_EQ(replayed[i].reading.buttons, answered[i].reading.buttons);
    EXPECT_EQ(replayed[i].reading.receive_time_ns, answered[i].reading.receive_time_ns);
  }
  EXPECT_EQ(replay.counters().records_used, kTicks);
  // Same readings → same commands: the replayed loop followed the recorded one.
  EXPECT_EQ(replay.counters().commands_differing, 0);
}

TEST_F(DeviceRecordingTest, ReplayAtAnotherRateHoldsTheLatestRecordAndEndsDisconnected) {
  const std::vector<Exchange> answered = record(dir_ / "a.frec");
  const DeviceRecording recording = read_recording(dir_ / "a.frec");
  LockstepClock clock(0);
  ReplayDevice replay(recording, clock);
  constexpr TimeNs kFastTick_ns = 250'000;  // 4 kHz
  const std::vector<Exchange> replayed = drive(replay, clock, 4 * kTicks, kFastTick_ns);
  for (std::size_t k = 0; k < replayed.size(); ++k) {
    EXPECT_EQ(replayed[k].reading.encoder_counts, answered[k / 4].reading.encoder_counts) << "exchange " << k;
  }
  EXPECT_EQ(replay.counters().records_used, kTicks);
  DeviceReading reading;
  clock.advance(ReplayDevice::kHoldAfterEnd_ns + kTick_ns);  // past the last record by more than the hold
  EXPECT_EQ(replay.try_exchange(DeviceCommand{}, reading), IoStatus::kDisconnected);
  EXPECT_EQ(replay.counters().after_end, 1);
}

/// Little-endian integer of sizeof(T) bytes at `offset`, assembled byte by byte (the file's byte
/// order, whatever the host's).
template <typename T>
T little_endian(const std::vector<std::uint8_t>& data, std::size_t offset) {
  std::uint64_t value = 0;
  for (std::size_t i = 0; i < sizeof(T); ++i) value |= static_cast<std::uint64_t>(data.at(offset + i)) << (8 * i);
  return static_cast<T>(value);
}

TEST_F(DeviceRecordingTest, TheUsbDriverIsRecordedAndReplayedWithTheSameReadingsAndTheDocumentedLayout) {
  // The lab's path: FalconUsbDriver in front of the Falcon (here the fake one behind the fake
  // FTDI bridge), wrapped in RecordingDevice, ticking at 1 kHz on a lockstep clock.
  LockstepClock clock(0);
  FakeFalconConfig fake_config;
  fake_config.firmware_running = true;
  fake_config.encoder_counts = {-400, -300, -200};
  FakeFalconTransport fake(clock, fake_config);
  FalconUsbConfig usb_config;
  usb_config.reply_timeout_ns = 800'000;  // a lost reply times out inside its 1 ms tick
  FalconUsbDriver driver(fake, clock, usb_config);
  ASSERT_TRUE(driver.open()) << driver.error();
  ASSERT_TRUE(driver.check_firmware()) << driver.error();
  ASSERT_TRUE(driver.start_running()) << driver.error();
  // The set-up took simulated time; the ticks start on the next whole millisecond.
  const TimeNs start_ns = (clock.now() / kTick_ns + 1) * kTick_ns;
  clock.sleep_until(start_ns);
  const std::filesystem::path path = dir_ / "usb.frec";
  RecordingDevice recording(driver, clock);
  RecordingWriter writer(path, RecordingHeader{kRecordingVersion, 1000.0, recording.name(), "test-scene"});
  fake.script_pull_out_push_in(500, 200);  // the grip moves over the first 400 replies
  const std::size_t commands_before = fake.commands().size();
  std::vector<Exchange> answered;
  DeviceReading reading;
  for (int k = 0; k < kTicks; ++k) {
    clock.sleep_until(start_ns + k * kTick_ns);
    if (k == 100) fake.set_buttons(0x1);
    if (k == 350) fake.set_buttons(0x6);
    // How the bytes arrive is not recorded, only what the driver made of them: torn replies and
    // garbage before a reply read as ordinary ones (a later receive time); lost replies as timeouts.
    if (k == 200) fake.inject_reply_faults(ReplyFault::kTear, 3);
    if (k == 250) fake.inject_reply_faults(ReplyFault::kGarbageBefore, 3);
    if (k == 300) fake.inject_reply_faults(ReplyFault::kDrop, 2);
    const DeviceCommand command = command_for(reading);
    answered.push_back({recording.try_exchange(command, reading), reading});
    if (k % 50 == 49) recording.drain(writer);
  }
  recording.drain(writer);
  writer.finish(recording.records_lost(), recording.recording_time(clock.now()));
  ASSERT_EQ(fake.commands().size(), commands_before + kTicks);

  // What the recorded session saw: motion, both button states, a timeout, a torn reply's later
  // receive time (so the test below compares something in each field).
  int timeouts = 0;
  bool moved = false, buttons_changed = false, receive_offsets_differ = false;
  for (std::size_t k = 0; k < answered.size(); ++k) {
    timeouts += answered[k].status == IoStatus::kTimeout ? 1 : 0;
    moved = moved || answered[k].reading.encoder_counts != answered[0].reading.encoder_counts;
    buttons_changed = buttons_changed || answered[k].reading.buttons != answered[0].reading.buttons;
    const TimeNs begin_ns = start_ns + static_cast<TimeNs>(k) * kTick_ns;
    if (answered[k].status == IoStatus::kOk) {
      receive_offsets_differ = receive_offsets_differ || answered[k].reading.receive_time_ns - begin_ns != fake_config.reply_latency_ns;
    }
  }
  EXPECT_EQ(timeouts, 2);
  EXPECT_TRUE(moved);
  EXPECT_TRUE(buttons_changed);
  EXPECT_TRUE(receive_offsets_differ);

  // The file, read byte by byte against docs/session.md's table ("File format", version 1).
  const std::vector<std::uint8_t> data = bytes(path);
  EXPECT_EQ(std::string(data.begin(), data.begin() + 8), std::string("FISSREC\x1A", 8));
  EXPECT_EQ(little_endian<std::uint32_t>(data, 8), 1u);
  EXPECT_EQ(std::bit_cast<double>(little_endian<std::uint64_t>(data, 12)), 1000.0);
  std::size_t at = 20;
  const auto name_at = [&](const std::string& expected) {
    const std::size_t length = little_endian<std::uint16_t>(data, at);
    EXPECT_EQ(std::string(data.begin() + static_cast<std::ptrdiff_t>(at + 2), data.begin() + static_cast<std::ptrdiff_t>(at + 2 + length)), expected);
    at += 2 + length;
  };
  name_at("usb-falcon");
  name_at("test-scene");
  for (std::size_t k = 0; k < answered.size(); ++k, at += 50) {
    SCOPED_TRACE("exchange record " + std::to_string(k));
    const Exchange& x = answered[k];
    const TimeNs begin_ns = start_ns + static_cast<TimeNs>(k) * kTick_ns;
    const bool ok = x.status == IoStatus::kOk;
    ASSERT_EQ(data.at(at), 'X');
    EXPECT_EQ(little_endian<std::int64_t>(data, at + 1), static_cast<TimeNs>(k) * kTick_ns);  // from the recording's start
    EXPECT_EQ(little_endian<std::int64_t>(data, at + 9), ok ? x.reading.receive_time_ns - begin_ns : 0);
    EXPECT_EQ(data.at(at + 17), ok ? 0 : 1);  // 0 ok, 1 timeout
    FalconPacket reply{}, command{};
    std::copy_n(data.begin() + static_cast<std::ptrdiff_t>(at + 18), 16, reply.begin());
    std::copy_n(data.begin() + static_cast<std::ptrdiff_t>(at + 34), 16, command.begin());
    EXPECT_EQ(reply, ok ? encode_reading(x.reading) : FalconPacket{});  // zeros unless ok
    EXPECT_EQ(command, encode_command(fake.commands()[commands_before + k]));  // the packet the device received
  }
  ASSERT_EQ(data.at(at), 'E');
  EXPECT_EQ(little_endian<std::uint64_t>(data, at + 1), static_cast<std::uint64_t>(kTicks));
  EXPECT_EQ(little_endian<std::uint64_t>(data, at + 9), 0u);  // none lost
  EXPECT_EQ(little_endian<std::int64_t>(data, at + 17), clock.now() - start_ns);
  EXPECT_EQ(data.size(), at + kEndRecordBytes);

  // Replayed in CI: the same statuses, encoder counts, buttons, homed flags and receive times
  // (counted from the replay's start, as the recording counts from its own).
  const DeviceRecording read_back = read_recording(path);
  EXPECT_EQ(read_back.header.device_name, "usb-falcon");
  LockstepClock replay_clock(0);
  ReplayDevice replay(read_back, replay_clock);
  DeviceReading replayed;
  for (std::size_t k = 0; k < answered.size(); ++k) {
    replay_clock.sleep_until(static_cast<TimeNs>(k) * kTick_ns);
    const IoStatus status = replay.try_exchange(command_for(replayed), replayed);
    ASSERT_EQ(status, answered[k].status) << "exchange " << k;
    EXPECT_EQ(replayed.encoder_counts, answered[k].reading.encoder_counts) << "exchange " << k;
    EXPECT_EQ(replayed.buttons, answered[k].reading.buttons) << "exchange " << k;
    EXPECT_EQ(replayed.homed_mask, answered[k].reading.homed_mask) << "exchange " << k;
    EXPECT_EQ(replayed.receive_time_ns, answered[k].reading.receive_time_ns - start_ns) << "exchange " << k;
  }
  EXPECT_EQ(replay.counters().records_used, kTicks);
  EXPECT_EQ(replay.counters().commands_differing, 0);  // the replayed loop sent the recorded commands
}

TEST_F(DeviceRecordingTest, RecordsOfTheSameTimeAreTakenOneExchangeEach) {
  // The lockstep session's last tick and the zero command after the loop stopped share a time.
  DeviceRecording recording;
  for (const TimeNs t : {0, 1'000'000, 1'000'000}) {
    RecordedExchange x;
    x.exchange_time_ns = t;
    DeviceReading r;
    r.encoder_counts = {static_cast<std::int16_t>(recording.exchanges.size()), 0, 0};
    x.reply = encode_reading(r);
    recording.exchanges.push_back(x);
  }
  LockstepClock clock(0);
  ReplayDevice replay(recording, clock);
  DeviceReading reading;
  ASSERT_EQ(replay.try_exchange(DeviceCommand{}, reading), IoStatus::kOk);
  EXPECT_EQ(reading.encoder_counts[0], 0);
  clock.advance(kTick_ns);
  ASSERT_EQ(replay.try_exchange(DeviceCommand{}, reading), IoStatus::kOk);
  EXPECT_EQ(reading.encoder_counts[0], 1);
  ASSERT_EQ(replay.try_exchange(DeviceCommand{}, reading), IoStatus::kOk);
  EXPECT_EQ(reading.encoder_counts[0], 2) << "the second exchange at the same time takes the next record";
  ASSERT_EQ(replay.try_exchange(DeviceCommand{}, reading), IoStatus::kOk);
  EXPECT_EQ(reading.encoder_counts[0], 2) << "then holds it";
}

TEST_F(DeviceRecordingTest, RecordedFaultsReplayAsFaults) {
  SimFalconConfig config = pressing_hand();
  config.faults.dropped_replies = {ExchangeWindow{100, 3}};
  config.faults.torn_packets = {ExchangeWindow{200, 2}};
  record(dir_ / "f.frec", config);
  const DeviceRecording recording = read_recording(dir_ / "f.frec");
  LockstepClock clock(0);
  ReplayDevice replay(recording, clock);
  const std::vector<Exchange> replayed = drive(replay, clock, kTicks, kTick_ns);
  EXPECT_EQ(replayed[101].status, IoStatus::kTimeout);
  EXPECT_EQ(replayed[201].status, IoStatus::kTornPacket);
  EXPECT_EQ(replayed[99].status, IoStatus::kOk);
}

TEST_F(DeviceRecordingTest, TheRtSideNeverAllocates) {
  const DeviceRecording recording = [&] {
    record(dir_ / "a.frec");
    return read_recording(dir_ / "a.frec");
  }();
  LockstepClock clock(0);
  SimFalcon sim(pressing_hand(), clock);
  RecordingDevice recorder(sim, clock);
  ReplayDevice replay(recording, clock);
  DeviceReading reading;
  const long before = testing::allocation_count();
  for (int k = 0; k < 100; ++k) {
    recorder.try_exchange(DeviceCommand{}, reading);
    replay.try_exchange(DeviceCommand{}, reading);
    clock.advance(kTick_ns);
  }
  EXPECT_EQ(testing::allocation_count(), before);
}

TEST_F(DeviceRecordingTest, AFullRingCountsLostRecordsAndTheFileIsRefused) {
  LockstepClock clock(0);
  SimFalcon sim(pressing_hand(), clock);
  RecordingDevice recording(sim, clock);
  RecordingWriter writer(dir_ / "lost.frec", RecordingHeader{kRecordingVersion, 1000.0, "sim-falcon", "s"});
  DeviceReading reading;
  for (std::size_t k = 0; k < RecordingDevice::kRingCapacity + 5; ++k) {
    recording.try_exchange(DeviceCommand{}, reading);
    clock.advance(kTick_ns);
  }
  EXPECT_EQ(recording.records_lost(), 5u);
  recording.drain(writer);
  writer.finish(recording.records_lost(), clock.now());
  EXPECT_THAT([&] { (void)read_recording(dir_ / "lost.frec"); },
              ::testing::ThrowsMessage<RecordingError>(HasSubstr("5 exchanges were lost while recording")));
}

TEST_F(DeviceRecordingTest, RefusesWhatItCannotReplayNamingFileAndOffset) {
  record(dir_ / "a.frec");
  const std::vector<std::uint8_t> good = bytes(dir_ / "a.frec");
  const std::string file = (dir_ / "bad.frec").string();
  auto refused = [&](std::vector<std::uint8_t> data, const std::string& expected) {
    write_bytes(dir_ / "bad.frec", data);
    try {
      (void)read_recording(dir_ / "bad.frec");
      ADD_FAILURE() << "accepted: " << expected;
    } catch (const RecordingError& e) {
      EXPECT_THAT(e.what(), HasSubstr(file)) << expected;
      EXPECT_THAT(e.what(), HasSubstr(expected));
    }
  };
  std::vector<std::uint8_t> data = good;
  data[0] = 'X';
  refused(data, "at byte offset 0: not a fissure device recording");
  data = good;
  data[8] = 2;  // version 2
  refused(data, "at byte offset 8: recording format version 2; this fissure reads version 1 only");
  const std::size_t header_bytes = good.size() - kTicks * kExchangeRecordBytes - kEndRecordBytes;
  // Cut in the middle of record 10.
  data.assign(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(header_bytes + 10 * kExchangeRecordBytes + 7));
  refused(data, "at byte offset " + std::to_string(header_bytes + 10 * kExchangeRecordBytes + 1) +
                    ": truncated: exchange record 10 needs 49 bytes, the file has 6 left");
  // Every record present, the end record missing: the recording never finished.
  data.assign(good.begin(), good.end() - static_cast<std::ptrdiff_t>(kEndRecordBytes));
  refused(data, "truncated: the record tag after 600 exchange records needs 1 bytes, the file has 0 left");
  // A reply packet with a bad end marker.
  data = good;
  const std::size_t record5 = header_bytes + 5 * kExchangeRecordBytes;
  data[record5 + 1 + 8 + 8 + 1 + 15] = 'x';
  refused(data, "at byte offset " + std::to_string(record5) + ": exchange record 5: reply packet invalid");
  data = good;
  data[record5] = 'Q';
  refused(data, "at byte offset " + std::to_string(record5) + ": record tag 0x51 is neither");
  data = good;
  data.push_back(0);
  refused(data, "1 bytes after the end record");
  refused({}, "at byte offset 0: truncated: the magic number needs 8 bytes, the file has 0 left");
  EXPECT_THAT([&] { (void)read_recording(dir_); }, ::testing::ThrowsMessage<RecordingError>(HasSubstr("is a directory")));
}

}  // namespace
}  // namespace fissure::falcon
