"""Fissure from Python: scenes, the host simulation, sessions, benchmarks and Falcon kinematics.

Built by the normal CMake build into build/python; use it with ``PYTHONPATH=build/python``
and Debian's python3 (the one toolchain/setup.sh installs NumPy and matplotlib for)::

    import fissure
    sim = fissure.HostSimulation(fissure.Scene.load("spatula-sphere"))
    sim.settle(1.0)
    for i in range(500):                          # the tool down at 5 cm/s [m, world]
        r = sim.step([0.0, 0.12 - 0.05e-3 * i, 0.0])
    print(r.force, r.contact_count, r.crossed_nodes)  # force on the tool [N, world]

Units are SI (m, s, N, rad) and every array says its frame: world = Bullet's (y up), tool =
the tool's own (thin axis y), device = the Falcon's (libnifalcon's: x right, y up, z towards
the user). Arrays of points are (N, 3) float64; faces are (F, 3) int32.

What is here:
  Scene.load / Scene.from_toml      a scene (errors: SceneError with .file, .line, .field)
  HostSimulation                    settle, step (force, per-jaw normal and friction), contacts,
                                    crossed nodes, node arrays; contact_response 'after_step' / 'in_solver'
  run_session                       a `fissure run` session: trace arrays + summary dict
  bench_collision, bench_grasp, bench_kinematics, bench_mesh, bench_pareto, bench_proxy,
  bench_rt, bench_tissue, bench_view,
  hil_latency, stress              the benchmarks / stress harness: the dict their JSON holds
  run_plunge_hold, plunge_tools     one cell of the tunnelling sweep
  fk, ik, jacobian, in_workspace    Falcon kinematics (one point or a batch)
"""
import os as _os
import sys as _sys

from . import _paths

try:
    import numpy as _numpy  # noqa: F401  (the compiled module needs it; say so plainly when it is missing)
except ImportError as _error:
    raise ImportError(f"fissure needs NumPy, which {_sys.executable} does not have; the module was built for "
                      f"{_paths.PYTHON_EXECUTABLE} (toolchain/setup.sh installs python3-numpy for it)") from _error

# Scene names ("spatula-sphere") and the session plot script resolve from any working directory.
_os.environ.setdefault("FISSURE_SCENES_DIR", _paths.SCENES_DIR)
_os.environ.setdefault("FISSURE_TOOLS_DIR", _paths.TOOLS_DIR)

from ._fissure import (  # noqa: E402  (the environment above must be set first)
    INSIDE_TOLERANCE_M,
    WORKSPACE_CENTRE_DEVICE_M,
    WORKSPACE_RADIUS_M,
    EvalError,
    HostSimulation,
    Scene,
    SceneError,
    SessionError,
    StepResult,
    ToolPose,
    fk,
    ik,
    in_workspace,
    jacobian,
    plunge_scene,
    plunge_tools,
    run_plunge_hold,
    stress_case_names,
)
from .evaluation import (  # noqa: E402
    bench_collision,
    bench_grasp,
    bench_kinematics,
    bench_mesh,
    bench_pareto,
    bench_proxy,
    bench_rt,
    bench_tissue,
    bench_view,
    hil_latency,
    stress,
)
from .session import SessionResult, TRACE_COLUMNS, read_trace, run_session  # noqa: E402

__all__ = [
    "INSIDE_TOLERANCE_M", "WORKSPACE_CENTRE_DEVICE_M", "WORKSPACE_RADIUS_M",
    "EvalError", "SceneError", "SessionError",
    "HostSimulation", "Scene", "StepResult", "ToolPose",
    "fk", "ik", "in_workspace", "jacobian",
    "plunge_scene", "plunge_tools", "run_plunge_hold",
    "bench_collision", "bench_grasp", "bench_kinematics", "bench_mesh", "bench_pareto", "bench_proxy", "bench_rt",
    "bench_tissue", "bench_view",
    "hil_latency", "stress", "stress_case_names",
    "SessionResult", "TRACE_COLUMNS", "read_trace", "run_session",
]
