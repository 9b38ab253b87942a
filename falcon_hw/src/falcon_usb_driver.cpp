#include "fissure/falcon_hw/falcon_usb_driver.hpp"

#include <algorithm>
#include <cstdarg>
#include <cstdio>

namespace fissure::falcon {
namespace {

// The firmware handshake (BRIEF §6, libnifalcon FalconCommLibUSB::setFirmwareMode).
constexpr std::array<std::uint8_t, 3> kHandshakeRequest{0x0A, 0x43, 0x0D};
constexpr std::array<std::uint8_t, 4> kHandshakeReply{0x0A, 0x44, 0x2C, 0x0D};
constexpr std::uint8_t kFirmwareSyncByte = 'A';

bool contains(std::span<const std::uint8_t> haystack, std::span<const std::uint8_t> needle) noexcept {
  return std::search(haystack.begin(), haystack.end(), needle.begin(), needle.end()) != haystack.end();
}

}  // namespace

const char* to_string(DriverState state) noexcept {
  switch (state) {
    case DriverState::kClosed: return "closed";
    case DriverState::kOpened: return "opened";
    case DriverState::kFirmwareCheck: return "firmware check";
    case DriverState::kFirmwareUpload: return "firmware upload";
    case DriverState::kHoming: return "homing";
    case DriverState::kRunning: return "running";
    case DriverState::kFault: return "fault";
  }
  return "unknown";
}

FalconUsbDriver::FalconUsbDriver(UsbTransport& transport, Clock& clock, FalconUsbConfig config) noexcept
    : transport_(transport), clock_(clock), config_(config) {}

void FalconUsbDriver::set_error(const char* format, ...) noexcept {
  va_list args;
  va_start(args, format);
  std::vsnprintf(error_.data(), error_.size(), format, args);
  va_end(args);
}

void FalconUsbDriver::fault(const char* format, ...) noexcept {
  va_list args;
  va_start(args, format);
  std::vsnprintf(error_.data(), error_.size(), format, args);
  va_end(args);
  state_ = DriverState::kFault;
}

bool FalconUsbDriver::ok_or_fault(TransportStatus status, const char* what) noexcept {
  if (status == TransportStatus::kOk) return true;
  if (status == TransportStatus::kDisconnected) {
    disconnected_ = true;
    fault("Novint Falcon disconnected (USB) during %s", what);
  } else {
    fault("Novint Falcon USB %s failed: %s", what, to_string(status));
  }
  return false;
}

FalconUsbDriver::UploadResult FalconUsbDriver::fatal(TransportStatus status, const char* what) noexcept {
  ok_or_fault(status, what);
  return UploadResult::kFatal;
}

bool FalconUsbDriver::set_normal_mode() noexcept {
  return ok_or_fault(transport_.purge(FtdiPurge::kBoth), "purge") &&
         ok_or_fault(transport_.set_line_8n1_no_flow_control(), "line set-up") &&
         ok_or_fault(transport_.set_latency_timer(kFtdiLatencyNormalMs), "latency timer set-up") &&
         ok_or_fault(transport_.set_baud_divisor(kFtdiBaudDivisorNormal), "baud rate set-up") &&
         ok_or_fault(transport_.purge(FtdiPurge::kBoth), "purge");
}

bool FalconUsbDriver::open() noexcept {
  if (state_ != DriverState::kClosed) {
    set_error("open() needs state closed, driver is %s", to_string(state_));
    return false;
  }
  if (!transport_.is_open()) {
    fault("Novint Falcon USB transport is not open");
    return false;
  }
  error_[0] = '\0';
  disconnected_ = false;
  firmware_loaded_ = false;
  homed_mask_ = 0;
  unanswered_writes_ = 0;
  stats_ = {};
  parser_.reset();
  state_ = DriverState::kOpened;
  return set_normal_mode();
}

void FalconUsbDriver::close() noexcept {
  transport_.close();
  state_ = DriverState::kClosed;
  firmware_loaded_ = false;
  homed_mask_ = 0;
}

// ---------------------------------------------------------------- ping-pong

IoStatus FalconUsbDriver::exchange(const DeviceCommand& command, DeviceReading& reading,
                                   TimeNs reply_timeout_ns) noexcept {
  ++stats_.exchanges;
  const FalconPacket packet = encode_command(command);
  const TransportStatus written = transport_.write(packet, config_.write_timeout_ns);
  if (written == TransportStatus::kDisconnected) {
    ok_or_fault(written, "write");
    return IoStatus::kDisconnected;
  }
  if (written != TransportStatus::kOk) {
    ++stats_.write_failures;
    return IoStatus::kTimeout;
  }

  // Replies we may still be owed from exchanges that timed out: wait for one more than that.
  const int late_expected = std::min(unanswered_writes_, kMaxLateRepliesTracked);
  const TimeNs deadline_ns = clock_.now() + reply_timeout_ns;
  int packets = 0;
  bool any_bytes = false;
  DeviceReading newest = reading;
  TimeNs newest_time_ns = 0;
  for (int reads = 0; reads < config_.max_reads_per_exchange && packets <= late_expected; ++reads) {
    const TimeNs remaining_ns = deadline_ns - clock_.now();
    if (remaining_ns <= 0) break;
    const TransportRead got = transport_.read(read_buffer_, remaining_ns);
    if (got.status == TransportStatus::kDisconnected) {
      ok_or_fault(got.status, "read");
      return IoStatus::kDisconnected;
    }
    if (got.status != TransportStatus::kOk) break;
    any_bytes = any_bytes || got.bytes > 0;
    for (std::size_t i = 0; i < got.bytes; ++i) {
      // The parser only completes packets that pass check_packet, so decoding cannot fail.
      if (parser_.push(read_buffer_[i]) && decode_reading(parser_.packet(), newest)) {
        ++packets;
        newest_time_ns = clock_.now();
      }
    }
  }
  if (packets == 0) {
    unanswered_writes_ = std::min(unanswered_writes_ + 1, kMaxLateRepliesTracked);
    if (any_bytes) {
      ++stats_.torn;
      return IoStatus::kTornPacket;
    }
    ++stats_.timeouts;
    return IoStatus::kTimeout;
  }
  stats_.stale_replies_dropped += static_cast<std::uint64_t>(packets - 1);
  unanswered_writes_ = 0;
  ++stats_.replies_ok;
  newest.receive_time_ns = newest_time_ns;
  reading = newest;
  last_reading_ = newest;
  homed_mask_ = newest.homed_mask;
  return IoStatus::kOk;
}

IoStatus FalconUsbDriver::try_exchange(const DeviceCommand& command, DeviceReading& reading) noexcept {
  if (state_ != DriverState::kRunning) {
    return disconnected_ ? IoStatus::kDisconnected : IoStatus::kNotRunning;
  }
  const IoStatus status = exchange(command, reading, config_.reply_timeout_ns);
  if (status == IoStatus::kOk) {
    stats_.consecutive_failures = 0;
  } else if (status != IoStatus::kDisconnected &&
             ++stats_.consecutive_failures >= config_.fault_after_failed_exchanges) {
    fault("Novint Falcon stopped answering: %d exchanges in a row without a valid reply (last: %s)",
          stats_.consecutive_failures, to_string(status));
  }
  return status;
}

// ---------------------------------------------------------------- firmware

bool FalconUsbDriver::check_firmware() noexcept {
  if (state_ != DriverState::kOpened) {
    set_error("check_firmware() needs state opened, driver is %s", to_string(state_));
    return false;
  }
  state_ = DriverState::kFirmwareCheck;
  if (!ok_or_fault(transport_.purge(FtdiPurge::kBoth), "purge")) return false;
  parser_.reset();
  unanswered_writes_ = 0;
  DeviceReading reading;
  for (int attempt = 0; attempt < config_.firmware_check_attempts; ++attempt) {
    const IoStatus status = exchange(DeviceCommand{}, reading, config_.firmware_check_timeout_ns);
    if (status == IoStatus::kDisconnected) return false;
    if (status == IoStatus::kOk) {
      firmware_loaded_ = true;
      state_ = DriverState::kOpened;
      return true;
    }
  }
  firmware_loaded_ = false;
  state_ = DriverState::kOpened;
  set_error("Novint Falcon firmware not loaded: no reply to %d packets (run 'fissure device firmware --file F')",
            config_.firmware_check_attempts);
  return false;
}

FalconUsbDriver::UploadResult FalconUsbDriver::wait_for_handshake() noexcept {
  // Collect what arrives and look for the reply anywhere in it: macOS delivers a leading
  // 0x00 before it (libnifalcon's "Apple case"), stale bytes may precede it.
  std::array<std::uint8_t, 64> received{};
  for (int attempt = 0; attempt < config_.handshake_attempts; ++attempt) {
    const TransportStatus written = transport_.write(kHandshakeRequest, config_.firmware_io_timeout_ns);
    if (written == TransportStatus::kDisconnected) return fatal(written, "firmware handshake");
    std::size_t length = 0;
    const TimeNs deadline_ns = clock_.now() + config_.handshake_timeout_ns;
    while (clock_.now() < deadline_ns) {
      const TransportRead got = transport_.read(read_buffer_, deadline_ns - clock_.now());
      if (got.status == TransportStatus::kDisconnected) return fatal(got.status, "firmware handshake");
      if (got.status != TransportStatus::kOk) break;
      for (std::size_t i = 0; i < got.bytes; ++i) {
        if (length == received.size()) {  // keep the newest bytes
          std::move(received.begin() + 1, received.end(), received.begin());
          --length;
        }
        received[length++] = read_buffer_[i];
      }
      if (contains(std::span<const std::uint8_t>(received.data(), length), kHandshakeReply)) return UploadResult::kOk;
    }
  }
  set_error("no firmware handshake answer from the Falcon's bootloader (sent 0A 43 0D %d times at 9600 baud)",
            config_.handshake_attempts);
  return UploadResult::kRetry;
}

FalconUsbDriver::UploadResult FalconUsbDriver::read_echo(std::span<const std::uint8_t> sent, std::size_t image_offset,
                                                         std::size_t image_size) noexcept {
  std::size_t echoed = 0;
  const TimeNs deadline_ns = clock_.now() + config_.firmware_io_timeout_ns;
  while (echoed < sent.size()) {
    const TimeNs remaining_ns = deadline_ns - clock_.now();
    const TransportRead got = remaining_ns > 0 ? transport_.read(read_buffer_, remaining_ns)
                                               : TransportRead{TransportStatus::kTimeout, 0};
    if (got.status == TransportStatus::kDisconnected) return fatal(got.status, "firmware upload");
    if (got.status != TransportStatus::kOk) {
      set_error("firmware echo timeout at byte %zu of %zu (%zu of %zu echo bytes arrived)", image_offset + echoed,
                image_size, echoed, sent.size());
      return UploadResult::kRetry;
    }
    for (std::size_t i = 0; i < got.bytes; ++i) {
      if (echoed == sent.size()) {
        set_error("firmware echo has extra bytes after byte %zu of %zu", image_offset + echoed, image_size);
        return UploadResult::kRetry;
      }
      if (read_buffer_[i] != sent[echoed]) {
        set_error("firmware echo mismatch at byte %zu of %zu (sent 0x%02x, device echoed 0x%02x)",
                  image_offset + echoed, image_size, sent[echoed], read_buffer_[i]);
        return UploadResult::kRetry;
      }
      ++echoed;
    }
  }
  return UploadResult::kOk;
}

FalconUsbDriver::UploadResult FalconUsbDriver::upload_once(std::span<const std::uint8_t> image) noexcept {
  // Bootloader mode (libnifalcon setFirmwareMode): 9600 8N1, no flow control, RTS low,
  // DTR low→high (resets the microcontroller into its bootloader), latency 16 ms.
  const bool configured = ok_or_fault(transport_.purge(FtdiPurge::kBoth), "purge") &&
                          ok_or_fault(transport_.set_latency_timer(kFtdiLatencyFirmwareMs), "latency timer set-up") &&
                          ok_or_fault(transport_.set_baud_divisor(kFtdiBaudDivisor9600), "baud rate set-up") &&
                          ok_or_fault(transport_.set_line_8n1_no_flow_control(), "line set-up") &&
                          ok_or_fault(transport_.set_rts(false), "RTS") &&
                          ok_or_fault(transport_.set_dtr(false), "DTR") &&
                          ok_or_fault(transport_.set_dtr(true), "DTR");
  if (!configured) return UploadResult::kFatal;
  if (const UploadResult handshake = wait_for_handshake(); handshake != UploadResult::kOk) return handshake;

  // Streaming speed; 'A' must come back before the image goes out.
  if (!ok_or_fault(transport_.set_dtr(false), "DTR") ||
      !ok_or_fault(transport_.set_baud_divisor(kFtdiBaudDivisorFirmware), "baud rate set-up") ||
      !ok_or_fault(transport_.purge(FtdiPurge::kReceive), "purge")) {
    return UploadResult::kFatal;
  }
  const std::array<std::uint8_t, 1> sync{kFirmwareSyncByte};
  const TransportStatus sync_written = transport_.write(sync, config_.firmware_io_timeout_ns);
  if (sync_written == TransportStatus::kDisconnected) return fatal(sync_written, "firmware upload");
  if (const UploadResult echo = read_echo(sync, 0, image.size()); echo != UploadResult::kOk) {
    if (echo == UploadResult::kRetry) set_error("the Falcon's bootloader did not echo the sync byte 'A' at ~140 kbaud");
    return echo;
  }

  for (std::size_t offset = 0; offset < image.size(); offset += config_.firmware_block_bytes) {
    const std::span<const std::uint8_t> block = image.subspan(offset, std::min(config_.firmware_block_bytes, image.size() - offset));
    const TransportStatus written = transport_.write(block, config_.firmware_io_timeout_ns);
    if (written == TransportStatus::kDisconnected) return fatal(written, "firmware upload");
    if (written != TransportStatus::kOk) {
      set_error("firmware write failed at byte %zu of %zu: %s", offset, image.size(), to_string(written));
      return UploadResult::kRetry;
    }
    if (const UploadResult echo = read_echo(block, offset, image.size()); echo != UploadResult::kOk) return echo;
  }
  return UploadResult::kOk;
}

bool FalconUsbDriver::upload_firmware(std::span<const std::uint8_t> image) noexcept {
  if (state_ != DriverState::kOpened) {
    set_error("upload_firmware() needs state opened, driver is %s", to_string(state_));
    return false;
  }
  if (image.empty()) {
    set_error("firmware image is empty");
    return false;
  }
  if (config_.firmware_block_bytes == 0 || config_.firmware_block_bytes > kReadBufferBytes) {
    set_error("firmware_block_bytes must be 1..%zu", kReadBufferBytes);
    return false;
  }
  state_ = DriverState::kFirmwareUpload;
  firmware_loaded_ = false;
  homed_mask_ = 0;
  UploadResult result = UploadResult::kRetry;
  int attempt = 0;
  while (attempt < config_.firmware_upload_attempts && result == UploadResult::kRetry) {
    ++attempt;
    result = upload_once(image);
  }
  if (result == UploadResult::kFatal) return false;  // fault() already said why
  if (result != UploadResult::kOk) {
    std::array<char, kErrorBytes> last{};
    std::copy(error_.begin(), error_.end(), last.begin());
    fault("firmware upload failed after %d attempt%s: %s", attempt, attempt == 1 ? "" : "s", last.data());
    return false;
  }
  if (!set_normal_mode()) return false;
  state_ = DriverState::kOpened;
  if (check_firmware()) return true;
  if (state_ != DriverState::kFault) {
    fault("firmware uploaded (%zu bytes, echo verified) but the Falcon does not answer packets", image.size());
  }
  return false;
}

// ---------------------------------------------------------------- homing / running

bool FalconUsbDriver::home(const std::function<void(std::uint8_t homed_mask)>& on_progress) {
  if (state_ != DriverState::kOpened || !firmware_loaded_) {
    set_error("home() needs an opened Falcon with firmware loaded (driver is %s, firmware %s)", to_string(state_),
              firmware_loaded_ ? "loaded" : "not loaded");
    return false;
  }
  state_ = DriverState::kHoming;
  const TimeNs start_ns = clock_.now();
  TimeNs next_ns = start_ns;
  int last_mask = -1;
  DeviceReading reading;
  DeviceCommand command;  // zero motor commands: the user moves the grip, not the motors
  command.homing_mode = true;
  while (true) {
    command.leds = homed_mask_ == 0 ? kLedHomingNone : kLedHomingPartial;
    const IoStatus status = exchange(command, reading, config_.reply_timeout_ns);
    if (status == IoStatus::kDisconnected) return false;
    if (status == IoStatus::kOk && reading.homed_mask != last_mask) {
      last_mask = reading.homed_mask;
      if (on_progress) on_progress(reading.homed_mask);
    }
    if (status == IoStatus::kOk && reading.homed_mask == kHomedMaskAllArms) break;
    if (clock_.now() - start_ns >= config_.homing_timeout_ns) {
      fault("homing timed out after %.0f s with arms homed mask 0x%x of 0x7: pull the grip fully out, then push it in",
            to_seconds(config_.homing_timeout_ns), static_cast<unsigned>(homed_mask_));
      return false;
    }
    next_ns += config_.homing_period_ns;
    clock_.sleep_until(next_ns);
  }
  // Homing mode off, green LED: tells the user homing is done.
  DeviceCommand done;
  done.leds = kLedHomed;
  for (int attempt = 0; attempt < config_.firmware_check_attempts; ++attempt) {
    const IoStatus status = exchange(done, reading, config_.reply_timeout_ns);
    if (status == IoStatus::kDisconnected) return false;
    if (status == IoStatus::kOk) {
      state_ = DriverState::kRunning;
      stats_.consecutive_failures = 0;
      return true;
    }
  }
  fault("Falcon homed but did not answer the homing-off packet");
  return false;
}

bool FalconUsbDriver::start_running() noexcept {
  if (state_ != DriverState::kOpened || !firmware_loaded_) {
    set_error("start_running() needs an opened Falcon with firmware loaded (driver is %s, firmware %s)",
              to_string(state_), firmware_loaded_ ? "loaded" : "not loaded");
    return false;
  }
  stats_.consecutive_failures = 0;
  state_ = DriverState::kRunning;
  return true;
}

}  // namespace fissure::falcon
