#pragma once
// `fissure bench grasp --json FILE [--quick]`: issue 23's grasp table (lift, slip, pull-out against grip).
#include "commands.hpp"

namespace fissure::app {

void register_bench_grasp(CommandTree& tree);

}  // namespace fissure::app
