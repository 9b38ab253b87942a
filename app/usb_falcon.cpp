#include "usb_falcon.hpp"

#include <cstdint>
#include <cstdio>
#include <string>

#include "commands.hpp"

namespace fissure::app {

UsbFalcon open_usb_falcon(Clock& clock) {
  UsbFalcon usb;
  std::string error;
  usb.transport = falcon::LibusbFalconTransport::open(0, error);
  if (!usb.transport) throw CommandError("--device usb: " + error);
  usb.driver = std::make_unique<falcon::FalconUsbDriver>(*usb.transport, clock);
  if (!usb.driver->open()) throw CommandError(std::string("--device usb: ") + usb.driver->error());
  if (!usb.driver->check_firmware()) {
    throw CommandError("--device usb: Novint Falcon firmware not loaded: run 'fissure device firmware --file F' first");
  }
  std::fprintf(stderr, "homing: pull the grip all the way out, then push it all the way in …\n");
  if (!usb.driver->home([](std::uint8_t mask) { std::fprintf(stderr, "  arms homed: 0x%x\n", mask); })) {
    throw CommandError(std::string("--device usb: homing failed: ") + usb.driver->error());
  }
  return usb;
}

}  // namespace fissure::app
