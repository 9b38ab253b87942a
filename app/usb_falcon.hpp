#pragma once
// The real Falcon for the commands that drive one (run --device usb, rt --device usb):
// libusb transport + driver, opened, firmware checked and homed. Set-up time only (it may
// prompt on stderr for homing); not for lockstep.
#include <memory>

#include "fissure/falcon_hw/falcon_usb_driver.hpp"
#include "fissure/falcon_hw/libusb_transport.hpp"
#include "fissure/shared/clock.hpp"

namespace fissure::app {

struct UsbFalcon {
  std::unique_ptr<falcon::LibusbFalconTransport> transport;
  std::unique_ptr<falcon::FalconUsbDriver> driver;  ///< the HapticDevice; uses `transport`
};

/// Throws CommandError ("--device usb: …", one line) when any step fails.
UsbFalcon open_usb_falcon(Clock& clock);

}  // namespace fissure::app
