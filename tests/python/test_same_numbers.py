"""The bindings give the C++ API's numbers: the same lockstep runs through Python and through C++
(the library called directly by host_reference, or the `fissure` command line) agree bit for bit."""
import json
import subprocess

import numpy as np
import pytest

import fissure


def _reference(host_reference, *args):
    out = subprocess.run([host_reference, *args], check=True, capture_output=True, text=True).stdout
    lines = {}
    for line in out.splitlines():
        tag, *values = line.split()
        lines.setdefault(tag, []).append(values)
    return lines


def _hex_rows(rows):
    return [[float.fromhex(v) for v in row] for row in rows]


# clamp-vessel-lift: the in-solver response with tool friction (by step 1800 the
# jaws grip and lift).
@pytest.mark.parametrize("scene_name,method,steps", [("spatula-sphere", "paired", 450), ("clamp-sphere", "paired", 1300),
                                                     ("spatula-sphere", "bullet", 500), ("clamp-vessel-lift", "paired", 1800)])
def test_host_steps_bit_for_bit(host_reference, scene_name, method, steps):
    settle_s = 0.2
    ref = _reference(host_reference, "host", scene_name, method, str(settle_s), str(steps))
    sim = fissure.HostSimulation(fissure.Scene.load(scene_name, check_plausible=False), method=method)
    sim.settle(settle_s)
    forces, parts, frictions, scalars = [], [], [], []
    for i in range(steps):
        pose, gap = sim.scripted_target()
        r = sim.step(pose, jaw_gap=gap)
        scalars.append([i, r.time_s, r.contact_count, r.crossed_nodes, r.penetration_m])
        forces.append(list(r.force))
        parts.extend(r.part_forces.tolist())
        frictions.extend(r.part_friction_forces.tolist())
        np.testing.assert_array_equal(r.friction_force, r.part_friction_forces.sum(axis=0))
    ref_scalars = [[int(s[0]), float.fromhex(s[1]), int(s[2]), int(s[3]), float.fromhex(s[4])] for s in ref["step"]]
    assert scalars == ref_scalars
    assert forces == _hex_rows(ref["force"])
    assert parts == _hex_rows(ref["part"])
    assert frictions == _hex_rows(ref["friction"])
    if sim.scene.friction_static_ratio > 0.0:
        assert max(float(np.linalg.norm(f)) for f in frictions) > 0.1, "the jaws must hold by friction to compare it"
    assert sim.node_positions().tolist() == _hex_rows(ref["node"])
    assert max(s[2] for s in scalars) > 0, "the run must reach contact to compare anything"


def test_kinematics_bit_for_bit(host_reference):
    ref = _reference(host_reference, "kinematics")
    points = np.array([[0.01 * i, 0.01 * j, 0.125 + 0.005 * (i + j)] for i in range(-2, 3) for j in range(-2, 3)])
    theta = fissure.ik(points)
    assert theta.tolist() == _hex_rows(ref["ik"])
    assert fissure.jacobian(points).reshape(-1, 3).tolist() == _hex_rows(ref["jac"])
    # fk warm-starts each row from the previous one, from the workspace centre: as the reference does.
    assert fissure.fk(theta).tolist() == _hex_rows(ref["fk"])


# Summary figures of a lockstep session that do not depend on the machine's speed.
DETERMINISTIC_SUMMARY_KEYS = ("ticks", "host_steps", "crossed_nodes_max", "faults", "overruns", "force_max_n", "energy_j",
                              "tool_reseats", "soft_volume_ratio_min", "proxy_age_ms")


