#pragma once
// The Novint Falcon USB driver: an explicit state machine over a UsbTransport.
//
//   kClosed ──open()──▶ kOpened ──check_firmware()──▶ [kFirmwareCheck] ──▶ kOpened
//                        │  ──upload_firmware(image)─▶ [kFirmwareUpload] ─▶ kOpened (firmware loaded)
//                        │  ──home()──────────────────▶ [kHoming] ────────▶ kRunning
//                        └─ ──start_running()─────────────────────────────▶ kRunning (not homed: probe)
//   any state ──transport failure / unplug / no reply──▶ kFault ──close()──▶ kClosed
//
// Bracketed states are the phases a call runs in; a call ends in the next stable state or
// in kFault, and error() then holds one line naming what failed. Setup calls are not for
// the RT thread (they wait up to seconds). try_exchange() is: noexcept, allocation-free,
// bounded by reply_timeout_ns, status codes only.
//
// Ping-pong: try_exchange writes one command packet and waits for one reply. A reply that
// missed its deadline may still arrive later; the next exchange then keeps reading until
// the fresh reply (or its deadline) and uses the newest packet, so a late reply is never
// mistaken for the current one. If the missed reply was really lost, that one exchange
// waits its full deadline.
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>

#include "fissure/falcon_hw/falcon_packet.hpp"
#include "fissure/falcon_hw/falcon_stream_parser.hpp"
#include "fissure/falcon_hw/haptic_device.hpp"
#include "fissure/falcon_hw/usb_transport.hpp"
#include "fissure/shared/clock.hpp"

namespace fissure::falcon {

enum class DriverState : std::uint8_t {
  kClosed,
  kOpened,          ///< FTDI configured for normal mode; firmware_loaded() says what we know
  kFirmwareCheck,   ///< asking the device for a packet
  kFirmwareUpload,  ///< bootloader handshake + streaming the image
  kHoming,          ///< homing mode on, waiting for all three homed flags
  kRunning,         ///< ping-pong; try_exchange() allowed
  kFault,           ///< stopped; error() says why; close() then open() again
};
const char* to_string(DriverState state) noexcept;

struct FalconUsbConfig {
  /// Deadline for one ping-pong reply: one 1-ms FTDI latency-timer period plus a 1-ms USB
  /// frame of margin (BRIEF §6: strict ping-pong at ~1 kHz).
  TimeNs reply_timeout_ns = 2'000'000;
  /// Deadline for handing one packet to the FTDI chip.
  TimeNs write_timeout_ns = 2'000'000;
  /// Bound on transport reads per exchange, so a transport that keeps returning empty
  /// transfers can never make try_exchange spin.
  int max_reads_per_exchange = 16;
  /// Consecutive failed exchanges in kRunning before the driver gives up (kFault):
  /// 250 ms at 1 kHz without a valid reply means the device is gone or wedged.
  int fault_after_failed_exchanges = 250;

  /// Firmware check: packets sent and per-packet deadline (libnifalcon tries 10 times).
  int firmware_check_attempts = 10;
  TimeNs firmware_check_timeout_ns = 20'000'000;
  /// Handshake at 9600 baud: tries, and how long to wait for each answer.
  int handshake_attempts = 20;
  TimeNs handshake_timeout_ns = 100'000'000;
  /// Deadline for each firmware write / echo (libnifalcon uses 1000 ms blocking transfers).
  TimeNs firmware_io_timeout_ns = 1'000'000'000;
  /// Firmware block size: one 64-byte full-speed USB packet minus the 2 FTDI status bytes,
  /// minus a margin (libnifalcon: "58 … happy medium").
  std::size_t firmware_block_bytes = 58;
  /// Whole-upload attempts (loading is known to be flaky, BRIEF §6).
  int firmware_upload_attempts = 3;

  /// Homing: exchange period and how long the user has to pull the grip out and push it in.
  TimeNs homing_period_ns = 1'000'000;
  TimeNs homing_timeout_ns = 60'000'000'000;
};

struct DriverStats {
  std::uint64_t exchanges = 0;
  std::uint64_t replies_ok = 0;
  std::uint64_t timeouts = 0;
  std::uint64_t torn = 0;
  std::uint64_t stale_replies_dropped = 0;
  std::uint64_t write_failures = 0;
  int consecutive_failures = 0;
};

/// LEDs the driver shows while homing (BRIEF §6 byte 13): red = no arm homed yet,
/// blue = some arms homed, green = all homed.
inline constexpr std::uint8_t kLedHomingNone = kLedRed;
inline constexpr std::uint8_t kLedHomingPartial = kLedBlue;
inline constexpr std::uint8_t kLedHomed = kLedGreen;

class FalconUsbDriver final : public HapticDevice {
 public:
  FalconUsbDriver(UsbTransport& transport, Clock& clock, FalconUsbConfig config = {}) noexcept;

