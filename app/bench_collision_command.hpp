#pragma once
// `fissure bench collision --json FILE [--quick]` (eval/bench_collision.hpp).
#include "commands.hpp"

namespace fissure::app {
void register_bench_collision(CommandTree& tree);
}
