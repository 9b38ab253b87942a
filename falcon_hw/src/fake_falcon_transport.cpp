#include "fissure/falcon_hw/fake_falcon_transport.hpp"

#include <algorithm>
#include <utility>

namespace fissure::falcon {
namespace {

// The firmware handshake (BRIEF §6, libnifalcon FalconCommLibUSB::setFirmwareMode).
constexpr std::array<std::uint8_t, 3> kHandshakeRequest{0x0A, 0x43, 0x0D};
constexpr std::array<std::uint8_t, 4> kHandshakeReply{0x0A, 0x44, 0x2C, 0x0D};
constexpr std::uint8_t kFirmwareSyncByte = 'A';
// A truncated reply keeps this many of its 16 bytes.
constexpr std::size_t kTruncatedReplyBytes = 9;
// A torn reply is split after this many bytes.
constexpr std::size_t kTearAtByte = 7;
constexpr std::size_t kMaxGarbageBytes = 40;
// Byte that is valid nowhere in a packet (below 'A', not a marker).
constexpr std::uint8_t kInvalidPayloadByte = 0x30;

}  // namespace

FakeFalconTransport::FakeFalconTransport(LockstepClock& clock, FakeFalconConfig config)
    : clock_(clock), config_(std::move(config)), garbage_state_(config_.garbage_seed | 1U) {
  firmware_running_ = config_.firmware_running;
  encoder_counts_ = config_.encoder_counts;
  command_log_.reserve(config_.command_log_capacity);
  received_image_.reserve(config_.firmware_image.size() + kChunkCapacityBytes);
}

// ---------------------------------------------------------------- FTDI bridge

void FakeFalconTransport::enqueue(std::span<const std::uint8_t> bytes, TimeNs available_at_ns) noexcept {
  // USB delivers in order: a chunk never becomes readable before the one queued ahead of it.
  if (chunk_count_ > 0) {
    const Chunk& last = chunks_[(chunk_head_ + chunk_count_ - 1) % kChunkRingSize];
    available_at_ns = std::max(available_at_ns, last.available_at_ns);
  }
  while (!bytes.empty()) {
    if (chunk_count_ == kChunkRingSize) {  // the FTDI chip's buffer overflows: bytes are lost
      overflowed_bytes_ += bytes.size();
      return;
    }
    Chunk& chunk = chunks_[(chunk_head_ + chunk_count_) % kChunkRingSize];
    chunk.available_at_ns = available_at_ns;
    chunk.length = std::min(bytes.size(), kChunkCapacityBytes);
    chunk.read_offset = 0;
    std::copy_n(bytes.begin(), chunk.length, chunk.bytes.begin());
    bytes = bytes.subspan(chunk.length);
    ++chunk_count_;
  }
}

TransportStatus FakeFalconTransport::write(std::span<const std::uint8_t> bytes, TimeNs timeout_ns) noexcept {
  if (gone()) return TransportStatus::kDisconnected;
  if (writes_until_disconnect_ > 0 && --writes_until_disconnect_ == 0) {
    disconnected_ = true;
    return TransportStatus::kDisconnected;
  }
  if (write_timeouts_ > 0) {
    --write_timeouts_;
    clock_.sleep_until(clock_.now() + std::max<TimeNs>(timeout_ns, 0));
    return TransportStatus::kTimeout;
  }
  std::array<std::uint8_t, kChunkCapacityBytes> echo{};
  std::size_t echo_length = 0;
  for (const std::uint8_t byte : bytes) {
    if (firmware_running_) {
      // The firmware's UART only makes sense of bytes at its own baud rate.
      if (baud_divisor_ == kFtdiBaudDivisorNormal && command_parser_.push(byte)) {
        DeviceCommand command;
        if (decode_command(command_parser_.packet(), command)) handle_command(command);
      }
      if (disconnected_) return TransportStatus::kOk;  // the bytes went out; the device then vanished
    } else {
      bootloader_byte(byte, echo.data(), echo_length);
      if (echo_length == echo.size()) {
        enqueue(std::span<const std::uint8_t>(echo.data(), echo_length), clock_.now() + config_.echo_latency_ns);
        echo_length = 0;
      }
    }
  }
  if (echo_length > 0) {
    enqueue(std::span<const std::uint8_t>(echo.data(), echo_length), clock_.now() + config_.echo_latency_ns);
  }
  return TransportStatus::kOk;
}

TransportRead FakeFalconTransport::read(std::span<std::uint8_t> buffer, TimeNs timeout_ns) noexcept {
  if (gone()) return {TransportStatus::kDisconnected, 0};
  const TimeNs deadline_ns = clock_.now() + std::max<TimeNs>(timeout_ns, 0);
  if (chunk_count_ == 0 || chunks_[chunk_head_].available_at_ns > deadline_ns) {
    clock_.sleep_until(deadline_ns);  // simulated wait: the clock jumps, nothing sleeps
    return {TransportStatus::kTimeout, 0};
  }
  Chunk& chunk = chunks_[chunk_head_];
  if (chunk.available_at_ns > clock_.now()) clock_.sleep_until(chunk.available_at_ns);
  const std::size_t n = std::min(buffer.size(), chunk.length - chunk.read_offset);
  std::copy_n(chunk.bytes.begin() + static_cast<std::ptrdiff_t>(chunk.read_offset), n, buffer.begin());
  chunk.read_offset += n;
  if (chunk.read_offset == chunk.length) {
    chunk_head_ = (chunk_head_ + 1) % kChunkRingSize;
    --chunk_count_;
  }
  return {TransportStatus::kOk, n};
}

TransportStatus FakeFalconTransport::set_baud_divisor(std::uint16_t divisor) noexcept {
  if (gone()) return TransportStatus::kDisconnected;
  baud_divisor_ = divisor;
  // Back to normal speed after streaming: the bootloader starts the image if it is intact.
  if (!firmware_running_ && stage_ == BootStage::kStreaming && divisor == kFtdiBaudDivisorNormal) {
    firmware_running_ = !config_.firmware_image.empty() && received_image_ == config_.firmware_image;
    stage_ = BootStage::kAwaitHandshake;
    homed_mask_ = 0;
  }
  return TransportStatus::kOk;
}

TransportStatus FakeFalconTransport::set_latency_timer(std::uint8_t latency_ms) noexcept {
  if (gone()) return TransportStatus::kDisconnected;
  latency_ms_ = latency_ms;
  return TransportStatus::kOk;
}

TransportStatus FakeFalconTransport::set_line_8n1_no_flow_control() noexcept {
  if (gone()) return TransportStatus::kDisconnected;
  line_configured_ = true;
  return TransportStatus::kOk;
}

TransportStatus FakeFalconTransport::set_dtr(bool high) noexcept {
  if (gone()) return TransportStatus::kDisconnected;
  if (high && !dtr_high_) reset_to_bootloader();
  dtr_high_ = high;
  return TransportStatus::kOk;
}

TransportStatus FakeFalconTransport::set_rts(bool /*high*/) noexcept {
  return gone() ? TransportStatus::kDisconnected : TransportStatus::kOk;
}

TransportStatus FakeFalconTransport::purge(FtdiPurge which) noexcept {
  if (gone()) return TransportStatus::kDisconnected;
  if (which != FtdiPurge::kTransmit) {
    chunk_head_ = 0;
    chunk_count_ = 0;
    ++receive_purges_;
  }
  return TransportStatus::kOk;
}

// ---------------------------------------------------------------- bootloader

void FakeFalconTransport::reset_to_bootloader() noexcept {
  firmware_running_ = false;
  homed_mask_ = 0;
  stage_ = BootStage::kAwaitHandshake;
  handshake_window_ = {};
  received_image_.clear();
  command_parser_.reset();
}

void FakeFalconTransport::bootloader_byte(std::uint8_t byte, std::uint8_t* echo, std::size_t& echo_length) noexcept {
  switch (stage_) {
    case BootStage::kAwaitHandshake: {
      if (baud_divisor_ != kFtdiBaudDivisor9600) return;
      handshake_window_ = {handshake_window_[1], handshake_window_[2], byte};
      if (handshake_window_ != kHandshakeRequest) return;
      handshake_window_ = {};
      if (handshake_drops_ > 0) {
        --handshake_drops_;
        return;
      }
      ++handshakes_answered_;
      enqueue(kHandshakeReply, clock_.now() + config_.echo_latency_ns);
      stage_ = BootStage::kAwaitSync;
      return;
    }
    case BootStage::kAwaitSync:
      if (baud_divisor_ != kFtdiBaudDivisorFirmware || byte != kFirmwareSyncByte) return;
      echo[echo_length++] = byte;
      stage_ = BootStage::kStreaming;
      received_image_.clear();
      ++uploads_started_;
      echo_fault_armed_ = echo_fault_attempts_ > 0;  // this upload consumes one faulty attempt
      if (echo_fault_armed_) --echo_fault_attempts_;
      return;
    case BootStage::kStreaming: {
      if (baud_divisor_ != kFtdiBaudDivisorFirmware) return;
      const std::size_t offset = received_image_.size();
      received_image_.push_back(byte);
      const bool corrupt = echo_fault_armed_ && offset == echo_fault_offset_;
      echo[echo_length++] = corrupt ? static_cast<std::uint8_t>(byte ^ 0xFF) : byte;
      return;
    }
  }
}

void FakeFalconTransport::fail_echo(std::size_t image_offset, int attempts) noexcept {
  echo_fault_offset_ = image_offset;
  echo_fault_attempts_ = attempts;
}

// ---------------------------------------------------------------- firmware

void FakeFalconTransport::script_pull_out_push_in(std::int16_t travel_counts, int steps_per_leg) {
  grip_script_.clear();
  grip_script_next_ = 0;
  const std::array<std::int16_t, 3> start = encoder_counts_;
  auto at = [&](int step) {
    std::array<std::int16_t, 3> counts{};
    for (std::size_t arm = 0; arm < 3; ++arm) {
      counts[arm] = static_cast<std::int16_t>(start[arm] + travel_counts * step / steps_per_leg);
    }
    return counts;
  };
  for (int k = 1; k <= steps_per_leg; ++k) grip_script_.push_back(at(k));
  for (int k = steps_per_leg - 1; k >= 0; --k) grip_script_.push_back(at(k));
}

void FakeFalconTransport::inject_reply_faults(ReplyFault fault, int count, TimeNs delay_ns) {
  if (fault_count_ < kMaxPendingFaults && count > 0) faults_[fault_count_++] = {fault, count, delay_ns};
}

void FakeFalconTransport::disconnect_after_replies(int replies) noexcept {
  if (replies <= 0) {
    disconnected_ = true;
  } else {
    replies_until_disconnect_ = replies;
  }
}

void FakeFalconTransport::handle_command(const DeviceCommand& command) noexcept {
  if (command_log_.size() < command_log_.capacity()) command_log_.push_back(command);
  const std::array<std::int16_t, 3> previous = encoder_counts_;
  if (grip_script_next_ < grip_script_.size()) encoder_counts_ = grip_script_[grip_script_next_++];
  if (command.homing_mode) {
    for (std::size_t arm = 0; arm < 3; ++arm) {
      const int index = config_.index_counts[arm];
      const bool passed = (previous[arm] < index && encoder_counts_[arm] >= index) ||
                          (previous[arm] > index && encoder_counts_[arm] <= index);
      if (passed) homed_mask_ = static_cast<std::uint8_t>(homed_mask_ | (1U << arm));
    }
  }
  DeviceReading reading;
  reading.encoder_counts = encoder_counts_;
  reading.buttons = buttons_;
  reading.homed_mask = homed_mask_;
  send_reply(encode_reading(reading));
}

std::uint8_t FakeFalconTransport::garbage_byte() noexcept {
  // xorshift64: deterministic garbage. Biased towards the bytes that confuse a parser.
  garbage_state_ ^= garbage_state_ << 13;
  garbage_state_ ^= garbage_state_ >> 7;
  garbage_state_ ^= garbage_state_ << 17;
  const auto r = static_cast<std::uint8_t>(garbage_state_ >> 24);
  switch (r & 3U) {
    case 0: return (r & 4U) != 0 ? kPacketStartByte : kPacketEndByte;
    case 1: return static_cast<std::uint8_t>(kNibbleOffset + ((r >> 3) & 0x0F));
    default: return static_cast<std::uint8_t>(r ^ (garbage_state_ >> 40));
  }
}

void FakeFalconTransport::send_reply(const FalconPacket& packet) noexcept {
  if (replies_until_disconnect_ > 0 && --replies_until_disconnect_ == 0) {
    disconnected_ = true;  // unplugged before this reply went out
    return;
  }
  ++replies_sent_;
  const TimeNs ready_ns = clock_.now() + config_.reply_latency_ns;
  if (fault_count_ == 0) {
    enqueue(packet, ready_ns);
    return;
  }
  PendingFault& pending = faults_[0];
  const ReplyFault fault = pending.fault;
  const TimeNs delay_ns = pending.delay_ns;
  if (--pending.remaining == 0) {
    std::move(faults_.begin() + 1, faults_.begin() + static_cast<std::ptrdiff_t>(fault_count_), faults_.begin());
    --fault_count_;
  }
  const std::span<const std::uint8_t> bytes(packet);
  switch (fault) {
    case ReplyFault::kDrop: return;
    case ReplyFault::kDelay: enqueue(bytes, ready_ns + delay_ns); return;
    case ReplyFault::kTear:
      enqueue(bytes.first(kTearAtByte), ready_ns);
      enqueue(bytes.subspan(kTearAtByte), ready_ns + config_.tear_gap_ns);
      return;
    case ReplyFault::kTruncate: enqueue(bytes.first(kTruncatedReplyBytes), ready_ns); return;
    case ReplyFault::kGarbageBefore: {
      std::array<std::uint8_t, kMaxGarbageBytes + kPacketSizeBytes> buffer{};
      const std::size_t garbage = 1 + garbage_byte() % kMaxGarbageBytes;
      for (std::size_t i = 0; i < garbage; ++i) buffer[i] = garbage_byte();
      std::copy(packet.begin(), packet.end(), buffer.begin() + static_cast<std::ptrdiff_t>(garbage));
      enqueue(std::span<const std::uint8_t>(buffer.data(), garbage + kPacketSizeBytes), ready_ns);
      return;
    }
    case ReplyFault::kCorrupt: {
      FalconPacket corrupted = packet;
      corrupted[1 + garbage_byte() % 12] = kInvalidPayloadByte;
      enqueue(corrupted, ready_ns);
      return;
    }
  }
}

}  // namespace fissure::falcon
