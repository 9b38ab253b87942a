#pragma once
// `fissure bench collision --json FILE [--quick]` (bench_collision.cpp).
#include "commands.hpp"

namespace fissure::app {
void register_bench_collision(CommandTree& tree);
}