def test_session_matches_the_command_line(fissure_bin, tmp_path):
    options = ["--lockstep", "--duration", "0.8", "--settle", "0.3", "--rate", "1000", "--host-rate", "500", "--no-plot", "--quiet"]
    cli_dir, py_dir = tmp_path / "cli", tmp_path / "py"
    subprocess.run([fissure_bin, "run", "spatula-sphere", *options, "--out", str(cli_dir)], check=True, capture_output=True)
    result = fissure.run_session("spatula-sphere", lockstep=True, duration_s=0.8, settle_s=0.3, rt_rate=1000.0, host_rate=500.0,
                                 out_dir=py_dir)
    assert (py_dir / "trace.csv").read_bytes() == (cli_dir / "trace.csv").read_bytes()
    cli_summary = json.loads((cli_dir / "summary.json").read_text())
    for key in DETERMINISTIC_SUMMARY_KEYS:
        assert result.summary[key] == cli_summary[key], key
    # The arrays are the trace's columns, one row per rt tick.
    trace = result.trace
    assert list(trace) == list(fissure.TRACE_COLUMNS)
    assert trace["tick"].dtype == np.int64 and trace["force_n"].dtype == np.float64
    assert len(trace["time_s"]) == result.summary["ticks"] > 0
    assert trace["force_n"].max() == pytest.approx(result.summary["force_max_n"], rel=1e-5)
    assert trace["host_force_n"].max() > 0.1, "the session must reach contact"


def test_a_recorded_session_replays_to_the_same_trace(tmp_path):
    recording = tmp_path / "session.frec"
    first = fissure.run_session("spatula-sphere", lockstep=True, duration_s=0.5, settle_s=0.3, out_dir=tmp_path / "recorded",
                                record=recording)
    assert recording.stat().st_size > 0
    again = fissure.run_session("spatula-sphere", lockstep=True, settle_s=0.3, out_dir=tmp_path / "replayed", replay=recording)
    assert (tmp_path / "replayed" / "trace.csv").read_bytes() == (tmp_path / "recorded" / "trace.csv").read_bytes()
    assert again.summary["ticks"] == first.summary["ticks"] > 0


def test_a_missing_recording_is_a_session_error(tmp_path):
    with pytest.raises(fissure.SessionError) as error:
        fissure.run_session("spatula-sphere", lockstep=True, settle_s=0.3, replay=tmp_path / "none.frec")
    assert "none.frec" in str(error.value)


def test_stress_case_matches_the_command_line(fissure_bin, tmp_path):
    case = fissure.stress_case_names()[0]
    report_path = tmp_path / "stress.json"
    subprocess.run([fissure_bin, "stress", "--case", case, "--jobs", "1", "--json", str(report_path)], check=True, capture_output=True)
    cli = json.loads(report_path.read_text())
    py = fissure.stress(cases=[case], jobs=1)
    assert set(py) == set(cli)
    for key in ("base_seed", "failed", "known_failures", "profile", "energy_bound_j", "recovery_bound_s"):
        assert py[key] == cli[key], key
    assert len(py["cases"]) == 1
    cli_row, py_row = cli["cases"][0], py["cases"][0]
    assert py_row["name"] == case and py_row["ticks"] > 0
    assert set(py_row) == set(cli_row)
    for key in cli_row:
        if key != "wall_s":  # the only wall-clock figure of a lockstep case
            assert py_row[key] == cli_row[key], key


def _without_wall_times(value):
    """The benchmark's JSON without its machine block and wall-clock figures (keys wall_s)."""
    if isinstance(value, dict):
        return {k: _without_wall_times(v) for k, v in value.items() if k not in ("machine", "wall_s")}
    if isinstance(value, list):
        return [_without_wall_times(v) for v in value]
    return value


def test_grasp_bench_matches_the_command_line(fissure_bin, tmp_path):
    json_path = tmp_path / "grasp.json"
    subprocess.run([fissure_bin, "bench", "grasp", "--quick", "--json", str(json_path)], check=True, capture_output=True)
    cli = json.loads(json_path.read_text())
    py = fissure.bench_grasp(quick=True)
    assert _without_wall_times(py) == _without_wall_times(cli)
    assert {c["name"] for c in py["checks"]} == {c["name"] for c in cli["checks"]} and len(py["checks"]) >= 4
