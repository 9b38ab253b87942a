#include "fissure/session/usb_falcon.hpp"

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>

#include "fissure/session/session_error.hpp"

#if FISSURE_HAS_USB_FALCON
#include "fissure/falcon_hw/falcon_usb_driver.hpp"
#include "fissure/falcon_hw/libusb_transport.hpp"
#endif

namespace fissure::session {

#if FISSURE_HAS_USB_FALCON

struct UsbFalcon::Parts {
  std::unique_ptr<falcon::LibusbFalconTransport> transport;
  std::unique_ptr<falcon::FalconUsbDriver> driver;  ///< the HapticDevice; uses `transport`
};

std::unique_ptr<UsbFalcon> UsbFalcon::open(Clock& clock) {
  auto parts = std::make_unique<Parts>();
  std::string error;
  parts->transport = falcon::LibusbFalconTransport::open(0, error);
  if (!parts->transport) throw SessionError("--device usb: " + error);
  parts->driver = std::make_unique<falcon::FalconUsbDriver>(*parts->transport, clock);
  if (!parts->driver->open()) throw SessionError(std::string("--device usb: ") + parts->driver->error());
  if (!parts->driver->check_firmware()) {
    throw SessionError("--device usb: Novint Falcon firmware not loaded: run 'fissure device firmware --file F' first");
  }
  std::fprintf(stderr, "homing: pull the grip all the way out, then push it all the way in …\n");
  if (!parts->driver->home([](std::uint8_t mask) { std::fprintf(stderr, "  arms homed: 0x%x\n", mask); })) {
    throw SessionError(std::string("--device usb: homing failed: ") + parts->driver->error());
  }
  return std::unique_ptr<UsbFalcon>(new UsbFalcon(std::move(parts)));
}

falcon::HapticDevice& UsbFalcon::device() noexcept { return *parts_->driver; }

bool usb_falcon_available() noexcept { return true; }

#else

struct UsbFalcon::Parts {};

std::unique_ptr<UsbFalcon> UsbFalcon::open(Clock&) {
  throw SessionError("--device usb: this build has no USB Falcon support (libusb-1.0 was not found for its target); "
                     "use --device sim, or build with libusb-1.0 for this machine");
}

// Unreachable: open() never returns an object in this build.
falcon::HapticDevice& UsbFalcon::device() noexcept { std::abort(); }

bool usb_falcon_available() noexcept { return false; }

#endif

UsbFalcon::UsbFalcon(std::unique_ptr<Parts> parts) noexcept : parts_(std::move(parts)) {}
UsbFalcon::~UsbFalcon() = default;

}  // namespace fissure::session
