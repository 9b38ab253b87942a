#pragma once
// The real transport: the Falcon's FTDI chip through libusb-1.0 (BRIEF §6: VID 0x0403,
// PID 0xCB48, bulk OUT 0x02, bulk IN 0x81). Lives in the separate target fissure_falcon_usb
// (falcon_hw/src/libusb/), so the real-time libraries cross-build without libusb; this
// header therefore only forward-declares libusb's types.
#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include "fissure/falcon_hw/usb_transport.hpp"

struct libusb_context;
struct libusb_device_handle;

namespace fissure::falcon {

inline constexpr std::uint16_t kFalconUsbVendorId = 0x0403;
inline constexpr std::uint16_t kFalconUsbProductId = 0xCB48;
/// The udev rule users install so that non-root users may open the device.
inline constexpr const char* kFalconUdevRulePath = "toolchain/udev/99-novint-falcon.rules";

class LibusbFalconTransport final : public UsbTransport {
 public:
  /// Opens the `index`-th attached Falcon: claims interface 0, resets the FTDI chip and
  /// puts it in plain UART mode. On failure returns nullptr and sets `error` to one line
  /// (no device, permission denied → udev rule, busy, libusb unavailable).
  static std::unique_ptr<LibusbFalconTransport> open(unsigned index, std::string& error);
  /// Number of attached Falcons (−1 and `error` set if libusb cannot enumerate).
  static int count_devices(std::string& error);

  ~LibusbFalconTransport() override;
  LibusbFalconTransport(const LibusbFalconTransport&) = delete;
  LibusbFalconTransport& operator=(const LibusbFalconTransport&) = delete;

  [[nodiscard]] bool is_open() const noexcept override { return handle_ != nullptr; }
  TransportStatus write(std::span<const std::uint8_t> bytes, TimeNs timeout_ns) noexcept override;
  TransportRead read(std::span<std::uint8_t> buffer, TimeNs timeout_ns) noexcept override;
  TransportStatus set_baud_divisor(std::uint16_t divisor) noexcept override;
  TransportStatus set_latency_timer(std::uint8_t latency_ms) noexcept override;
  TransportStatus set_line_8n1_no_flow_control() noexcept override;
  TransportStatus set_dtr(bool high) noexcept override;
  TransportStatus set_rts(bool high) noexcept override;
  TransportStatus purge(FtdiPurge which) noexcept override;
  void close() noexcept override;

 private:
  LibusbFalconTransport(libusb_context* context, libusb_device_handle* handle) noexcept
      : context_(context), handle_(handle) {}
  TransportStatus control(std::uint8_t request, std::uint16_t value, std::uint16_t index = 0) noexcept;
  TransportStatus status_from(int libusb_result) noexcept;

  libusb_context* context_ = nullptr;
  libusb_device_handle* handle_ = nullptr;
  bool disconnected_ = false;
  // One raw IN transfer (status bytes included) and the payload a caller had no room for.
  std::array<std::uint8_t, kFtdiMaxPacketBytes> transfer_{};
  std::array<std::uint8_t, kFtdiMaxPacketBytes> leftover_{};
  std::size_t leftover_begin_ = 0;
  std::size_t leftover_end_ = 0;
};

}  // namespace fissure::falcon
