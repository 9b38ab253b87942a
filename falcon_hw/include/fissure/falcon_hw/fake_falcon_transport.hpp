#pragma once
// A fake Novint Falcon behind a fake FTDI bridge: the UsbTransport that tests and CI run the
// whole USB driver against. It answers the way the real device does (BRIEF §6):
// * bootloader after power-up / a DTR low→high edge: at 9600 baud the handshake
//   0x0A 0x43 0x0D → 0x0A 0x44 0x2C 0x0D; then at ~140 kbaud 'A' → 'A'; then it echoes every
//   firmware byte. Switching to the normal baud divisor after exactly the configured image
//   was streamed starts the "firmware"; anything else leaves the device in its bootloader.
// * with firmware running, at the normal baud divisor: one reply packet per command packet
//   (strict ping-pong), encoder counts from a scripted grip motion, buttons, and homed flags
//   that get set while homing mode is on and the scripted grip passes each arm's index.
// * nothing (a timeout) for bytes sent at the wrong baud rate or without firmware.
// Injectable faults: dropped, delayed, torn, truncated, corrupted replies, garbage before a
// reply, failed firmware echo, dropped handshake replies, write timeouts, disconnect.
//
// Time is simulated on a LockstepClock: a reply becomes readable reply_latency_ns after its
// command, and a read that times out advances the clock to its deadline instead of sleeping.
// Steady-state ping-pong is allocation-free (fixed chunk ring, preallocated command log), so
// tests can check that the driver's try_exchange does not allocate.
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fissure/falcon_hw/falcon_stream_parser.hpp"
#include "fissure/falcon_hw/haptic_device.hpp"
#include "fissure/falcon_hw/usb_transport.hpp"
#include "fissure/shared/clock.hpp"

namespace fissure::falcon {

struct FakeFalconConfig {
  /// The firmware the fake bootloader accepts (tests generate a random blob; we never ship
  /// the real one). Empty: no upload can succeed.
  std::vector<std::uint8_t> firmware_image;
  /// Power-up state: firmware already running (as after a previous upload) or bootloader.
  bool firmware_running = false;
  /// Ping-pong reply latency: USB frame + 1 ms latency timer in the real device.
  TimeNs reply_latency_ns = 500'000;
  /// Echo latency of a firmware block at ~140 kbaud.
  TimeNs echo_latency_ns = 200'000;
  /// Gap between the two halves of a torn reply.
  TimeNs tear_gap_ns = 100'000;
  std::array<std::int16_t, 3> encoder_counts{-400, -400, -400};
  /// Encoder count of each arm's homing index; the arm is homed when it passes it while the
  /// host has homing mode on.
  std::array<std::int16_t, 3> index_counts{0, 0, 0};
  /// Decoded commands kept for assertions (preallocated; further commands are not logged).
  std::size_t command_log_capacity = 1U << 16;
  std::uint64_t garbage_seed = 0x5eed;
};

enum class ReplyFault : std::uint8_t {
  kDrop,           ///< the reply never comes (→ driver timeout)
  kDelay,          ///< the reply comes `delay_ns` late (after the driver gave up)
  kTear,           ///< the reply arrives in two USB transfers
  kTruncate,       ///< the reply loses its last 7 bytes
  kGarbageBefore,  ///< 1–40 random bytes (with stray '<' '>' and nibbles) precede the reply
  kCorrupt,        ///< one payload byte of the reply becomes invalid
};

class FakeFalconTransport final : public UsbTransport {
 public:
  FakeFalconTransport(LockstepClock& clock, FakeFalconConfig config);

  // --- UsbTransport ---
  [[nodiscard]] bool is_open() const noexcept override { return !closed_; }
  TransportStatus write(std::span<const std::uint8_t> bytes, TimeNs timeout_ns) noexcept override;
  TransportRead read(std::span<std::uint8_t> buffer, TimeNs timeout_ns) noexcept override;
  TransportStatus set_baud_divisor(std::uint16_t divisor) noexcept override;
  TransportStatus set_latency_timer(std::uint8_t latency_ms) noexcept override;
  TransportStatus set_line_8n1_no_flow_control() noexcept override;
  TransportStatus set_dtr(bool high) noexcept override;
  TransportStatus set_rts(bool high) noexcept override;
  TransportStatus purge(FtdiPurge which) noexcept override;
  void close() noexcept override { closed_ = true; }

  // --- scripting the device and its faults ---
  void set_buttons(std::uint8_t buttons) noexcept { buttons_ = buttons; }
  void set_encoder_counts(const std::array<std::int16_t, 3>& counts) noexcept { encoder_counts_ = counts; }
  /// From the next reply on, all three arms move by `travel_counts` over `steps_per_leg`
  /// replies (the user pulls the grip out) and back over as many (pushes it in).
  void script_pull_out_push_in(std::int16_t travel_counts, int steps_per_leg);
  /// Applies `fault` to the next `count` replies (faults queue in order of injection).
  void inject_reply_faults(ReplyFault fault, int count, TimeNs delay_ns = 0);
  /// The device disappears instead of sending its `replies`-th next reply (0: right now).
  void disconnect_after_replies(int replies) noexcept;
  /// The device disappears during the `writes`-th next write() (the bytes are lost).
  void disconnect_after_writes(int writes) noexcept { writes_until_disconnect_ = writes; }
  /// The echo of firmware byte `image_offset` is wrong in the next `attempts` uploads.
  void fail_echo(std::size_t image_offset, int attempts) noexcept;
  /// The next `count` correct handshakes get no answer.
  void drop_handshake_replies(int count) noexcept { handshake_drops_ = count; }
  /// The next `count` writes time out (the device does not take the bytes).
  void inject_write_timeouts(int count) noexcept { write_timeouts_ = count; }

