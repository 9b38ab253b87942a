#pragma once
// `fissure bench mesh --json FILE [--quick]`: mesh import load time against mesh size.
#include "commands.hpp"

namespace fissure::app {

void register_bench_mesh(CommandTree& tree);

}  // namespace fissure::app
