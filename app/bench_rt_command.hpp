#pragma once
// `fissure bench rt --json FILE [--seconds N]`: rt_core tick time, SCHED_FIFO wake-up latency
// against cyclictest, and the Z-width table against the Colgate–Schenkel bound.
#include "commands.hpp"

namespace fissure::app {
void register_bench_rt(CommandTree& tree);
}
