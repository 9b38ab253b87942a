"""The benchmarks and the stress harness: each runs the library function its `fissure` command
runs and returns the dict the command's JSON file holds (json.loads of the same JSON text, so the
figures are the command's to the last digit). They print their tables to stdout as they run."""
from __future__ import annotations

import json
from typing import Optional, Sequence

from . import _fissure


def bench_collision(quick: bool = False, full: bool = False, only: Optional[Sequence[str]] = None,
                    contact_response: str = "after_step", in_solver_friction: bool = True) -> dict:
    """`fissure bench collision`: tunnelling sweep, levering and clamp-release cells, force–indentation,
    mesh convergence, cost vs mesh. only: parts to run ('sweep', 'cells', 'indentation', 'scaling'; None: all).
    quick: CI-sized. contact_response: 'after_step' or 'in_solver' (`--contact-response`); in_solver_friction:
    the in-solver cells' tool friction 0.5 / 0.4 (True) or none (`--in-solver-friction on|off`)."""
    return json.loads(_fissure._bench_collision(quick, full, list(only or []), contact_response, in_solver_friction))


def bench_grasp(quick: bool = False) -> dict:
    """`fissure bench grasp`: clamp lift with the shipped friction and at mu 0.05, release delay, pull-out force
    against grip force, and the drag rt_core renders; 'checks' holds each target with its value and bound."""
    return json.loads(_fissure._bench_grasp(quick))


def bench_mesh(quick: bool = False) -> dict:
    """`fissure bench mesh`: load time of tool meshes (OBJ, STL), soft-body surface meshes and tetrahedral
    meshes against their size. quick: without the ~362k-triangle rows."""
    return json.loads(_fissure._bench_mesh(quick))


def bench_tissue(quick: bool = False) -> dict:
    """`fissure bench tissue`: Bullet's FEM against analytic anchors (cube compression, Sneddon punch,
    cantilever) and the step cost against node count. quick: the two coarser resolutions only."""
    return json.loads(_fissure._bench_tissue(quick))


def bench_kinematics(samples: int = 20000, repeats: int = 5, seed: int = 2024) -> dict:
    """`fissure bench kinematics`: FK/IK/Jacobian cost and FK iterations on a hand trajectory."""
    return json.loads(_fissure._bench_kinematics(samples, repeats, seed))


def bench_pareto(scene: str = "spatula-sphere", quick: bool = False, repeats: int = 2) -> dict:
    """`fissure bench pareto`: accuracy against step time over the tool's node spacing."""
    return json.loads(_fissure._bench_pareto(scene, quick, repeats))


def bench_proxy(scene: str = "spatula-sphere", rt_rate_hz: float = 2000.0,
                host_rates_hz: Sequence[float] = (1000.0, 500.0, 250.0, 100.0, 50.0), duration_s: float = 0.0,
                settle_s: float = 1.0, trace_dir: str = "") -> dict:
    """`fissure bench proxy`: rendered-force error at each host rate against an every-tick-proxy oracle on
    the same device trajectory, and the host CPU time per simulated second (rows[i]['host_cpu_s_per_s']).
    duration_s: 0 = the hand script's length. Each host rate must divide rt_rate_hz."""
    return json.loads(_fissure._bench_proxy(scene, rt_rate_hz, [float(r) for r in host_rates_hz], duration_s, settle_s, trace_dir))


def bench_rt(seconds: float = 30.0, enforce_rt: bool = True, priority: int = 80, skip_sched_fifo: bool = False) -> dict:
    """`fissure bench rt`: rt_core tick time, SCHED_FIFO wake-up latency against cyclictest, Z-width.
    enforce_rt=False runs best effort when SCHED_FIFO cannot be had; skip_sched_fifo leaves part 2 out."""
    return json.loads(_fissure._bench_rt(seconds, enforce_rt, priority, skip_sched_fifo))


def bench_view(scene: str = "spatula-sphere", repeats: int = 3, out_dir: str = "out/bench-view") -> dict:
    """`fissure bench view`: what the view (live window / PNG frames) costs a session."""
    return json.loads(_fissure._bench_view(scene, repeats, out_dir))


def hil_latency(device: str = "sim", transport: str = "inproc", scene: str = "spatula-sphere", seconds: float = 10.0,
                rate_hz: float = 1000.0, settle_s: float = 1.0) -> dict:
    """`fissure hil latency`: device-to-force latency distributions over a transport (inproc, udp:HOST:PORT, can:IFACE)."""
    return json.loads(_fissure._hil_latency(device, transport, scene, seconds, rate_hz, settle_s))


def stress(cases: Optional[Sequence[str]] = None, profile: str = "ci", seed: int = 7, jobs: int = 1) -> dict:
    """`fissure stress`: the fault-injection harness; the report `fissure stress --json` writes (rows, failed, ...).
    cases: names from stress_case_names() (None: all). jobs: cases side by side in child processes (1: all in
    this process; 0: one per core)."""
    return json.loads(_fissure._stress(list(cases) if cases is not None else None, profile, seed, jobs))
