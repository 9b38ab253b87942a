#pragma once
// The byte transport below the Falcon driver: an FTDI serial bridge reduced to what the
// driver needs. The real one is LibusbFalconTransport (falcon_hw/src/libusb, target
// fissure_falcon_usb); tests and CI use FakeFalconTransport, which answers like the device.
//
// Contract (both implementations):
// * read() returns payload bytes only — the 2 FTDI modem-status bytes at the start of every
//   64-byte USB IN packet are stripped here (strip_ftdi_status_bytes), because only the
//   transport sees USB packet boundaries. It returns as soon as ≥ 1 byte is available; an
//   FTDI transfer that carried only status bytes yields kOk with 0 bytes.
// * Every call is bounded by its timeout. Timeouts are durations on the driver's Clock, so
//   a fake transport on a LockstepClock simulates waiting by advancing that clock: no test
//   ever sleeps. (libusb counts whole milliseconds; the real transport rounds up to ≥ 1 ms,
//   because 0 means "forever" to libusb.)
// * kDisconnected is sticky: once returned, every later call returns it until close().
// * All calls are noexcept and allocation-free, so the driver may call read()/write() from
//   the RT tick.
#include <cstddef>
#include <cstdint>
#include <span>

#include "fissure/shared/time.hpp"

namespace fissure::falcon {

enum class TransportStatus : std::uint8_t {
  kOk = 0,
  kTimeout,       ///< nothing (more) within the timeout
  kDisconnected,  ///< device unplugged / gone; sticky
  kError,         ///< any other transfer failure (stall, overflow, …)
};
const char* to_string(TransportStatus status) noexcept;

struct TransportRead {
  TransportStatus status = TransportStatus::kOk;
  std::size_t bytes = 0;  ///< payload bytes placed at the start of the buffer
};

enum class FtdiPurge : std::uint8_t { kReceive, kTransmit, kBoth };

// FTDI baud-rate divisors: the raw wValue of SIO_SET_BAUD_RATE on an FT232 (3 MHz base
// clock; bits 0–13 integer divisor, bits 14–15 the sub-integer fraction). Values from
// libnifalcon's FalconCommLibUSB.cpp.
/// Normal (packet) mode: 3 MHz / 2 = 1.5 Mbaud.
inline constexpr std::uint16_t kFtdiBaudDivisorNormal = 0x0002;
/// Firmware handshake: 0x138 = 312 plus fraction code 01 (= 0.5) → 3 MHz / 312.5 = 9600 baud.
inline constexpr std::uint16_t kFtdiBaudDivisor9600 = 0x4138;
/// Firmware streaming: 3 MHz / 21 ≈ 142.9 kbaud (BRIEF §6: "~140 kbaud").
inline constexpr std::uint16_t kFtdiBaudDivisorFirmware = 0x0015;

/// Latency timer in normal mode: 1 ms (BRIEF §6 — the 16 ms default caps ping-pong at ~60 Hz).
inline constexpr std::uint8_t kFtdiLatencyNormalMs = 1;
/// Latency timer while uploading firmware: 16 ms (libnifalcon: "otherwise firmware checks
/// tend to always fail").
inline constexpr std::uint8_t kFtdiLatencyFirmwareMs = 16;

/// Full-speed bulk packet size of the Falcon's FTDI chip; each IN packet starts with 2
/// modem-status bytes.
inline constexpr std::size_t kFtdiMaxPacketBytes = 64;
inline constexpr std::size_t kFtdiStatusBytes = 2;

class UsbTransport {
 public:
  virtual ~UsbTransport() = default;

  [[nodiscard]] virtual bool is_open() const noexcept = 0;
  /// Writes all of `bytes` within `timeout_ns` (kTimeout if the device did not take them).
  virtual TransportStatus write(std::span<const std::uint8_t> bytes, TimeNs timeout_ns) noexcept = 0;
  /// Waits up to `timeout_ns` for payload bytes; see the contract above.
  virtual TransportRead read(std::span<std::uint8_t> buffer, TimeNs timeout_ns) noexcept = 0;

  virtual TransportStatus set_baud_divisor(std::uint16_t divisor) noexcept = 0;
  virtual TransportStatus set_latency_timer(std::uint8_t latency_ms) noexcept = 0;
  /// 8 data bits, no parity, 1 stop bit, no flow control (what the Falcon's UART speaks).
  virtual TransportStatus set_line_8n1_no_flow_control() noexcept = 0;
  /// Modem lines. A low→high edge of DTR resets the Falcon's microcontroller into its
  /// bootloader (libnifalcon's firmware mode toggles DTR low then high before the handshake).
  virtual TransportStatus set_dtr(bool high) noexcept = 0;
  virtual TransportStatus set_rts(bool high) noexcept = 0;
  /// Drops bytes buffered in the FTDI chip (and in the transport) in the given direction.
  virtual TransportStatus purge(FtdiPurge which) noexcept = 0;
  /// Releases the device; safe to call more than once.
  virtual void close() noexcept = 0;
};

/// Removes the FTDI modem-status bytes from one bulk IN transfer: the transfer is a sequence
/// of USB packets of `max_packet_bytes` (the last may be short), each starting with 2 status
/// bytes. Copies the payload to `out` (as much as fits) and returns the number of bytes copied.
std::size_t strip_ftdi_status_bytes(std::span<const std::uint8_t> transfer, std::size_t max_packet_bytes,
                                    std::span<std::uint8_t> out) noexcept;

}  // namespace fissure::falcon
