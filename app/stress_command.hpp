#pragma once
// `fissure stress [--profile ci|full] [--seed S] [--json FILE] [--case NAME] [--jobs N]`: the numerical
// stability stress harness (eval/stress_cases.hpp). Lockstep, one report row per case;
// exit code 1 when any case fails, with the command that reproduces it. Cases run side by side
// in child processes (eval/stress_parallel.hpp), one per core unless --jobs says otherwise.
#include "commands.hpp"

namespace fissure::app {
void register_stress(CommandTree& tree);
}
