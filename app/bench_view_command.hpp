#pragma once
#include "commands.hpp"

namespace fissure::app {
/// `fissure bench view`: what drawing the scene costs the host step.
void register_bench_view(CommandTree& tree);
}  // namespace fissure::app