  // --- observing what the host did ---
  [[nodiscard]] bool firmware_running() const noexcept { return firmware_running_; }
  [[nodiscard]] std::uint8_t homed_mask() const noexcept { return homed_mask_; }
  [[nodiscard]] std::uint16_t baud_divisor() const noexcept { return baud_divisor_; }
  [[nodiscard]] std::uint8_t latency_timer_ms() const noexcept { return latency_ms_; }
  [[nodiscard]] bool line_configured() const noexcept { return line_configured_; }
  [[nodiscard]] int receive_purges() const noexcept { return receive_purges_; }
  [[nodiscard]] int handshakes_answered() const noexcept { return handshakes_answered_; }
  [[nodiscard]] int uploads_started() const noexcept { return uploads_started_; }
  [[nodiscard]] std::size_t firmware_bytes_received() const noexcept { return received_image_.size(); }
  [[nodiscard]] std::uint64_t replies_sent() const noexcept { return replies_sent_; }
  [[nodiscard]] const std::vector<DeviceCommand>& commands() const noexcept { return command_log_; }
  [[nodiscard]] const std::array<std::int16_t, 3>& encoder_counts() const noexcept { return encoder_counts_; }
  [[nodiscard]] const StreamParserStats& command_parser_stats() const noexcept { return command_parser_.stats(); }

 private:
  static constexpr std::size_t kChunkCapacityBytes = kFtdiMaxPacketBytes - kFtdiStatusBytes;
  static constexpr std::size_t kChunkRingSize = 1024;
  static constexpr std::size_t kMaxPendingFaults = 64;

  // One USB IN transfer's payload, readable from available_at_ns on.
  struct Chunk {
    TimeNs available_at_ns = 0;
    std::size_t length = 0;
    std::size_t read_offset = 0;
    std::array<std::uint8_t, kChunkCapacityBytes> bytes{};
  };
  struct PendingFault {
    ReplyFault fault = ReplyFault::kDrop;
    int remaining = 0;
    TimeNs delay_ns = 0;
  };
  enum class BootStage : std::uint8_t { kAwaitHandshake, kAwaitSync, kStreaming };

  void enqueue(std::span<const std::uint8_t> bytes, TimeNs available_at_ns) noexcept;
  void reset_to_bootloader() noexcept;
  void bootloader_byte(std::uint8_t byte, std::uint8_t* echo, std::size_t& echo_length) noexcept;
  void handle_command(const DeviceCommand& command) noexcept;
  void send_reply(const FalconPacket& packet) noexcept;
  std::uint8_t garbage_byte() noexcept;
  [[nodiscard]] bool gone() const noexcept { return closed_ || disconnected_; }

  LockstepClock& clock_;
  FakeFalconConfig config_;

  // FTDI bridge state.
  bool closed_ = false;
  bool disconnected_ = false;
  std::uint16_t baud_divisor_ = kFtdiBaudDivisor9600;
  std::uint8_t latency_ms_ = kFtdiLatencyFirmwareMs;  // the FTDI default
  bool line_configured_ = false;
  bool dtr_high_ = false;
  int receive_purges_ = 0;
  std::array<Chunk, kChunkRingSize> chunks_{};
  std::size_t chunk_head_ = 0;
  std::size_t chunk_count_ = 0;
  std::uint64_t overflowed_bytes_ = 0;
  int write_timeouts_ = 0;
  int writes_until_disconnect_ = -1;  // < 0: never

  // Bootloader.
  bool firmware_running_ = false;
  BootStage stage_ = BootStage::kAwaitHandshake;
  std::array<std::uint8_t, 3> handshake_window_{};
  std::vector<std::uint8_t> received_image_;
  int handshake_drops_ = 0;
  int handshakes_answered_ = 0;
  int uploads_started_ = 0;
  std::size_t echo_fault_offset_ = 0;
  int echo_fault_attempts_ = 0;
  bool echo_fault_armed_ = false;

  // Firmware (normal mode).
  FalconStreamParser command_parser_{PacketDirection::kHostToDevice};
  std::vector<DeviceCommand> command_log_;
  std::array<std::int16_t, 3> encoder_counts_{};
  std::uint8_t buttons_ = 0;
  std::uint8_t homed_mask_ = 0;
  std::vector<std::array<std::int16_t, 3>> grip_script_;
  std::size_t grip_script_next_ = 0;
  std::array<PendingFault, kMaxPendingFaults> faults_{};
  std::size_t fault_count_ = 0;
  int replies_until_disconnect_ = -1;  // < 0: never
  std::uint64_t replies_sent_ = 0;
  std::uint64_t garbage_state_;
};

}  // namespace fissure::falcon
