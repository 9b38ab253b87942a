#pragma once
// Runs stress cases side by side, each in its own forked child process. The full profile is
// 43 cases of 10⁶ lockstep ticks (16–30 min on one core): cases are independent and
// deterministic from their own seeds, so N processes give the same rows N times sooner. A
// process per case (not a thread) also keeps one case's crash — a segfault deep in Bullet, an
// abort — from ending the run: it becomes a failed row naming the signal, and the rest still run.
#include <cstdint>
#include <functional>
#include <vector>

#include "fissure/eval/stress_cases.hpp"

namespace fissure::eval {

/// Runs `cases` with at most `jobs` child processes at a time; returns the rows in case order
/// and calls `on_row` in case order as soon as a row and every row before it are in.
/// Throws EvalError when a child process cannot be started.
std::vector<StressRow> run_stress_cases_forked(const std::vector<StressCase>& cases, StressProfile profile, std::uint64_t base_seed,
                                               unsigned jobs, const std::function<void(const StressRow&)>& on_row);

}  // namespace fissure::eval
