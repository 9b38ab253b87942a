#pragma once
// `fissure stress [--profile ci|full] [--seed S] [--json FILE] [--case NAME]`: the numerical
// stability stress harness of issue 7 (stress_cases.hpp). Lockstep, one report row per case;
// exit code 1 when any case fails, with the command that reproduces it.
#include "commands.hpp"

namespace fissure::app {
void register_stress(CommandTree& tree);
}
