#pragma once
// `fissure bench pareto --json FILE [--scene S] [--quick]`: host step time against host force
// error over the two host knobs no other benchmark sweeps — tool node spacing (coarse → fine)
// and Bullet sub-steps per host step (the report's Pareto plots (b) and (c)).
#include "commands.hpp"

namespace fissure::app {
void register_bench_pareto(CommandTree& tree);
}
