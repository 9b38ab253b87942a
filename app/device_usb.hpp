#pragma once
// `fissure device probe | firmware | home`: the real Novint Falcon over USB (libusb).
#include "commands.hpp"

namespace fissure::app {

void register_device_usb(CommandTree& tree);

}  // namespace fissure::app
