#pragma once
// `fissure bench tissue --json FILE [--quick]`: issue 24's FEM validation table and step cost.
#include "commands.hpp"

namespace fissure::app {

void register_bench_tissue(CommandTree& tree);

}  // namespace fissure::app
