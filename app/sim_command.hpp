#pragma once
// `fissure sim SCENE [--method paired|ray|bullet] [--seconds S] [--json FILE] [--csv FILE]`
// and `fissure sim --write-meshes DIR` (sim_command.cpp).
#include "commands.hpp"

namespace fissure::app {
void register_sim(CommandTree& tree);
}
