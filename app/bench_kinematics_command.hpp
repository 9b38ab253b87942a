#pragma once
// `fissure bench kinematics --json FILE`: FK/IK/Jacobian run time against error.
#include "commands.hpp"

namespace fissure::app {
void register_bench_kinematics(CommandTree& tree);
}
