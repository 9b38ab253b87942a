#pragma once
// The real Falcon for the commands that drive one (run --device usb, rt --device usb,
// fissure-rt --device usb): libusb transport + driver, opened, firmware checked and homed.
// Set-up time only (it may prompt on stderr for homing); not for lockstep. A build without
// libusb for its target (the aarch64 cross build when the sysroot has none) links a version
// whose open() refuses with a one-line error, so the same programs build everywhere.
#include <memory>

#include "fissure/falcon_hw/haptic_device.hpp"
#include "fissure/shared/clock.hpp"

namespace fissure::session {

class UsbFalcon {
 public:
  /// Throws SessionError ("--device usb: …", one line) when any step fails.
  static std::unique_ptr<UsbFalcon> open(Clock& clock);
  ~UsbFalcon();
  UsbFalcon(const UsbFalcon&) = delete;
  UsbFalcon& operator=(const UsbFalcon&) = delete;

  [[nodiscard]] falcon::HapticDevice& device() noexcept;

 private:
  struct Parts;
  explicit UsbFalcon(std::unique_ptr<Parts> parts) noexcept;
  std::unique_ptr<Parts> parts_;
};

/// True when this build can drive the USB Falcon (libusb-1.0 was found for its target).
[[nodiscard]] bool usb_falcon_available() noexcept;

}  // namespace fissure::session