  /// kClosed → kOpened: FTDI set-up for normal mode (purge, 8N1, latency 1 ms, baud divisor 0x2).
  bool open() noexcept;
  /// In kOpened: true when the firmware answers a packet. false with state kOpened means
  /// "no firmware"; false with state kFault means the transport failed.
  bool check_firmware() noexcept;
  /// In kOpened: uploads `image` (retrying whole uploads), then checks that it runs.
  bool upload_firmware(std::span<const std::uint8_t> image) noexcept;
  /// In kOpened with firmware: homing mode with LED feedback until all arms are homed;
  /// on_progress(homed_mask) is called whenever the mask changes. Ends in kRunning.
  bool home(const std::function<void(std::uint8_t homed_mask)>& on_progress = {});
  /// In kOpened with firmware: kRunning without homing (encoders are then relative to
  /// power-up; fine for probing, not for haptics).
  bool start_running() noexcept;
  /// Any state → kClosed; closes the transport too, so reconnecting (after an unplug, say)
  /// means a new transport and driver — the CLI opens one per command.
  void close() noexcept;

  // HapticDevice
  [[nodiscard]] const char* name() const noexcept override { return "usb-falcon"; }
  /// One ping-pong, bounded by reply_timeout_ns (+ write_timeout_ns). On any status but
  /// kOk `reading` is left untouched. kDisconnected is sticky (state kFault); so is kFault
  /// after fault_after_failed_exchanges consecutive failures (then kNotRunning).
  IoStatus try_exchange(const DeviceCommand& command, DeviceReading& reading) noexcept override;

  [[nodiscard]] DriverState state() const noexcept { return state_; }
  /// One line describing the last failure ("" if none).
  [[nodiscard]] const char* error() const noexcept { return error_.data(); }
  [[nodiscard]] bool firmware_loaded() const noexcept { return firmware_loaded_; }
  [[nodiscard]] std::uint8_t homed_mask() const noexcept { return homed_mask_; }
  [[nodiscard]] const DeviceReading& last_reading() const noexcept { return last_reading_; }
  [[nodiscard]] const DriverStats& stats() const noexcept { return stats_; }
  [[nodiscard]] const StreamParserStats& parser_stats() const noexcept { return parser_.stats(); }
  [[nodiscard]] const FalconUsbConfig& config() const noexcept { return config_; }

 private:
  enum class UploadResult : std::uint8_t { kOk, kRetry, kFatal };
  static constexpr std::size_t kReadBufferBytes = 512;
  static constexpr std::size_t kErrorBytes = 256;
  static constexpr int kMaxLateRepliesTracked = 4;

  IoStatus exchange(const DeviceCommand& command, DeviceReading& reading, TimeNs reply_timeout_ns) noexcept;
  bool set_normal_mode() noexcept;
  UploadResult upload_once(std::span<const std::uint8_t> image) noexcept;
  UploadResult wait_for_handshake() noexcept;
  UploadResult read_echo(std::span<const std::uint8_t> sent, std::size_t image_offset, std::size_t image_size) noexcept;
  /// Checks a control/transfer status; on failure enters kFault naming `what`.
  bool ok_or_fault(TransportStatus status, const char* what) noexcept;
  UploadResult fatal(TransportStatus status, const char* what) noexcept;
  void fault(const char* format, ...) noexcept __attribute__((format(printf, 2, 3)));
  void set_error(const char* format, ...) noexcept __attribute__((format(printf, 2, 3)));

  UsbTransport& transport_;
  Clock& clock_;
  FalconUsbConfig config_;
  DriverState state_ = DriverState::kClosed;
  bool disconnected_ = false;
  bool firmware_loaded_ = false;
  std::uint8_t homed_mask_ = 0;
  int unanswered_writes_ = 0;
  FalconStreamParser parser_{PacketDirection::kDeviceToHost};
  std::array<std::uint8_t, kReadBufferBytes> read_buffer_{};
  std::array<char, kErrorBytes> error_{};
  DeviceReading last_reading_{};
  DriverStats stats_{};
};

}  // namespace fissure::falcon
