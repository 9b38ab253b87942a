#pragma once
// `fissure bench proxy --json FILE`: rendered force vs an every-tick-proxy oracle over host rates.
#include "commands.hpp"

namespace fissure::app {

void register_bench_proxy(CommandTree& tree);

}  // namespace fissure::app
