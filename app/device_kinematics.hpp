#pragma once
// `fissure device kinematics --ik X Y Z | --fk E1 E2 E3`: check a Falcon's kinematics by hand.
#include "commands.hpp"

namespace fissure::app {
void register_device_kinematics(CommandTree& tree);
}
