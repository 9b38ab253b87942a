#include "fissure/falcon_hw/falcon_usb_driver.hpp"

#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fissure/falcon_hw/fake_falcon_transport.hpp"

// Counts heap allocations while `g_count_allocations` is set, to check that try_exchange
// allocates nothing (the RT-path rule).
namespace {
std::atomic<bool> g_count_allocations{false};
std::atomic<std::uint64_t> g_allocations{0};
}  // namespace

// GCC inlines these into callers and then flags malloc/free as mismatched with new/delete;
// they are matched (every new here is malloc, every delete free).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif
// GCC 12 at -O1 (the sanitizer presets) inlines these replacements into their callers and then
// reports free() on memory from "operator new" as -Wmismatched-new-delete: a false positive for
// a replaced global operator new that itself allocates with malloc.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t size) {
  if (g_count_allocations.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

namespace fissure::falcon {
namespace {

// A generated stand-in for the firmware: we never ship (or need) Novint's real image.
std::vector<std::uint8_t> fake_firmware_blob(std::size_t size = 10'000) {
  std::mt19937 rng(20240601);
  std::vector<std::uint8_t> blob(size);
  for (auto& b : blob) b = static_cast<std::uint8_t>(rng());
  return blob;
}

class FalconUsbDriverTest : public ::testing::Test {
 protected:
  explicit FalconUsbDriverTest(bool firmware_running = true) : fake_(clock_, make_config(firmware_running)), driver_(fake_, clock_) {}

  static FakeFalconConfig make_config(bool firmware_running) {
    FakeFalconConfig config;
    config.firmware_image = fake_firmware_blob();
    config.firmware_running = firmware_running;
    config.encoder_counts = {-400, -400, -400};
    config.index_counts = {-300, 0, 300};  // the arms pass their index at different times
    return config;
  }

  void open_and_run() {
    ASSERT_TRUE(driver_.open()) << driver_.error();
    ASSERT_TRUE(driver_.check_firmware()) << driver_.error();
    ASSERT_TRUE(driver_.start_running()) << driver_.error();
  }

  LockstepClock clock_{0};
  FakeFalconTransport fake_;
  FalconUsbDriver driver_;
};

class FalconUsbDriverNoFirmwareTest : public FalconUsbDriverTest {
 protected:
  FalconUsbDriverNoFirmwareTest() : FalconUsbDriverTest(false) {}
};

bool contains(const char* text, const std::string& part) { return std::string(text).find(part) != std::string::npos; }

// ---------------------------------------------------------------- open / firmware

TEST_F(FalconUsbDriverTest, OpenSetsUpTheFtdiChipForNormalMode) {
  EXPECT_EQ(driver_.state(), DriverState::kClosed);
  EXPECT_STREQ(driver_.name(), "usb-falcon");
  ASSERT_TRUE(driver_.open()) << driver_.error();
  EXPECT_EQ(driver_.state(), DriverState::kOpened);
  EXPECT_EQ(fake_.latency_timer_ms(), 1);
  EXPECT_EQ(fake_.baud_divisor(), 0x2);
  EXPECT_TRUE(fake_.line_configured());
  EXPECT_GE(fake_.receive_purges(), 1);
  EXPECT_FALSE(driver_.open());  // not from kOpened
  EXPECT_TRUE(contains(driver_.error(), "needs state closed"));
}

TEST_F(FalconUsbDriverTest, FirmwareCheckFindsRunningFirmware) {
  ASSERT_TRUE(driver_.open());
  EXPECT_TRUE(driver_.check_firmware()) << driver_.error();
  EXPECT_TRUE(driver_.firmware_loaded());
  EXPECT_EQ(driver_.state(), DriverState::kOpened);
}

TEST_F(FalconUsbDriverNoFirmwareTest, FirmwareCheckReportsMissingFirmwareWithoutHanging) {
  ASSERT_TRUE(driver_.open());
  EXPECT_FALSE(driver_.check_firmware());
  EXPECT_FALSE(driver_.firmware_loaded());
  EXPECT_EQ(driver_.state(), DriverState::kOpened);  // not a fault: upload is the remedy
  EXPECT_TRUE(contains(driver_.error(), "firmware not loaded")) << driver_.error();
  // Waited its configured attempts × deadline of simulated time, no more.
  const FalconUsbConfig& c = driver_.config();
  EXPECT_LE(clock_.now(), c.firmware_check_attempts * (c.firmware_check_timeout_ns + c.write_timeout_ns));
  EXPECT_FALSE(driver_.start_running());
  EXPECT_FALSE(driver_.home());
}

TEST_F(FalconUsbDriverNoFirmwareTest, FirmwareUploadSucceeds) {
  const std::vector<std::uint8_t> image = fake_firmware_blob();
  ASSERT_TRUE(driver_.open());
  ASSERT_FALSE(driver_.check_firmware());
  ASSERT_TRUE(driver_.upload_firmware(image)) << driver_.error();
  EXPECT_TRUE(fake_.firmware_running());
  EXPECT_TRUE(driver_.firmware_loaded());
  EXPECT_EQ(driver_.state(), DriverState::kOpened);
  EXPECT_EQ(fake_.handshakes_answered(), 1);
  EXPECT_EQ(fake_.uploads_started(), 1);
  EXPECT_EQ(fake_.firmware_bytes_received(), image.size());
  // Back in normal mode afterwards.
  EXPECT_EQ(fake_.latency_timer_ms(), 1);
  EXPECT_EQ(fake_.baud_divisor(), 0x2);
}

TEST_F(FalconUsbDriverNoFirmwareTest, EchoFailureIsRetriedThenSucceeds) {
  fake_.fail_echo(5'000, 1);  // the first upload gets one wrong echo byte
  ASSERT_TRUE(driver_.open());
  ASSERT_TRUE(driver_.upload_firmware(fake_firmware_blob())) << driver_.error();
  EXPECT_EQ(fake_.uploads_started(), 2);
  EXPECT_TRUE(fake_.firmware_running());
  EXPECT_TRUE(driver_.firmware_loaded());
}

TEST_F(FalconUsbDriverNoFirmwareTest, PersistentEchoFailureFaultsWithAClearError) {
  fake_.fail_echo(100, 1000);
  ASSERT_TRUE(driver_.open());
  EXPECT_FALSE(driver_.upload_firmware(fake_firmware_blob()));
  EXPECT_EQ(driver_.state(), DriverState::kFault);
  EXPECT_EQ(fake_.uploads_started(), driver_.config().firmware_upload_attempts);
  EXPECT_TRUE(contains(driver_.error(), "firmware upload failed after 3 attempts")) << driver_.error();
  EXPECT_TRUE(contains(driver_.error(), "echo mismatch at byte 100 of 10000")) << driver_.error();
  EXPECT_FALSE(fake_.firmware_running());
  DeviceReading reading;
  EXPECT_EQ(driver_.try_exchange(DeviceCommand{}, reading), IoStatus::kNotRunning);
}

TEST_F(FalconUsbDriverNoFirmwareTest, UnansweredHandshakesAreRetried) {
  fake_.drop_handshake_replies(3);
  ASSERT_TRUE(driver_.open());
  ASSERT_TRUE(driver_.upload_firmware(fake_firmware_blob())) << driver_.error();
  EXPECT_EQ(fake_.handshakes_answered(), 1);
  EXPECT_TRUE(fake_.firmware_running());
}

TEST_F(FalconUsbDriverNoFirmwareTest, SilentBootloaderFaultsAfterBoundedWaiting) {
  fake_.drop_handshake_replies(1'000'000);
  ASSERT_TRUE(driver_.open());
  EXPECT_FALSE(driver_.upload_firmware(fake_firmware_blob()));
  EXPECT_EQ(driver_.state(), DriverState::kFault);
  EXPECT_TRUE(contains(driver_.error(), "no firmware handshake answer")) << driver_.error();
  const FalconUsbConfig& c = driver_.config();
  EXPECT_LE(clock_.now(), c.firmware_upload_attempts * c.handshake_attempts * c.handshake_timeout_ns);
}

TEST_F(FalconUsbDriverNoFirmwareTest, UnplugDuringUploadFaultsAsDisconnected) {
  ASSERT_TRUE(driver_.open());
  fake_.disconnect_after_writes(20);
  EXPECT_FALSE(driver_.upload_firmware(fake_firmware_blob()));
  EXPECT_EQ(driver_.state(), DriverState::kFault);
  EXPECT_TRUE(contains(driver_.error(), "disconnected")) << driver_.error();
  DeviceReading reading;
  EXPECT_EQ(driver_.try_exchange(DeviceCommand{}, reading), IoStatus::kDisconnected);
}

TEST_F(FalconUsbDriverNoFirmwareTest, RejectsEmptyImageAndWrongState) {
  EXPECT_FALSE(driver_.upload_firmware(fake_firmware_blob()));  // still closed
  EXPECT_TRUE(contains(driver_.error(), "needs state opened"));
  ASSERT_TRUE(driver_.open());
  EXPECT_FALSE(driver_.upload_firmware({}));
  EXPECT_TRUE(contains(driver_.error(), "empty"));
  EXPECT_EQ(driver_.state(), DriverState::kOpened);
}

// ---------------------------------------------------------------- homing

TEST_F(FalconUsbDriverTest, HomingSetsTheHomedFlagsWithLedFeedback) {
  ASSERT_TRUE(driver_.open());
  ASSERT_TRUE(driver_.check_firmware());
  const std::size_t commands_before = fake_.commands().size();
  fake_.script_pull_out_push_in(800, 200);  // -400 → +400 → -400 counts: passes every index
  std::vector<std::uint8_t> progress;
  ASSERT_TRUE(driver_.home([&](std::uint8_t mask) { progress.push_back(mask); })) << driver_.error();
  EXPECT_EQ(driver_.state(), DriverState::kRunning);
  EXPECT_EQ(driver_.homed_mask(), kHomedMaskAllArms);
  EXPECT_EQ(fake_.homed_mask(), kHomedMaskAllArms);
  EXPECT_EQ(progress, (std::vector<std::uint8_t>{0x0, 0x1, 0x3, 0x7}));

  // What the device saw: homing mode on, red until the first arm homed, then blue;
  // finally homing off with the green LED.
  const std::vector<DeviceCommand>& seen = fake_.commands();
  ASSERT_GT(seen.size(), commands_before + 2);
  bool saw_red = false;
  bool saw_blue = false;
  for (std::size_t i = commands_before; i + 1 < seen.size(); ++i) {
    EXPECT_TRUE(seen[i].homing_mode) << i;
    EXPECT_EQ(seen[i].motor_counts, (std::array<std::int16_t, 3>{0, 0, 0}));
    EXPECT_TRUE(seen[i].leds == kLedHomingNone || seen[i].leds == kLedHomingPartial) << int(seen[i].leds);
    if (seen[i].leds == kLedHomingPartial) saw_blue = true;
    if (seen[i].leds == kLedHomingNone) {
      EXPECT_FALSE(saw_blue) << "red after blue";
      saw_red = true;
    }
  }
  EXPECT_TRUE(saw_red);
  EXPECT_TRUE(saw_blue);
  EXPECT_FALSE(seen.back().homing_mode);
  EXPECT_EQ(seen.back().leds, kLedHomed);
}

TEST_F(FalconUsbDriverTest, GripMovedWithoutHomingModeDoesNotHome) {
  open_and_run();
  fake_.script_pull_out_push_in(800, 50);
  DeviceReading reading;
  for (int i = 0; i < 120; ++i) ASSERT_EQ(driver_.try_exchange(DeviceCommand{}, reading), IoStatus::kOk);
  EXPECT_EQ(reading.homed_mask, 0);
}

TEST_F(FalconUsbDriverTest, HomingTimesOutIntoFaultWhenTheGripNeverMoves) {
  FalconUsbConfig config;
  config.homing_timeout_ns = 3'000'000'000;
  FalconUsbDriver driver(fake_, clock_, config);
  ASSERT_TRUE(driver.open());
  ASSERT_TRUE(driver.check_firmware());
  const TimeNs start_ns = clock_.now();
  EXPECT_FALSE(driver.home());
  EXPECT_EQ(driver.state(), DriverState::kFault);
  EXPECT_TRUE(contains(driver.error(), "homing timed out after 3 s")) << driver.error();
  EXPECT_GE(clock_.now() - start_ns, config.homing_timeout_ns);
  EXPECT_LT(clock_.now() - start_ns, config.homing_timeout_ns + 10'000'000);
}

// ---------------------------------------------------------------- running

TEST_F(FalconUsbDriverTest, PingPongCarriesCommandsAndReadings) {
  open_and_run();
  const std::size_t commands_before = fake_.commands().size();
  TimeNs previous_receive_ns = -1;
  for (int i = 0; i < 2000; ++i) {
    DeviceCommand command;
    command.motor_counts = {static_cast<std::int16_t>(i - 1000), static_cast<std::int16_t>(-i),
                            static_cast<std::int16_t>(i % 4096)};
    command.leds = static_cast<std::uint8_t>((i % 8) << 1);
    const std::array<std::int16_t, 3> encoders{static_cast<std::int16_t>(3 * i), static_cast<std::int16_t>(-7 * i),
                                               static_cast<std::int16_t>(i)};
    fake_.set_encoder_counts(encoders);
    fake_.set_buttons(static_cast<std::uint8_t>(i % 16));
    DeviceReading reading;
    ASSERT_EQ(driver_.try_exchange(command, reading), IoStatus::kOk) << i;
    EXPECT_EQ(reading.encoder_counts, encoders);
    EXPECT_EQ(reading.buttons, i % 16);
    EXPECT_GT(reading.receive_time_ns, previous_receive_ns);
    previous_receive_ns = reading.receive_time_ns;
    const DeviceCommand& seen = fake_.commands().back();
    EXPECT_EQ(seen.motor_counts, command.motor_counts);
    EXPECT_EQ(seen.leds, command.leds);
  }
  EXPECT_EQ(fake_.commands().size(), commands_before + 2000);  // strict ping-pong: one each
  EXPECT_EQ(driver_.stats().replies_ok, driver_.stats().exchanges);
  EXPECT_EQ(driver_.parser_stats().total_discarded_bytes(), 0U);
}

TEST_F(FalconUsbDriverTest, LostReplyIsATimeoutThenTheLinkRecovers) {
  open_and_run();
  fake_.inject_reply_faults(ReplyFault::kDrop, 1);
  DeviceReading reading;
  const TimeNs before_ns = clock_.now();
  EXPECT_EQ(driver_.try_exchange(DeviceCommand{}, reading), IoStatus::kTimeout);
  EXPECT_GE(clock_.now() - before_ns, driver_.config().reply_timeout_ns);  // waited its deadline (simulated)
  EXPECT_LE(clock_.now() - before_ns, driver_.config().reply_timeout_ns + driver_.config().write_timeout_ns);
  fake_.set_encoder_counts({9, 8, 7});
  EXPECT_EQ(driver_.try_exchange(DeviceCommand{}, reading), IoStatus::kOk);
  EXPECT_EQ(reading.encoder_counts, (std::array<std::int16_t, 3>{9, 8, 7}));
  EXPECT_EQ(driver_.stats().timeouts, 1U);
}

TEST_F(FalconUsbDriverTest, LateReplyIsNotMistakenForTheNextOne) {
  open_and_run();
  fake_.set_encoder_counts({1, 1, 1});
  fake_.inject_reply_faults(ReplyFault::kDelay, 1, 2'500'000);  // arrives after the 2 ms deadline
  DeviceReading reading;
  EXPECT_EQ(driver_.try_exchange(DeviceCommand{}, reading), IoStatus::kTimeout);
  fake_.set_encoder_counts({2, 2, 2});
  ASSERT_EQ(driver_.try_exchange(DeviceCommand{}, reading), IoStatus::kOk);
  EXPECT_EQ(reading.encoder_counts, (std::array<std::int16_t, 3>{2, 2, 2}));  // the fresh reply, not the stale one
  EXPECT_EQ(driver_.stats().stale_replies_dropped, 1U);
  fake_.set_encoder_counts({3, 3, 3});
  ASSERT_EQ(driver_.try_exchange(DeviceCommand{}, reading), IoStatus::kOk);
  EXPECT_EQ(reading.encoder_counts, (std::array<std::int16_t, 3>{3, 3, 3}));
}

TEST_F(FalconUsbDriverTest, TornAndGarbledRepliesAreReassembledOrReported) {
  open_and_run();
  DeviceReading reading;
  fake_.set_encoder_counts({5, 6, 7});
  fake_.inject_reply_faults(ReplyFault::kTear, 1);
  EXPECT_EQ(driver_.try_exchange(DeviceCommand{}, reading), IoStatus::kOk);  // two transfers, one packet
  EXPECT_EQ(reading.encoder_counts, (std::array<std::int16_t, 3>{5, 6, 7}));

  fake_.inject_reply_faults(ReplyFault::kGarbageBefore, 50);
  for (int i = 0; i < 50; ++i) {
    fake_.set_encoder_counts({static_cast<std::int16_t>(i), 0, 0});
    ASSERT_EQ(driver_.try_exchange(DeviceCommand{}, reading), IoStatus::kOk) << i;
    EXPECT_EQ(reading.encoder_counts[0], i);
  }

  fake_.inject_reply_faults(ReplyFault::kTruncate, 1);
  EXPECT_EQ(driver_.try_exchange(DeviceCommand{}, reading), IoStatus::kTornPacket);
  fake_.inject_reply_faults(ReplyFault::kCorrupt, 1);
  EXPECT_EQ(driver_.try_exchange(DeviceCommand{}, reading), IoStatus::kTornPacket);
  fake_.set_encoder_counts({-5, -6, -7});
  ASSERT_EQ(driver_.try_exchange(DeviceCommand{}, reading), IoStatus::kOk);
  EXPECT_EQ(reading.encoder_counts, (std::array<std::int16_t, 3>{-5, -6, -7}));
  EXPECT_EQ(driver_.stats().torn, 2U);
  EXPECT_GT(driver_.parser_stats().total_discarded_bytes(), 0U);
}

TEST_F(FalconUsbDriverTest, WriteTimeoutIsATimeout) {
  open_and_run();
  fake_.inject_write_timeouts(1);
  DeviceReading reading;
  EXPECT_EQ(driver_.try_exchange(DeviceCommand{}, reading), IoStatus::kTimeout);
  EXPECT_EQ(driver_.try_exchange(DeviceCommand{}, reading), IoStatus::kOk);
  EXPECT_EQ(driver_.stats().write_failures, 1U);
}

TEST_F(FalconUsbDriverTest, UnplugGivesDisconnectedAndFaultNeverAHang) {
  open_and_run();
  fake_.disconnect_after_replies(5);
  DeviceReading reading;
  for (int i = 0; i < 4; ++i) ASSERT_EQ(driver_.try_exchange(DeviceCommand{}, reading), IoStatus::kOk);
  EXPECT_EQ(driver_.try_exchange(DeviceCommand{}, reading), IoStatus::kDisconnected);
  EXPECT_EQ(driver_.state(), DriverState::kFault);
  EXPECT_TRUE(contains(driver_.error(), "Novint Falcon disconnected")) << driver_.error();
  const TimeNs after_ns = clock_.now();
  for (int i = 0; i < 1000; ++i) ASSERT_EQ(driver_.try_exchange(DeviceCommand{}, reading), IoStatus::kDisconnected);
  EXPECT_EQ(clock_.now(), after_ns);  // answered at once, no waiting
  driver_.close();
  EXPECT_EQ(driver_.state(), DriverState::kClosed);
  EXPECT_FALSE(driver_.open());  // the transport is gone: reopening reports it
  EXPECT_EQ(driver_.state(), DriverState::kFault);
}

TEST_F(FalconUsbDriverTest, DeviceThatStopsAnsweringEndsInFault) {
  open_and_run();
  fake_.inject_reply_faults(ReplyFault::kDrop, 1'000);
  DeviceReading reading;
  const int limit = driver_.config().fault_after_failed_exchanges;
  for (int i = 0; i < limit; ++i) ASSERT_EQ(driver_.try_exchange(DeviceCommand{}, reading), IoStatus::kTimeout) << i;
  EXPECT_EQ(driver_.state(), DriverState::kFault);
  EXPECT_TRUE(contains(driver_.error(), "stopped answering")) << driver_.error();
  EXPECT_EQ(driver_.try_exchange(DeviceCommand{}, reading), IoStatus::kNotRunning);
}

TEST_F(FalconUsbDriverTest, ExchangeOutsideRunningIsRefused) {
  DeviceReading reading;
  EXPECT_EQ(driver_.try_exchange(DeviceCommand{}, reading), IoStatus::kNotRunning);
  ASSERT_TRUE(driver_.open());
  EXPECT_EQ(driver_.try_exchange(DeviceCommand{}, reading), IoStatus::kNotRunning);
  EXPECT_TRUE(fake_.commands().empty());
}

TEST_F(FalconUsbDriverTest, TryExchangeDoesNotAllocate) {
  open_and_run();
  fake_.inject_reply_faults(ReplyFault::kGarbageBefore, 100);
  fake_.inject_reply_faults(ReplyFault::kDrop, 10);
  fake_.inject_reply_faults(ReplyFault::kTear, 100);
  DeviceReading reading;
  std::uint64_t ok = 0;
  g_allocations = 0;
  g_count_allocations = true;
  for (int i = 0; i < 5'000; ++i) {
    ok += driver_.try_exchange(DeviceCommand{}, reading) == IoStatus::kOk ? 1 : 0;
  }
  g_count_allocations = false;
  EXPECT_EQ(g_allocations.load(), 0U);
  EXPECT_EQ(ok, 5'000U - 10U);
}

}  // namespace
}  // namespace fissure::falcon
