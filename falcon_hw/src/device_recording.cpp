#include "fissure/falcon_hw/device_recording.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <fstream>
#include <iterator>

namespace fissure::falcon {
namespace {

// Explicit little-endian encoding, so a recording made on one machine reads on any other.
void put_u64(std::vector<std::uint8_t>& out, std::uint64_t value) {
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
}
void put_u32(std::vector<std::uint8_t>& out, std::uint32_t value) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
}
void put_string(std::vector<std::uint8_t>& out, const std::string& text) {
  const auto length = static_cast<std::uint16_t>(std::min<std::size_t>(text.size(), 0xFFFF));
  out.push_back(static_cast<std::uint8_t>(length));
  out.push_back(static_cast<std::uint8_t>(length >> 8));
  out.insert(out.end(), text.begin(), text.begin() + length);
}

std::string offset_text(const std::filesystem::path& path, std::size_t offset) {
  return path.string() + ": at byte offset " + std::to_string(offset) + ": ";
}

/// Reads the recording's bytes in order, each failure naming the file and the offset.
class ByteCursor {
 public:
  ByteCursor(const std::filesystem::path& path, std::vector<std::uint8_t> bytes) : path_(path), bytes_(std::move(bytes)) {}
  [[nodiscard]] std::size_t offset() const noexcept { return offset_; }
  [[nodiscard]] std::size_t left() const noexcept { return bytes_.size() - offset_; }
  [[nodiscard]] RecordingError error(const std::string& what, std::size_t at) const {
    return RecordingError(offset_text(path_, at) + what);
  }
  void need(std::size_t count, const char* what) const {
    if (left() < count) {
      throw error("truncated: " + std::string(what) + " needs " + std::to_string(count) + " bytes, the file has " +
                      std::to_string(left()) + " left (the recording was cut short)",
                  offset_);
    }
  }
  std::uint8_t u8() { return bytes_[offset_++]; }
  std::uint64_t u64() {
    std::uint64_t value = 0;
    for (int i = 0; i < 8; ++i) value |= static_cast<std::uint64_t>(bytes_[offset_++]) << (8 * i);
    return value;
  }
  std::uint32_t u32() {
    std::uint32_t value = 0;
    for (int i = 0; i < 4; ++i) value |= static_cast<std::uint32_t>(bytes_[offset_++]) << (8 * i);
    return value;
  }
  std::string string(const char* what) {
    need(2, what);
    const std::size_t length = bytes_[offset_] | (static_cast<std::size_t>(bytes_[offset_ + 1]) << 8);
    offset_ += 2;
    need(length, what);
    std::string text(reinterpret_cast<const char*>(bytes_.data() + offset_), length);
    offset_ += length;
    return text;
  }
  void copy(std::uint8_t* out, std::size_t count) {
    std::memcpy(out, bytes_.data() + offset_, count);
    offset_ += count;
  }

 private:
  const std::filesystem::path& path_;
  std::vector<std::uint8_t> bytes_;
  std::size_t offset_ = 0;
};

RecordingHeader read_header(ByteCursor& in) {
  in.need(sizeof kRecordingMagic, "the magic number");
  std::array<std::uint8_t, sizeof kRecordingMagic> magic{};
  in.copy(magic.data(), magic.size());
  if (std::memcmp(magic.data(), kRecordingMagic, magic.size()) != 0) {
    throw in.error("not a fissure device recording (the file does not start with \"FISSREC\\x1a\")", 0);
  }
  RecordingHeader header;
  in.need(4, "the format version");
  const std::size_t version_at = in.offset();
  header.version = in.u32();
  if (header.version != kRecordingVersion) {
    throw in.error("recording format version " + std::to_string(header.version) + "; this fissure reads version " +
                       std::to_string(kRecordingVersion) + " only",
                   version_at);
  }
  in.need(8, "the rt rate");
  const std::uint64_t rate_bits = in.u64();
  std::memcpy(&header.rt_rate_hz, &rate_bits, sizeof header.rt_rate_hz);
  header.device_name = in.string("the device name");
  header.scene_name = in.string("the scene name");
  return header;
}

RecordedExchange read_exchange(ByteCursor& in, std::size_t record_at, std::size_t index, TimeNs previous_time_ns) {
  in.need(kExchangeRecordBytes - 1, ("exchange record " + std::to_string(index)).c_str());
  RecordedExchange x;
  x.exchange_time_ns = static_cast<TimeNs>(in.u64());
  x.receive_offset_ns = static_cast<TimeNs>(in.u64());
  const std::uint8_t status = in.u8();
  in.copy(x.reply.data(), x.reply.size());
  in.copy(x.command.data(), x.command.size());
  const std::string which = "exchange record " + std::to_string(index) + ": ";
  if (x.exchange_time_ns < previous_time_ns) {
    throw in.error(which + "time " + std::to_string(x.exchange_time_ns) + " ns is before the previous record's " +
                       std::to_string(previous_time_ns) + " ns",
                   record_at);
  }
  if (status > static_cast<std::uint8_t>(IoStatus::kNotRunning)) {
    throw in.error(which + "I/O status " + std::to_string(status) + " is not one of 0..4", record_at);
  }
  x.status = static_cast<IoStatus>(status);
  if (x.status == IoStatus::kOk) {
    const PacketCheck check = check_packet(PacketDirection::kDeviceToHost, x.reply);
    if (!check.ok()) {
      throw in.error(which + "reply packet invalid (" + std::string(to_string(check.error)) + " at packet byte " +
                         std::to_string(check.byte_index) + ")",
                     record_at);
    }
  }
  return x;
}

}  // namespace

