"""run_session: one `fissure run` session (session::run_session) from Python.

The session writes what the command line writes (trace.csv, summary.json, optionally
session.png); this module reads the trace into NumPy arrays and the summary into a dict. The
trace's values are therefore exactly the CSV's (the precision the CSV prints: docs/session.md);
a lockstep run gives the same trace and deterministic summary figures as
``fissure run SCENE --lockstep`` with the same options.
"""
from __future__ import annotations

import dataclasses
import json
import os
import shutil
import tempfile
from typing import Dict, Optional, Union

import numpy as np

from . import _fissure

#: Columns of trace.csv (one row per rt tick) and their units; integer columns are int64.
TRACE_COLUMNS = {
    "time_s": "s since the first tick",
    "tick": "rt tick number (int)",
    "tool_x_world_m": "m, world", "tool_y_world_m": "m, world", "tool_z_world_m": "m, world",
    "jaw_closing_m": "m (clamp)",
    "force_x_device_n": "N, device frame", "force_y_device_n": "N, device frame", "force_z_device_n": "N, device frame",
    "force_n": "N, |commanded device force|",
    "contact_force_n": "N, |proxy force| before passivity and safety",
    "penetration_m": "m, deepest proxy penetration rt_core evaluated",
    "patches_in_contact": "count (int)",
    "proxy_age_ms": "ms",
    "proxy_sequence": "int",
    "energy_j": "J, passivity observer",
    "fade_gain": "1", "ramp_gain": "1",
    "fault_bits": "RtFaultBits (int)",
    "overruns": "count (int)",
    "host_time_s": "s, host simulated time of the newest host status",
    "host_force_n": "N", "host_contacts": "count (int)", "host_crossed_nodes": "count (int)",
    "host_penetration_m": "m",
    "host_jaw_gap_m": "m, the jaw gap the host applied (clamp; 0 otherwise)",
    "host_jaw_a_normal_n": "N, |normal (Hunt-Crossley) force| on jaw A (other tools: on the tool)",
    "host_jaw_a_friction_n": "N, |friction force| on jaw A (other tools: on the tool)",
    "host_jaw_b_normal_n": "N, |normal force| on jaw B (clamp; 0 otherwise)",
    "host_jaw_b_friction_n": "N, |friction force| on jaw B (clamp; 0 otherwise)",
    "friction_n": "N, |friction share of the proxy force| rt_core rendered (device frame, faded)",
    "parts_sliding": "count (int): tool parts whose friction cone slides",
}
_INT_COLUMNS = {"tick", "patches_in_contact", "proxy_sequence", "fault_bits", "overruns", "host_contacts", "host_crossed_nodes",
                "parts_sliding"}


def read_trace(path: Union[str, os.PathLike]) -> Dict[str, np.ndarray]:
    """A session's trace.csv as {column: (T,) array}, T = rt ticks (TRACE_COLUMNS gives the units)."""
    with open(path, encoding="ascii") as f:
        names = f.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    if data.shape[0] == 0:
        data = np.zeros((0, len(names)))
    return {name: (data[:, i].astype(np.int64) if name in _INT_COLUMNS else data[:, i].copy()) for i, name in enumerate(names)}


@dataclasses.dataclass
class SessionResult:
    """What a session produced: trace {column: (T,) array}, summary (summary.json as a dict) and,
    when out_dir was given, the files' paths (None otherwise: they were in a removed temporary dir)."""

    trace: Dict[str, np.ndarray]
    summary: dict
    trace_path: Optional[str] = None
    summary_path: Optional[str] = None
    plot_path: Optional[str] = None


def run_session(scene, lockstep: bool = True, device: str = "sim", host_rate: Optional[float] = None,
                rt_rate: float = 1000.0, method: Optional[str] = None, duration_s: Optional[float] = None,
                settle_s: float = 1.0, out_dir: Optional[Union[str, os.PathLike]] = None, plot: bool = False,
                passivity_controller: bool = True, status_line: bool = False,
                record: Optional[Union[str, os.PathLike]] = None,
                replay: Optional[Union[str, os.PathLike]] = None) -> SessionResult:
    """Runs one session: device (SimFalcon playing the scene's hand script, or the USB Falcon) +
    rt_core + the host simulation, as ``fissure run`` does.

    scene: a Scene, or a scene name / path (Scene.load). lockstep: simulated time, deterministic,
    as fast as the CPU allows (False: real time, SCHED_FIFO when allowed). device: 'sim' or 'usb'.
    host_rate [Hz]: host step rate (None: the scene's time step). rt_rate [Hz]: rt tick rate.
    method: 'paired' or 'ray' overrides the scene's collision method (a session builds its proxy from
    the method's contacts, so 'bullet' is refused with SessionError). duration_s [s]: None = the hand
    script's length. settle_s [s]: soft body settling before the session. out_dir: keep trace.csv,
    summary.json (and session.png with plot=True) there; None: a temporary directory, removed.
    record: write every device exchange to this device recording (``fissure run --record``,
    docs/session.md "Device recordings"). replay: the device answers from this recording instead
    of SimFalcon (``--replay``); a lockstep replay reproduces the recorded session's trace.
    Raises SessionError (set-up failures, a bad recording), SceneError.
    """
    from ._fissure import Scene  # noqa: PLC0415  (import cycle: the package imports this module)

    if not isinstance(scene, Scene):
        scene = Scene.load(os.fspath(scene))
    temporary = out_dir is None
    directory = tempfile.mkdtemp(prefix="fissure-session-") if temporary else os.fspath(out_dir)
    try:
        outcome = _fissure._run_session(
            scene, directory, lockstep, device, 0.0 if host_rate is None else float(host_rate), float(rt_rate), method,
            0.0 if duration_s is None else float(duration_s), float(settle_s), plot, passivity_controller, status_line,
            "" if record is None else os.fspath(record), "" if replay is None else os.fspath(replay))
        result = SessionResult(trace=read_trace(outcome["trace_path"]), summary=json.loads(outcome["summary_json"]))
        if not temporary:
            result.trace_path = outcome["trace_path"]
            result.summary_path = outcome["summary_path"]
            result.plot_path = outcome["plot_path"] or None
        return result
    finally:
        if temporary:
            shutil.rmtree(directory, ignore_errors=True)
