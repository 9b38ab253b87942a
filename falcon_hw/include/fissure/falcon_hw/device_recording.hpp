#pragma once
// A device recording: every exchange a HapticDevice answered during a session, as the raw
// wire values — the Falcon's 16-byte reply packet (encoder counts, buttons, homed flags), the
// 16-byte command packet the host sent, the I/O status and the timestamps. The USB Falcon and
// SimFalcon are recorded the same way, through the HapticDevice interface (RecordingDevice),
// so a recording made on the lab's Falcon replays in CI exactly like one made from SimFalcon
// (ReplayDevice). The file format is documented in docs/session.md ("Device recordings"); in
// short, little-endian throughout:
//
//   header   "FISSREC" 0x1A (8 bytes) · u32 version · f64 rt rate [Hz] ·
//            u16 length + device name · u16 length + scene name
//   records  'X' · i64 exchange time [ns] · i64 receive time − exchange time [ns] · u8 status ·
//            16 bytes reply packet · 16 bytes command packet        (50 bytes each)
//   end      'E' · u64 record count · u64 records lost · i64 session end [ns]
//
// Times count from the recording device's construction. The end record is written last, so a
// file without it was cut short (a crash, a full disk) and is refused, as is any other version.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "fissure/falcon_hw/falcon_packet.hpp"
#include "fissure/falcon_hw/haptic_device.hpp"

namespace fissure::falcon {

inline constexpr char kRecordingMagic[8] = {'F', 'I', 'S', 'S', 'R', 'E', 'C', 0x1A};
/// The one format version this build reads and writes.
inline constexpr std::uint32_t kRecordingVersion = 1;
inline constexpr std::uint8_t kRecordTagExchange = 'X';
inline constexpr std::uint8_t kRecordTagEnd = 'E';
inline constexpr std::size_t kExchangeRecordBytes = 1 + 8 + 8 + 1 + kPacketSizeBytes + kPacketSizeBytes;
inline constexpr std::size_t kEndRecordBytes = 1 + 8 + 8 + 8;

/// One exchange as the device answered it.
struct RecordedExchange {
  TimeNs exchange_time_ns = 0;         ///< clock.now() when the exchange began, from the recording's start
  TimeNs receive_offset_ns = 0;        ///< reading.receive_time_ns − the exchange's start (kOk only)
  IoStatus status = IoStatus::kOk;
  FalconPacket reply{};                ///< device→host packet (kOk only; zero bytes otherwise)
  FalconPacket command{};              ///< host→device packet as sent
};

struct RecordingHeader {
  std::uint32_t version = kRecordingVersion;
  double rt_rate_hz = 0.0;
  std::string device_name;  ///< the recorded device's name(): "sim-falcon", "usb-falcon"
  std::string scene_name;
};

struct DeviceRecording {
  RecordingHeader header;
  std::vector<RecordedExchange> exchanges;
  TimeNs session_end_ns = 0;  ///< when the recorded session asked the loop to stop (the ramp-out follows)
};

/// A recording that cannot be read: the message names the file and the byte offset.
class RecordingError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Streams a recording to a file: header at construction, records as they come, the end
/// record at finish(). Not for the RT thread (it does file I/O).
class RecordingWriter {
 public:
  /// Throws RecordingError when the file cannot be created.
  RecordingWriter(const std::filesystem::path& path, const RecordingHeader& header);
  ~RecordingWriter();
  RecordingWriter(const RecordingWriter&) = delete;
  RecordingWriter& operator=(const RecordingWriter&) = delete;

  void write(const RecordedExchange& exchange);
  /// Writes the end record and closes the file; throws RecordingError if any write failed.
  void finish(std::uint64_t records_lost, TimeNs session_end_ns);
  [[nodiscard]] std::uint64_t records() const noexcept { return records_; }

 private:
  std::filesystem::path path_;
  std::FILE* file_ = nullptr;
  std::uint64_t records_ = 0;
};

/// Reads and checks a whole recording. Throws RecordingError naming the file and offset for a
/// wrong magic or version, a truncated file, an unknown record tag, an invalid status or reply
/// packet, times running backwards, records lost while recording, or bytes after the end record.
DeviceRecording read_recording(const std::filesystem::path& path);

}  // namespace fissure::falcon
