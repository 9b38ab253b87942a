#pragma once
// The unit every carrier moves: one CAN FD frame (BRIEF §8). Loopback and UDP carriers move
// exactly these frames too, so the codec tested in CI is the code that runs on the bus.
// Also: the CAN FD bit-time arithmetic behind the bus-time figures in docs/wire_protocol.md.
#include <array>
#include <cstddef>
#include <cstdint>

namespace fissure::wire {

/// CAN FD data field: at most 64 bytes (ISO 11898-1:2015).
inline constexpr std::size_t kCanFdMaxDataBytes = 64;

/// Flag bits of CanFdFrame::flags; the values are Linux's canfd_frame.flags bits, so the
/// SocketCAN carrier passes them through unchanged.
enum CanFdFlags : std::uint8_t {
  kCanFdBitRateSwitch = 0x01,  ///< CANFD_BRS: data phase at the fast (data) bit rate
  kCanFdErrorState = 0x02,     ///< CANFD_ESI: transmitter is error passive
};

/// One CAN FD frame. Same fields as Linux's struct canfd_frame, without the kernel header so
/// that the codec does not depend on one. `can_id` is an 11-bit standard identifier here.
struct CanFdFrame {
  std::uint32_t can_id = 0;
  std::uint8_t length = 0;  ///< valid bytes in data, 0…64
  std::uint8_t flags = 0;   ///< CanFdFlags
  std::array<std::uint8_t, kCanFdMaxDataBytes> data{};
};

/// A frame as a carrier delivered it. `receive_time_ns` is on the receiving side's
/// fissure::Clock timeline (for SocketCAN: the kernel's SO_TIMESTAMP mapped to CLOCK_MONOTONIC).
struct ReceivedFrame {
  CanFdFrame frame;
  std::int64_t receive_time_ns = 0;
};

/// CAN FD can only carry these data lengths (DLC codes 0…15). Returns the smallest valid
/// length ≥ `bytes` (bytes ≤ 64); the sender pads the frame with zeros up to it.
constexpr std::size_t can_fd_padded_length(std::size_t bytes) noexcept {
  constexpr std::array<std::size_t, 16> kDlcLengths{0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64};
  for (const std::size_t length : kDlcLengths) {
    if (length >= bytes) return length;
  }
  return kCanFdMaxDataBytes;
}

/// Bit rates of a CAN FD bus with bit-rate switching: arbitration at the nominal rate,
/// the data phase at the data rate. The brief's deployment bus is 1 Mbit/s / 5 Mbit/s.
struct CanFdBitRates {
  double nominal_bit_per_s = 1e6;
  double data_bit_per_s = 5e6;
};

/// Time a base-format (11-bit id) CAN FD frame with BRS and `data_bytes` (a valid DLC length)
/// occupies the bus, including the 3-bit intermission, per ISO 11898-1:2015's field layout:
///   nominal rate: SOF 1, id 11, RRS 1, IDE 1, FDF 1, res 1, BRS 1 (17 bits), then CRC
///                 delimiter 1, ACK 1, ACK delimiter 1, EOF 7, intermission 3 (13 bits);
///   data rate:    ESI 1, DLC 4, data 8·N, stuff count 4, CRC 17 (N ≤ 16) or 21 (N > 16),
///                 fixed stuff bits in the CRC field 5 (CRC-17) or 6 (CRC-21).
/// `worst_case_stuffing` adds one dynamic stuff bit per 4 bits from SOF to the end of the
/// data field (the bound for alternating patterns); without it no stuff bits are counted.
/// The brief's "~140–170 µs for a 64-byte frame at 1/5 Mbit/s" is exactly this range.
constexpr double can_fd_frame_bus_time_s(std::size_t data_bytes, CanFdBitRates rates,
                                         bool worst_case_stuffing) noexcept {
  constexpr double kArbitrationBits = 17.0;
  constexpr double kTrailerBits = 13.0;
  const double data_field_bits = 8.0 * static_cast<double>(data_bytes);
  const double crc_bits = data_bytes <= 16 ? 17.0 : 21.0;
  const double fixed_stuff_bits = data_bytes <= 16 ? 5.0 : 6.0;
  double nominal_bits = kArbitrationBits + kTrailerBits;
  double data_bits = 1.0 + 4.0 + data_field_bits + 4.0 + crc_bits + fixed_stuff_bits;
  if (worst_case_stuffing) {
    // Dynamic stuffing: after the first 5 equal bits, then every 4 in the worst pattern.
    const double stuffed_region_bits = kArbitrationBits + 1.0 + 4.0 + data_field_bits;
    const double stuff_bits_total = static_cast<double>(static_cast<long>((stuffed_region_bits - 1.0) / 4.0));
    const double stuff_bits_arbitration = static_cast<double>(static_cast<long>((kArbitrationBits - 1.0) / 4.0));
    nominal_bits += stuff_bits_arbitration;
    data_bits += stuff_bits_total - stuff_bits_arbitration;
  }
  return nominal_bits / rates.nominal_bit_per_s + data_bits / rates.data_bit_per_s;
}

}  // namespace fissure::wire
