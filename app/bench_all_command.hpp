#pragma once
// `fissure bench all --out DIR [--quick] [--docs DOCS_DIR]`: runs every benchmark (each as a
// child `fissure` process, so one crashing benchmark cannot take the others down and its failure
// is reported), writes their JSON into DIR, then the PNG plots and DIR/report.md through
// tools/report/make_report.py (eval/bench_all.hpp).
#include "commands.hpp"

namespace fissure::app {
void register_bench_all(CommandTree& tree);
}
