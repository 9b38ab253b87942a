#pragma once
// `fissure run SCENE`: the one-command session (SimFalcon or the USB Falcon + rt_core +
// host_sim in one process), real time or --lockstep. See session_runner.hpp.
#include "commands.hpp"

namespace fissure::app {

void register_run(CommandTree& tree);

}  // namespace fissure::app
