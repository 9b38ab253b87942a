#include "fissure/falcon_hw/libusb_transport.hpp"

#include <libusb.h>

#include <algorithm>
#include <climits>
#include <cstdio>

namespace fissure::falcon {
namespace {

// FTDI vendor requests (FTDI application notes / libftdi; as libnifalcon's libusb comm uses them).
// Vendor request to the device, host→device (libnifalcon's 0x40).
constexpr std::uint8_t kRequestTypeOut = static_cast<std::uint8_t>(LIBUSB_REQUEST_TYPE_VENDOR) |
                                         static_cast<std::uint8_t>(LIBUSB_RECIPIENT_DEVICE) |
                                         static_cast<std::uint8_t>(LIBUSB_ENDPOINT_OUT);
static_assert(kRequestTypeOut == 0x40);
constexpr std::uint8_t kSioReset = 0x00;
constexpr std::uint8_t kSioModemControl = 0x01;
constexpr std::uint8_t kSioSetFlowControl = 0x02;
constexpr std::uint8_t kSioSetBaudRate = 0x03;
constexpr std::uint8_t kSioSetData = 0x04;
constexpr std::uint8_t kSioSetLatencyTimer = 0x09;
constexpr std::uint8_t kSioSetBitMode = 0x0B;
// wValue of kSioReset.
constexpr std::uint16_t kResetSio = 0;
constexpr std::uint16_t kPurgeRx = 1;
constexpr std::uint16_t kPurgeTx = 2;
// Modem control: high byte = which lines to change, low byte = their new level.
constexpr std::uint16_t kDtrMask = 0x0100;
constexpr std::uint16_t kDtrHigh = 0x0001;
constexpr std::uint16_t kRtsMask = 0x0200;
constexpr std::uint16_t kRtsHigh = 0x0002;
// SIO_SET_DATA: 8 data bits, parity none (bits 8–10 = 0), 1 stop bit (bits 11–12 = 0).
constexpr std::uint16_t kData8N1 = 8;
constexpr std::uint16_t kFlowControlNone = 0;
// SIO_SET_BITMODE wValue: mode 0 (reset: ordinary UART) in the high byte, pin mask 0.
constexpr std::uint16_t kBitModeReset = 0x0000;
constexpr int kInterface = 0;
constexpr unsigned char kEndpointOut = 0x02;
constexpr unsigned char kEndpointIn = 0x81;
// Control transfers are set-up calls, never on the RT path: a generous deadline.
constexpr unsigned kControlTimeoutMs = 1000;

// libusb counts whole milliseconds and treats 0 as "wait forever": round up, at least 1 ms.
unsigned timeout_ms(TimeNs timeout_ns) noexcept {
  if (timeout_ns <= 0) return 1;
  const TimeNs ms = (timeout_ns + 999'999) / 1'000'000;
  return static_cast<unsigned>(std::clamp<TimeNs>(ms, 1, UINT_MAX));
}

std::string no_falcon_message() {
  char text[200];
  std::snprintf(text, sizeof text,
                "no Novint Falcon found (USB %04x:%04x) — is it plugged in and is the udev rule installed? see %s",
                kFalconUsbVendorId, kFalconUsbProductId, kFalconUdevRulePath);
  return text;
}

}  // namespace

int LibusbFalconTransport::count_devices(std::string& error) {
  libusb_context* context = nullptr;
  if (const int rc = libusb_init(&context); rc != 0) {
    error = no_falcon_message() + " (libusb: " + libusb_strerror(static_cast<libusb_error>(rc)) + ")";
    return -1;
  }
  libusb_device** list = nullptr;
  const ssize_t n = libusb_get_device_list(context, &list);
  int count = 0;
  for (ssize_t i = 0; i < n; ++i) {
    libusb_device_descriptor descriptor{};
    if (libusb_get_device_descriptor(list[i], &descriptor) == 0 && descriptor.idVendor == kFalconUsbVendorId &&
        descriptor.idProduct == kFalconUsbProductId) {
      ++count;
    }
  }
  if (n >= 0) libusb_free_device_list(list, 1);
  libusb_exit(context);
  return count;
}

std::unique_ptr<LibusbFalconTransport> LibusbFalconTransport::open(unsigned index, std::string& error) {
  libusb_context* context = nullptr;
  if (const int rc = libusb_init(&context); rc != 0) {
    error = no_falcon_message() + " (libusb: " + libusb_strerror(static_cast<libusb_error>(rc)) + ")";
    return nullptr;
  }
  libusb_device** list = nullptr;
  const ssize_t n = libusb_get_device_list(context, &list);
  libusb_device* found = nullptr;
  unsigned seen = 0;
  for (ssize_t i = 0; i < n && found == nullptr; ++i) {
    libusb_device_descriptor descriptor{};
    if (libusb_get_device_descriptor(list[i], &descriptor) != 0 || descriptor.idVendor != kFalconUsbVendorId ||
        descriptor.idProduct != kFalconUsbProductId) {
      continue;
    }
    if (seen++ == index) found = list[i];
  }
  if (found == nullptr) {
    if (n >= 0) libusb_free_device_list(list, 1);
    libusb_exit(context);
    error = seen == 0 ? no_falcon_message()
                      : "Novint Falcon #" + std::to_string(index) + " not found (" + std::to_string(seen) + " attached)";
    return nullptr;
  }
  libusb_device_handle* handle = nullptr;
  const int open_rc = libusb_open(found, &handle);
  const int bus = libusb_get_bus_number(found);
  const int address = libusb_get_device_address(found);
  libusb_free_device_list(list, 1);
  if (open_rc != 0) {
    libusb_exit(context);
    char text[300];
    if (open_rc == LIBUSB_ERROR_ACCESS) {
      std::snprintf(text, sizeof text,
                    "permission denied opening the Novint Falcon (USB %04x:%04x, bus %d device %d) — install the "
                    "udev rule %s and re-plug it",
                    kFalconUsbVendorId, kFalconUsbProductId, bus, address, kFalconUdevRulePath);
    } else {
      std::snprintf(text, sizeof text, "cannot open the Novint Falcon (USB bus %d device %d): %s", bus, address,
                    libusb_strerror(static_cast<libusb_error>(open_rc)));
    }
    error = text;
    return nullptr;
  }
  libusb_set_auto_detach_kernel_driver(handle, 1);  // ftdi_sio may have bound it
  if (const int rc = libusb_claim_interface(handle, kInterface); rc != 0) {
    libusb_close(handle);
    libusb_exit(context);
    error = std::string("cannot claim the Novint Falcon's USB interface: ") +
            libusb_strerror(static_cast<libusb_error>(rc)) +
            (rc == LIBUSB_ERROR_BUSY ? " (another program is using it)" : "");
    return nullptr;
  }
  std::unique_ptr<LibusbFalconTransport> transport(new LibusbFalconTransport(context, handle));
  // A known starting point: chip reset, ordinary UART mode (not bit-bang).
  if (transport->control(kSioReset, kResetSio) != TransportStatus::kOk ||
      transport->control(kSioSetBitMode, kBitModeReset) != TransportStatus::kOk) {
    error = "the Novint Falcon's FTDI chip did not accept reset/bit-mode requests";
    return nullptr;
  }
  return transport;
}

LibusbFalconTransport::~LibusbFalconTransport() { close(); }

void LibusbFalconTransport::close() noexcept {
  if (handle_ != nullptr) {
    libusb_release_interface(handle_, kInterface);
    libusb_close(handle_);
    handle_ = nullptr;
  }
  if (context_ != nullptr) {
    libusb_exit(context_);
    context_ = nullptr;
  }
}

TransportStatus LibusbFalconTransport::status_from(int libusb_result) noexcept {
  switch (libusb_result) {
    case LIBUSB_SUCCESS: return TransportStatus::kOk;
    case LIBUSB_ERROR_TIMEOUT: return TransportStatus::kTimeout;
    case LIBUSB_ERROR_NO_DEVICE:
      disconnected_ = true;
      return TransportStatus::kDisconnected;
    default: return TransportStatus::kError;
  }
}

TransportStatus LibusbFalconTransport::control(std::uint8_t request, std::uint16_t value, std::uint16_t index) noexcept {
  if (disconnected_ || handle_ == nullptr) return TransportStatus::kDisconnected;
  const int rc = libusb_control_transfer(handle_, kRequestTypeOut, request, value, index, nullptr, 0, kControlTimeoutMs);
  return status_from(rc < 0 ? rc : LIBUSB_SUCCESS);
}

TransportStatus LibusbFalconTransport::write(std::span<const std::uint8_t> bytes, TimeNs timeout_ns) noexcept {
  if (disconnected_ || handle_ == nullptr) return TransportStatus::kDisconnected;
  int transferred = 0;
  // libusb takes a non-const pointer but does not write to an OUT buffer.
  const int rc = libusb_bulk_transfer(handle_, kEndpointOut, const_cast<unsigned char*>(bytes.data()),
                                      static_cast<int>(bytes.size()), &transferred, timeout_ms(timeout_ns));
  if (rc == 0 && static_cast<std::size_t>(transferred) != bytes.size()) return TransportStatus::kTimeout;
  return status_from(rc);
}

TransportRead LibusbFalconTransport::read(std::span<std::uint8_t> buffer, TimeNs timeout_ns) noexcept {
  if (disconnected_ || handle_ == nullptr) return {TransportStatus::kDisconnected, 0};
  if (leftover_begin_ == leftover_end_) {
    // One 64-byte USB packet per transfer (libnifalcon: larger reads misbehave on some
    // platforms); its first 2 bytes are FTDI modem status.
    int transferred = 0;
    const int rc = libusb_bulk_transfer(handle_, kEndpointIn, transfer_.data(), static_cast<int>(transfer_.size()),
                                        &transferred, timeout_ms(timeout_ns));
    if (rc != 0 && !(rc == LIBUSB_ERROR_TIMEOUT && transferred > 0)) return {status_from(rc), 0};
    leftover_begin_ = 0;
    leftover_end_ = strip_ftdi_status_bytes(std::span<const std::uint8_t>(transfer_.data(), static_cast<std::size_t>(transferred)),
                                            kFtdiMaxPacketBytes, leftover_);
  }
  const std::size_t n = std::min(buffer.size(), leftover_end_ - leftover_begin_);
  std::copy_n(leftover_.begin() + static_cast<std::ptrdiff_t>(leftover_begin_), n, buffer.begin());
  leftover_begin_ += n;
  return {TransportStatus::kOk, n};
}

TransportStatus LibusbFalconTransport::set_baud_divisor(std::uint16_t divisor) noexcept {
  return control(kSioSetBaudRate, divisor);
}

TransportStatus LibusbFalconTransport::set_latency_timer(std::uint8_t latency_ms) noexcept {
  return control(kSioSetLatencyTimer, latency_ms);
}

TransportStatus LibusbFalconTransport::set_line_8n1_no_flow_control() noexcept {
  const TransportStatus data = control(kSioSetData, kData8N1);
  return data != TransportStatus::kOk ? data : control(kSioSetFlowControl, kFlowControlNone);
}

TransportStatus LibusbFalconTransport::set_dtr(bool high) noexcept {
  return control(kSioModemControl, static_cast<std::uint16_t>(kDtrMask | (high ? kDtrHigh : 0)));
}

TransportStatus LibusbFalconTransport::set_rts(bool high) noexcept {
  return control(kSioModemControl, static_cast<std::uint16_t>(kRtsMask | (high ? kRtsHigh : 0)));
}

TransportStatus LibusbFalconTransport::purge(FtdiPurge which) noexcept {
  leftover_begin_ = leftover_end_ = 0;
  if (which != FtdiPurge::kTransmit) {
    if (const TransportStatus s = control(kSioReset, kPurgeRx); s != TransportStatus::kOk) return s;
  }
  if (which != FtdiPurge::kReceive) return control(kSioReset, kPurgeTx);
  return TransportStatus::kOk;
}

}  // namespace fissure::falcon