RecordingWriter::RecordingWriter(const std::filesystem::path& path, const RecordingHeader& header) : path_(path) {
  file_ = std::fopen(path.c_str(), "wb");
  if (file_ == nullptr) throw RecordingError("cannot create the device recording '" + path.string() + "'");
  std::vector<std::uint8_t> bytes(std::begin(kRecordingMagic), std::end(kRecordingMagic));
  put_u32(bytes, kRecordingVersion);
  std::uint64_t rate_bits = 0;
  std::memcpy(&rate_bits, &header.rt_rate_hz, sizeof rate_bits);
  put_u64(bytes, rate_bits);
  put_string(bytes, header.device_name);
  put_string(bytes, header.scene_name);
  std::fwrite(bytes.data(), 1, bytes.size(), file_);
}

RecordingWriter::~RecordingWriter() {
  if (file_ != nullptr) std::fclose(file_);
}

void RecordingWriter::write(const RecordedExchange& exchange) {
  if (file_ == nullptr) return;
  std::array<std::uint8_t, kExchangeRecordBytes> bytes{};
  std::size_t at = 0;
  bytes[at++] = kRecordTagExchange;
  for (const auto value : {static_cast<std::uint64_t>(exchange.exchange_time_ns), static_cast<std::uint64_t>(exchange.receive_offset_ns)}) {
    for (int i = 0; i < 8; ++i) bytes[at++] = static_cast<std::uint8_t>(value >> (8 * i));
  }
  bytes[at++] = static_cast<std::uint8_t>(exchange.status);
  at = static_cast<std::size_t>(std::copy(exchange.reply.begin(), exchange.reply.end(), bytes.begin() + static_cast<std::ptrdiff_t>(at)) - bytes.begin());
  std::copy(exchange.command.begin(), exchange.command.end(), bytes.begin() + static_cast<std::ptrdiff_t>(at));
  std::fwrite(bytes.data(), 1, bytes.size(), file_);
  ++records_;
}

void RecordingWriter::finish(std::uint64_t records_lost, TimeNs session_end_ns) {
  if (file_ == nullptr) return;
  std::vector<std::uint8_t> bytes{kRecordTagEnd};
  put_u64(bytes, records_);
  put_u64(bytes, records_lost);
  put_u64(bytes, static_cast<std::uint64_t>(session_end_ns));
  std::fwrite(bytes.data(), 1, bytes.size(), file_);
  const bool failed = std::ferror(file_) != 0;
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  if (failed || !closed) throw RecordingError("cannot write the device recording '" + path_.string() + "'");
}

DeviceRecording read_recording(const std::filesystem::path& path) {
  std::error_code code;
  if (std::filesystem::is_directory(path, code)) {
    throw RecordingError(path.string() + ": is a directory, not a device recording");
  }
  std::ifstream file(path, std::ios::binary);
  if (!file) throw RecordingError(path.string() + ": cannot open the device recording");
  std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  ByteCursor in(path, std::move(bytes));
  DeviceRecording recording;
  recording.header = read_header(in);
  TimeNs previous_time_ns = 0;
  while (true) {
    in.need(1, ("the record tag after " + std::to_string(recording.exchanges.size()) + " exchange records").c_str());
    const std::size_t record_at = in.offset();
    const std::uint8_t tag = in.u8();
    if (tag == kRecordTagExchange) {
      recording.exchanges.push_back(read_exchange(in, record_at, recording.exchanges.size(), previous_time_ns));
      previous_time_ns = recording.exchanges.back().exchange_time_ns;
      continue;
    }
    if (tag != kRecordTagEnd) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "0x%02x", tag);
      throw in.error(std::string("record tag ") + hex + " is neither 'X' (exchange) nor 'E' (end)", record_at);
    }
    in.need(kEndRecordBytes - 1, "the end record");
    const std::uint64_t count = in.u64();
    const std::uint64_t lost = in.u64();
    recording.session_end_ns = static_cast<TimeNs>(in.u64());
    if (count != recording.exchanges.size()) {
      throw in.error("the end record counts " + std::to_string(count) + " exchanges, the file holds " +
                         std::to_string(recording.exchanges.size()),
                     record_at);
    }
    if (lost != 0) {
      throw in.error(std::to_string(lost) + " exchanges were lost while recording (the writer fell behind the rt loop); "
                     "the recording has gaps and cannot be replayed",
                     record_at);
    }
    if (in.left() != 0) throw in.error(std::to_string(in.left()) + " bytes after the end record", in.offset());
    return recording;
  }
}

}  // namespace fissure::falcon
