#!/usr/bin/python3
"""Turn the JSON of `fissure bench all` into PNG plots and a Markdown report.

usage: make_report.py DIR [--md FILE] [--images DIR]

DIR holds what `fissure bench all --out DIR` wrote: kinematics.json, rt.json, collision.json,
collision_in_solver.json, collision_in_solver_frictionless.json, proxy.json, pareto.json, view.json, stress.json, mesh.json and bench_all.json (which children ran, their
exit codes and wall times). --md (default DIR/report.md) is the report; --images (default DIR)
receives the PNGs, linked from the report by relative paths, so a report written to
docs/benchmarks.md with --images docs/images/bench works from docs/.

Every figure stands beside its target with "met" or "MISSED" (targets.py says where each target
comes from). A benchmark whose JSON is missing or unreadable is reported as such, never skipped
silently. Uses only the standard library and matplotlib (Debian's python3-matplotlib).
"""
import argparse
import json
import math
import os
import shutil
import statistics
import sys

import matplotlib

matplotlib.use("Agg")  # headless: CI and SSH sessions have no display
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from targets import IN_SOLVER_VARIANTS, MET, MISSED, NOT_CHECKED, Target, evaluate_all  # noqa: E402

REGENERATE = "build/bin/fissure bench all --out out/bench --docs docs --stress-full"

BENCHMARKS = ["kinematics", "rt", "collision", "collision_in_solver", "collision_in_solver_frictionless", "proxy", "pareto", "view",
              "stress", "stress_full", "mesh", "grasp", "tissue"]
# `fissure render` children of bench all: one PNG frame each of the 10 m/s plunge.
PLUNGE_FRAMES = {"plunge_bullet": "plunge-bullet", "plunge_paired": "plunge-paired"}


def load_inputs(directory):
    data, problems = {}, {}
    for name in BENCHMARKS + ["bench_all"]:
        path = os.path.join(directory, name + ".json")
        if not os.path.exists(path):
            problems[name] = "no " + name + ".json"
            continue
        try:
            with open(path) as f:
                data[name] = json.load(f)
        except (OSError, ValueError) as e:
            problems[name] = f"{name}.json unreadable: {e}"
    return data, problems


# ---------------------------------------------------------------- formatting helpers


def fmt(value, digits=3):
    if value is None:
        return "—"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value) or math.isinf(value):
            return str(value)
        if value != 0 and (abs(value) >= 1e5 or abs(value) < 1e-3):
            return f"{value:.{digits - 1}e}"
        return f"{value:.{digits}g}" if abs(value) < 1000 else f"{value:.0f}"
    return str(value)


def cell_text(value):
    # A "|" inside a cell (|F|, |ΔF|) would split the Markdown table.
    return str(value).replace("|", "\\|").replace("\n", " ")


def table(header, rows):
    out = ["| " + " | ".join(cell_text(h) for h in header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    for row in rows:
        out.append("| " + " | ".join(cell_text(c) for c in row) + " |")
    return "\n".join(out) + "\n"


def status_text(status):
    return {MET: "met", MISSED: "**MISSED**", NOT_CHECKED: "not checked"}[status]


def targets_table(targets):
    if not targets:
        return ""
    rows = [[t.description, t.measured, status_text(t.status), t.source] for t in targets]
    return table(["target", "measured", "status", "from"], rows)


class Report:
    def __init__(self, md_path, image_dir):
        self.md_path = md_path
        self.image_dir = image_dir
        self.lines = []
        self.images = []

    def add(self, text=""):
        self.lines.append(text)

    def figure(self, fig, name, caption):
        path = os.path.join(self.image_dir, name)
        fig.tight_layout()
        fig.savefig(path, dpi=110)
        plt.close(fig)
        self.images.append(path)
        rel = os.path.relpath(path, os.path.dirname(os.path.abspath(self.md_path)))
        self.add(f"![{caption}]({rel.replace(os.sep, '/')})")
        self.add("")

    def text(self):
        return "\n".join(self.lines) + "\n"


# ---------------------------------------------------------------- Pareto helper


def pareto_front(points):
    """Indices of the non-dominated points (minimise both time and error)."""
    front = []
    for i, (t, e) in enumerate(points):
        dominated = any((t2 <= t and e2 <= e) and (t2 < t or e2 < e) for j, (t2, e2) in enumerate(points) if j != i)
        if not dominated:
            front.append(i)
    return sorted(front, key=lambda i: points[i][0])


def pareto_plot(ax, series, xlabel, ylabel, logx=False, logy=False):
    """series: list of (label, [(time, error, point_label, is_reference)], marker)."""
    for label, points, marker in series:
        xs = [p[0] for p in points]
        ys = [p[1] for p in points]
        line = ax.plot(xs, ys, marker=marker, ls=":", lw=0.8, label=label)[0]
        colour = line.get_color()
        front = pareto_front([(p[0], p[1]) for p in points])
        if len(front) > 1:
            ax.plot([xs[i] for i in front], [ys[i] for i in front], ls="-", lw=2.0, alpha=0.35, color=colour)
        for x, y, text, reference in points:
            ax.annotate(text + (" (ref)" if reference else ""), (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7,
                        color=colour)
    if logx:
        ax.set_xscale("log")
    if logy:
        ax.set_yscale("log")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize="small")


# ---------------------------------------------------------------- sections


def section_header(report, data, problems, targets):
    bench_all = data.get("bench_all", {})
    machine = None
    for name in ["bench_all"] + BENCHMARKS:
        if name in data and isinstance(data[name].get("machine"), dict):
            machine = data[name]["machine"]
            break
    report.add("# Fissure benchmarks: run time against error")
    report.add("")
    report.add("Generated by `fissure bench all` (issue 7). **Regenerate with one command** from the repository root after "
               "building:")
    report.add("")
    report.add("```")
    report.add(REGENERATE)
    report.add("```")
    report.add("")
    report.add("(`--quick` gives short runs for development; the committed report is a full run. `--report-only` remakes the "
               "plots and this file from the JSON already in `--out`.)")
    report.add("")
    if bench_all:
        report.add(f"This run: `{bench_all.get('invocation', '?')}`, started {bench_all.get('started_utc', '?')}, "
                   f"{fmt(bench_all.get('wall_s'))} s wall in all"
                   + (" — **a --quick run: short, not the figures to quote**" if bench_all.get("quick") else "") + ".")
        source = bench_all.get("source") or {}
        if source.get("commit"):
            modified = source.get("modified_tracked_files", 0)
            report.add(f"Source tree at run time: commit `{source['commit']}`"
                       + (f" **with {modified} modified tracked files** (uncommitted work of the day is in these figures)"
                          if modified else " (clean)") + ".")
        if bench_all.get("loadavg_at_end"):
            report.add(f"Load average at the end (`/proc/loadavg`): `{bench_all['loadavg_at_end']}` — timings on a shared "
                       "VM; ratios measured within one run are the robust figures.")
        report.add("")
    report.add("## Machine")
    report.add("")
    if machine:
        report.add(table(["nproc", "CPU", "kernel", "arch", "compiler", "assertions"],
                         [[fmt(machine.get("nproc")), machine.get("cpu_model", "?"), machine.get("kernel", "?"),
                           machine.get("arch", "?"), machine.get("compiler", "?"), fmt(machine.get("assertions"))]]))
    else:
        report.add("No JSON carried a `machine` object.\n")
    report.add("## Targets at a glance")
    report.add("")
    met = sum(1 for t in targets if t.status == MET)
    missed = sum(1 for t in targets if t.status == MISSED)
    unchecked = sum(1 for t in targets if t.status == NOT_CHECKED)
    report.add(f"**{met} met, {missed} missed, {unchecked} not checked** of {len(targets)} targets. Each section below shows "
               "its figures beside these targets.")
    report.add("")
    rows = [[t.section, t.description, t.measured, status_text(t.status)] for t in targets]
    report.add(table(["section", "target", "measured", "status"], rows))
    report.add("## The benchmark runs")
    report.add("")
    children = bench_all.get("children", {}) if isinstance(bench_all.get("children"), dict) else {}
    rows = []
    for name in BENCHMARKS + list(PLUNGE_FRAMES):
        child = children.get(name)
        have = name in data or (name in PLUNGE_FRAMES and plunge_frame(data, name) is not None)
        if child is None:
            rows.append([name, "—", "not run by bench all", "—", "yes" if have else "no"])
            continue
        if child.get("ok"):
            outcome = "ok"
        elif child.get("signal"):
            outcome = f"**FAILED**: signal {child['signal']}"
        elif child.get("error"):
            outcome = f"**FAILED**: {child['error']}"
        else:
            outcome = f"**FAILED**: exit {child.get('exit_code')}"
        rows.append([name, f"`{child.get('command', '?')}`", outcome, fmt(child.get("wall_s")),
                     "yes" if have else "**no**"])
    report.add(table(["benchmark", "command", "outcome", "wall s", "output"], rows))
    for name, problem in problems.items():
        if name != "bench_all":
            report.add(f"* `{name}`: {problem} — its section says so.")
    report.add("")


def plunge_frame(data, name):
    """The frame a plunge child rendered, or None (not rendered, or its child failed)."""
    path = os.path.join(data.get("_directory", ""), PLUNGE_FRAMES[name], "frame_000000.png")
    child = data.get("bench_all", {}).get("children", {}).get(name)
    if not os.path.isfile(path) or (child is not None and not child.get("ok")):
        return None
    return path


def missing(report, name, problems):
    report.add(f"*No data: {problems.get(name, name + '.json missing')}.*")
    report.add("")


def section_pareto(report, data, problems, targets):
    report.add("## Run time against error (Pareto plots)")
    report.add("")
    report.add("Each plot puts the cost of a knob setting against the error it leaves; the thick translucent line joins the "
               "Pareto-optimal settings (nothing else is both faster and more accurate).")
    report.add("")
    # (a) host rate
    report.add("### (a) Host rate — `fissure bench proxy`")
    report.add("")
    proxy = data.get("proxy")
    if proxy:
        rows = proxy["rows"]
        oracle = proxy.get("oracle", {})
        pts = [(r["host_cpu_s_per_s"], r["rms_error_pct"], f"{r['host_hz']:.0f} Hz", False) for r in rows]
        if oracle:
            pts.append((oracle.get("host_cpu_s_per_s", 0.0), 0.0, f"{oracle.get('host_hz', 0):.0f} Hz", True))
        fig, ax = plt.subplots(figsize=(6.5, 4.2))
        pareto_plot(ax, [("RMS force error", pts, "o"),
                         ("peak force error", [(r["host_cpu_s_per_s"], r["peak_error_pct"], f"{r['host_hz']:.0f} Hz", False)
                                               for r in rows], "s")],
                    "host CPU time per simulated second [s/s]", "force error [% of the oracle's peak |F|]")
        ax.set_title(f"host rate: rendered force vs every-tick oracle ({proxy.get('scene', '?')}, rt {fmt(proxy.get('rt_rate_hz'))} Hz)",
                     fontsize=9)
        report.figure(fig, "pareto_host_rate.png", "host rate: host CPU against force error")
        report.add(f"Oracle: the host refreshes the proxy every rt tick ({fmt(oracle.get('host_hz'))} Hz), peak |F| "
                   f"{fmt(oracle.get('peak_force_n'))} N; force compared: {proxy.get('force_compared', '?')}.")
        report.add("")
        report.add(table(["host Hz", "RMS error %", "peak error %", "max |ΔF|/tick N", "host CPU s/s", "host step median ms",
                          "crossed nodes"],
                         [[fmt(r["host_hz"]), fmt(r["rms_error_pct"]), fmt(r["peak_error_pct"]), fmt(r["max_dforce_n"]),
                           fmt(r["host_cpu_s_per_s"]), fmt(r.get("host_step_ms", {}).get("median")),
                           fmt(r.get("crossed_nodes_max"))] for r in rows]))
        force_position = proxy.get("force_position")
        if force_position:
            report.add("")
            report.add(f"rt_core evaluates the contact at a sub-count force position (weight of the previous reading "
                       f"{fmt(force_position.get('previous_weight'))}): added lag {fmt(force_position.get('added_lag_s', 0.0) * 1e6)} µs "
                       f"at the rt rate, every row.")
            report.add("")  # a table after a paragraph line needs a blank line to render as a table
        report.add(targets_table([t for t in targets if t.section == "proxy"]))
    else:
        missing(report, "proxy", problems)
    pareto = data.get("pareto")
    for key, title, knob_label, unit_fn in [
            ("node_spacing", "(b) Tool node resolution — `fissure bench pareto`", "node spacing",
             lambda v: f"{v * 1e3:g} mm"),
            ("substeps", "(c) Host sub-steps — `fissure bench pareto`", "sub-steps", lambda v: f"{v:g}")]:
        report.add("### " + title)
        report.add("")
        if not pareto:
            missing(report, "pareto", problems)
            continue
        rows = pareto[key]
        knob = "node_spacing_m" if key == "node_spacing" else "substeps"
        pts = [(r["host_step_in_contact_us"]["median"], r["rms_error_pct"], unit_fn(r[knob]), r.get("reference", False))
               for r in rows]
        fig, ax = plt.subplots(figsize=(6.5, 4.2))
        pareto_plot(ax, [("RMS force error", pts, "o"),
                         ("peak force error", [(r["host_step_in_contact_us"]["median"], r["peak_error_pct"], unit_fn(r[knob]),
                                                r.get("reference", False)) for r in rows], "s")],
                    "host step time in contact, median [µs]", "host force error [% of the reference's peak |F|]",
                    logx=key == "node_spacing")
        ax.set_title(f"{knob_label}: host step time vs force error ({pareto.get('scene', '?')}, scripted press-and-hold)",
                     fontsize=9)
        report.figure(fig, f"pareto_{key}.png", f"{knob_label}: host step time against force error")
        if key == "node_spacing":
            report.add(f"The scene's tool node spacing swept coarse → fine at {fmt(pareto.get('scene_substeps_count'))} sub-step(s); "
                       "the finest is the reference. ")
        else:
            report.add(f"Sub-steps per {fmt(pareto.get('host_step_s', 0) * 1e3)} ms host step at the scene's node spacing "
                       f"({fmt(pareto.get('scene_node_spacing_m', 0) * 1e3)} mm); the most sub-steps is the reference.")
        others = [r for r in rows if not r.get("reference")]
        # Below this the force equals the reference's to floating-point rounding.
        rounding_pct = 1e-9
        same = [r for r in others if r["peak_error_pct"] < rounding_pct]
        if same:
            report.add(f"**{len(same)} of {len(others)} {knob_label} settings give the reference's force at every step to "
                       f"rounding** (peak error < {rounding_pct:g} %: "
                       + ", ".join(unit_fn(r[knob]) for r in same) + "): there the knob changes only the cost.")
        report.add(f"Same scripted trajectory ({fmt(pareto.get('trajectory_s'))} s after {fmt(pareto.get('settle_s'))} s settling) "
                   f"for every row, {pareto.get('repeats', '?')} repeat(s) per row.")
        report.add("")
        report.add(table([knob_label, "tool nodes", "step median µs", "step p99 µs", "in-contact median µs", "RMS error %",
                          "peak error %", "crossed nodes", "max penetration mm", "hold |F| start N", "hold drift %",
                          "deterministic"],
                         [[unit_fn(r[knob]) + (" (ref)" if r.get("reference") else ""), fmt(r.get("tool_nodes")),
                           fmt(r["host_step_us"]["median"]), fmt(r["host_step_us"]["p99"]),
                           fmt(r["host_step_in_contact_us"]["median"]), fmt(r["rms_error_pct"]), fmt(r["peak_error_pct"]),
                           fmt(r["crossed_nodes_max"]), fmt(r["max_penetration_m"] * 1e3), fmt(r.get("hold_force_start_n")),
                           fmt(r.get("hold_drift_pct")), fmt(r.get("deterministic"))]
                          for r in rows]))
        report.add(targets_table([t for t in targets if t.section == "pareto " + key]))
    # (d) FK tolerance
    report.add("### (d) Forward-kinematics tolerance — `fissure bench kinematics`")
    report.add("")
    kin = data.get("kinematics")
    if kin:
        table_rows = kin["tolerance_table"]
        series = []
        for start, marker in (("warm", "o"), ("cold", "s")):
            pts = [(r["median_ns"], max(r["error_max_m"], 1e-16), f"{r['tolerance_rad']:.0e}", False)
                   for r in table_rows if r["start"] == start]
            if pts:
                series.append((f"{start} start (max error)", pts, marker))
        base = kin.get("baseline_libnifalcon")
        if base:
            series.append(("libnifalcon scheme", [(base["median_ns"], base["error_max_m"], "0.01 rad", False)], "x"))
        fig, ax = plt.subplots(figsize=(6.5, 4.2))
        pareto_plot(ax, series, "time per FK solve, median [ns]", "position error, max [m]", logx=True, logy=True)
        ax.axhline(1e-6, color="grey", ls="--", lw=0.8)
        ax.axvline(500, color="grey", ls="--", lw=0.8)
        ax.set_title("FK tolerance [rad]: time vs error on a 1 kHz hand trajectory", fontsize=9)
        report.figure(fig, "pareto_fk_tolerance.png", "FK tolerance: time against error")
        report.add("Dashed lines: the target (≤ 1 µm in ≤ 500 ns). " + kin.get("method", {}).get("timing", ""))
        report.add("")
        report.add(table(["start", "tolerance rad", "iterations mean", "iterations max", "median ns", "p99 ns", "error median m",
                          "error max m"],
                         [[r["start"], f"{r['tolerance_rad']:.0e}", fmt(r["iterations_mean"]), fmt(r["iterations_max"]),
                           fmt(r["median_ns"]), fmt(r["p99_ns"]), fmt(r["error_median_m"]), fmt(r["error_max_m"])]
                          for r in table_rows]
                         + ([["libnifalcon", "0.01", fmt(base["iterations_mean"]), fmt(base["iterations_max"]),
                              fmt(base["median_ns"]), fmt(base["p99_ns"]), fmt(base["error_median_m"]), fmt(base["error_max_m"])]]
                            if base else [])))
        report.add(f"IK {fmt(kin.get('ik_median_ns'))} ns, Jacobian {fmt(kin.get('jacobian_median_ns'))} ns, warm FK + J "
                   f"{fmt(kin.get('fk_warm_with_jacobian_median_ns'))} ns (medians); Jacobian vs central differences "
                   f"{fmt(kin.get('jacobian_max_rel_error'))} relative.")
        report.add("")
        report.add(targets_table([t for t in targets if t.section == "kinematics"]))
    else:
        missing(report, "kinematics", problems)


def section_tunnelling(report, data, problems, targets):
    report.add("## Tunnelling against Bullet's own collision — `fissure bench collision`")
    report.add("")
    col = data.get("collision")
    if not col:
        missing(report, "collision", problems)
        return
    sweep = col["sweep"]
    speeds = sorted({r["speed_m_s"] for r in sweep})
    tools = list(dict.fromkeys(r["tool"] for r in sweep))
    methods = list(dict.fromkeys(r["method"] for r in sweep))
    cell = {(r["tool"], r["method"], r["speed_m_s"]): r for r in sweep}
    fig, axes = plt.subplots(1, len(methods), figsize=(3.6 * len(methods), 3.4), sharey=True)
    if len(methods) == 1:
        axes = [axes]
    vmax = max(1, max(r["crossed_nodes"] for r in sweep))
    for ax, method in zip(axes, methods):
        grid = [[cell.get((t, method, v), {}).get("crossed_nodes", float("nan")) for v in speeds] for t in tools]
        image = ax.imshow(grid, cmap="Reds", vmin=0, vmax=vmax, aspect="auto")
        for i, row in enumerate(grid):
            for j, value in enumerate(row):
                ax.text(j, i, "" if value != value else str(int(value)), ha="center", va="center", fontsize=8,
                        color="white" if value == value and value > 0.6 * vmax else "black")
        ax.set_xticks(range(len(speeds)))
        ax.set_xticklabels([f"{v:g}" for v in speeds], fontsize=7)
        ax.set_yticks(range(len(tools)))
        ax.set_yticklabels(tools, fontsize=8)
        ax.set_xlabel("tool speed [m/s]")
        ax.set_title(method, fontsize=9)
    fig.colorbar(image, ax=list(axes), shrink=0.8, label="crossed nodes")
    fig.suptitle("crossed soft nodes after a plunge and hold (must be 0)", fontsize=9)
    path_caption = "tunnelling sweep: crossed nodes per tool, method and speed"
    # tight_layout does not know colorbars spanning axes; keep the default layout.
    name = "tunnelling.png"
    path = os.path.join(report.image_dir, name)
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    report.images.append(path)
    rel = os.path.relpath(path, os.path.dirname(os.path.abspath(report.md_path)))
    report.add(f"![{path_caption}]({rel.replace(os.sep, '/')})")
    report.add("")
    frames = {name: plunge_frame(data, name) for name in PLUNGE_FRAMES}
    if all(frames.values()):
        links = []
        for name, source in frames.items():
            target = os.path.join(report.image_dir, name.replace("plunge_", "plunge_10mps_") + ".png")
            if os.path.abspath(source) != os.path.abspath(target):
                shutil.copyfile(source, target)
            report.images.append(target)
            rel = os.path.relpath(target, os.path.dirname(os.path.abspath(report.md_path))).replace(os.sep, "/")
            links.append(f"![{name.replace('_', ' ')} at 10 m/s]({rel})")
        report.add(" ".join(links))
        report.add("")
        command = data.get("bench_all", {}).get("children", {}).get("plunge_paired", {}).get("command", "fissure render")
        report.add("The spatula plunged at 10 m/s from 15 mm above to 20 mm below the sphere's top, frame 10 ms after the start: "
                   f"Bullet's collision (left) against ours (right); the overlay gives crossed nodes and force (`{command}`).")
    else:
        report.add("*No 10 m/s plunge frames: the `plunge_bullet` / `plunge_paired` renders were not run or failed.*")
    report.add("")
    report.add("Cells: crossed nodes / max penetration into the tool [mm] / median step [µs]. `bullet` is Bullet's own SDF_RS "
               "soft-rigid collision set up fairly (fine voxel, mm margin, kKHR 1); `ray` is the paper's rays without "
               "pairing; `paired` is ours.")
    report.add("")
    def tool_method_table(cell_text_of):
        # One row per tool and method, one column per speed; cell_text_of(row) gives the text, or
        # None for "—" (as does a missing cell).
        rows = []
        for t in tools:
            for m in methods:
                texts = [None if cell.get((t, m, v)) is None else cell_text_of(cell[(t, m, v)]) for v in speeds]
                rows.append([t, m] + ["—" if x is None else x for x in texts])
        return table(["tool", "method"] + [f"{v:g} m/s" for v in speeds], rows)

    report.add(tool_method_table(lambda r: f"{r['crossed_nodes']}/{r['max_penetration_m'] * 1e3:.2f}/{r['step_median_us']:.0f}"))
    jitter_rows = [r for r in sweep if r["method"] == "paired"]
    report.add("Hold after the plunge (paired): force jitter (residual std / mean about a fitted line) and drift; "
               "`lost` = no contact left in the hold.")
    report.add("")
    report.add(table(["tool"] + [f"{v:g} m/s" for v in speeds],
                     [[t] + [("lost" if not (cell.get((t, "paired", v)) or {}).get("hold_in_contact")
                              else f"{100 * cell[(t, 'paired', v)]['force_jitter']:.2f}% / "
                                   f"{100 * (cell[(t, 'paired', v)].get('force_drift') or 0):+.1f}%")
                             if (t, "paired", v) in cell else "—" for v in speeds]
                      for t in tools if any(r["tool"] == t for r in jitter_rows)]))
    if any("hold_max_cut_triangles" in r for r in sweep):
        steps = next((r.get("hold_steps") for r in sweep if r.get("hold_steps")), "?")
        report.add("Soft triangles cut by the tool during the hold: reaching more than 0.1 mm into its volume, most on one step / "
                   f"steps with any, of {steps}. The penetration above is measured at the nodes; a coarse triangle can pass "
                   "into a thin tool between its nodes, which only this count shows.")
        report.add("")
        report.add(tool_method_table(lambda r: None if r.get("hold_max_cut_triangles") is None else
                                     f"{r['hold_max_cut_triangles']} / {r['hold_steps_with_cut_triangles']}"))
    report.add(targets_table([t for t in targets if t.section == "collision sweep"]))

    fine = col.get("sweep_fine") or []
    if fine:
        faces = (col.get("sweep_fine_body") or {}).get("faces", "?")
        fcell = {(r["tool"], r["speed_m_s"]): r for r in fine}
        ftools = list(dict.fromkeys(r["tool"] for r in fine))
        fspeeds = sorted({r["speed_m_s"] for r in fine})

        def fine_text(r):
            if not r.get("hold_in_contact"):
                return f"lost, cut {r['hold_max_cut_triangles']}/{r['hold_steps_with_cut_triangles']}"
            return (f"{r['crossed_nodes']} / {100 * r['force_jitter']:.2f}% / {100 * r['force_step_noise']:.2f}% / "
                    f"{r['hold_max_cut_triangles']}·{r['hold_steps_with_cut_triangles']}")
        report.add(f"The same paired cells on a {faces}-face icosphere: crossed nodes / hold jitter / step noise / cut triangles "
                   "(most on a hold step · hold steps with any).")
        report.add("")
        report.add(table(["tool"] + [f"{v:g} m/s" for v in fspeeds],
                         [[t] + [fine_text(fcell[(t, v)]) if (t, v) in fcell else "—" for v in fspeeds] for t in ftools]))
    lever = col.get("lever") or []
    if lever:
        report.add("### Levering and clamp release (issue 22)")
        report.add("")
        report.add("Levering: the 1 mm blade inserted edge-first 20 mm at 0.1 m/s, turned 30° about its leading edge at 1 rad/s, "
                   "held 0.5 s. Cut triangles over every step of the cell (insert, turn, hold).")
        report.add("")
        report.add(table(["mesh faces", "method", "crossed", "pen mm", "cut max / steps", "F_hold N", "jitter", "step noise", "median step µs"],
                         [[r["faces"], r["method"], r["crossed_nodes"], f"{r['max_penetration_m'] * 1e3:.3f}",
                           f"{r['max_cut_triangles']} / {r['steps_with_cut_triangles']} of {r['steps']}", f"{r['hold_force_n']:.3f}",
                           "lost" if r.get("force_jitter") is None else f"{100 * r['force_jitter']:.2f} %",
                           "lost" if r.get("force_step_noise") is None else f"{100 * r['force_step_noise']:.2f} %",
                           f"{r['step_median_us']:.0f}"] for r in lever]))
    release = col.get("clamp_release") or []
    if release:
        grace = release[0].get("open_grace_steps", 5)
        report.add(f"Clamp release: clamp-sphere's script (close on the ball, hold, open fully) after the ball settled; the larger "
                   f"jaw's force from the {grace + 1}th fully open step on (target 0 N within 5 ms).")
        report.add("")
        report.add(table(["settled s", "method", "max F N", "open F N", "crossed", "cut max / steps"],
                         [[f"{r['settle_s']:g}", r["method"], f"{r['script_max_force_n']:.3f}", f"{r['open_force_max_n']:.4f}",
                           r["crossed_nodes"], f"{r['max_cut_triangles']} / {r['steps_with_cut_triangles']}"] for r in release]))
    if fine or lever or release:
        report.add(targets_table([t for t in targets if t.section == "contact"]))

    report.add("### Force–indentation and mesh convergence")
    report.add("")
    ind = col.get("indentation")
    conv = col.get("convergence")
    if ind:
        fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
        for key, label in (("slab_curve", f"flat slab (fitted n {fmt(ind.get('slab_fitted_n'))})"),
                           ("sphere_curve", f"sphere {ind.get('sphere_faces', '?')} faces (fitted n {fmt(ind.get('sphere_fitted_n'))})")):
            curve = ind.get(key) or []
            if curve:
                axes[0].plot([p["depth_m"] * 1e3 for p in curve], [p["force_n"] for p in curve], "o-", label=label)
        axes[0].set_xscale("log")
        axes[0].set_yscale("log")
        axes[0].set_xlabel("depth [mm]")
        axes[0].set_ylabel("force [N]")
        axes[0].set_title(f"force–indentation (configured n {fmt(ind.get('configured_n'))})", fontsize=9)
        axes[0].grid(True, which="both", alpha=0.3)
        axes[0].legend(fontsize="small")
        if conv:
            axes[1].plot([r["faces"] for r in conv], [r["force_at_depth_n"] for r in conv], "o-")
            axes[1].set_xscale("log")
            axes[1].set_xlabel("sphere faces")
            axes[1].set_ylabel(f"force at {fmt(conv[0].get('depth_m', 0) * 1e3)} mm [N]")
            axes[1].set_title("mesh convergence (area-weighted HC)", fontsize=9)
            axes[1].grid(True, which="both", alpha=0.3)
        report.figure(fig, "indentation.png", "force-indentation curves and mesh convergence")
        report.add(table(["specimen", "fitted exponent", "expected"],
                         [["flat slab (fixed contact set)", fmt(ind.get("slab_fitted_n"), 4), fmt(ind.get("configured_n"))],
                          [f"sphere, {ind.get('sphere_faces', '?')} faces", fmt(ind.get("sphere_fitted_n"), 4),
                           f"{fmt(ind.get('sphere_predicted_n'))} (rigid cap n+1; the soft shell also squashes as a whole)"]]))
    if conv:
        report.add(table(["faces", "force at depth N"], [[r["faces"], fmt(r["force_at_depth_n"], 4)] for r in conv]))
    report.add(targets_table([t for t in targets if t.section == "collision indentation"]))


def section_contact_in_solver(report, data, problems, targets):
    report.add("## Contact inside the solver — `fissure bench collision --contact-response in_solver`")
    report.add("")
    report.add("The paired response as constraints inside Bullet's position iterations (issue 22; `[simulation] contact_response = "
               "\"in_solver\"`, not yet the scenes' default). Its plunge and levering cells tie the ball's bottom cap to the "
               "ground (a bed); one run gives the tool's faces friction 0.5 / 0.4, the other none (`--in-solver-friction off`). "
               "The clamp-release cells are clamp-sphere's. Each cell: crossed nodes / hold jitter / step noise / cut triangles "
               "(most on a hold step · hold steps with any); the median paired step beside Bullet's own on the same cell.")
    report.add("")
    for name, variant in IN_SOLVER_VARIANTS.items():
        report.add(f"### {variant}")
        report.add("")
        col = data.get(name)
        if col is None:
            missing(report, name, problems)
            report.add(targets_table([t for t in targets if t.section == ("contact in_solver" if name == "collision_in_solver"
                                                                           else "contact in_solver frictionless")]))
            continue

        def cell_text(r):
            if not r.get("hold_in_contact"):
                return f"lost, cut {r['hold_max_cut_triangles']}·{r['hold_steps_with_cut_triangles']}"
            return (f"{r['crossed_nodes']} / {100 * r['force_jitter']:.2f}% / {100 * r['force_step_noise']:.2f}% / "
                    f"{r['hold_max_cut_triangles']}·{r['hold_steps_with_cut_triangles']}")
        for key, body in (("sweep", "sweep_body"), ("sweep_fine", "sweep_fine_body")):
            rows = [r for r in col.get(key) or [] if r["method"] == "paired"]
            if not rows:
                continue
            bullet = {(r["tool"], r["speed_m_s"]): r for r in col.get(key) or [] if r["method"] == "bullet"}
            cells = {(r["tool"], r["speed_m_s"]): r for r in rows}
            tools = list(dict.fromkeys(r["tool"] for r in rows))
            speeds = sorted({r["speed_m_s"] for r in rows})
            faces = (col.get(body) or {}).get("faces", "?")
            report.add(f"{faces} faces:")
            report.add("")
            table_rows = []
            for t in tools:
                steps = [cells[(t, v)]["step_median_us"] for v in speeds if (t, v) in cells]
                own = [bullet[(t, v)]["step_median_us"] for v in speeds if (t, v) in bullet]
                cost = f"{statistics.median(steps):.0f}" + (f" / {statistics.median(own):.0f}" if own else "")
                table_rows.append([t] + [cell_text(cells[(t, v)]) if (t, v) in cells else "—" for v in speeds] + [cost])
            report.add(table(["tool"] + [f"{v:g} m/s" for v in speeds] + ["step µs paired / bullet"], table_rows))
        lever = [r for r in col.get("lever") or [] if r["method"] == "paired"]
        release = [r for r in col.get("clamp_release") or [] if r["method"] == "paired"]
        if lever:
            report.add("Levering (the 1 mm blade turned 30° about its edge, held 0.5 s):")
            report.add("")
            report.add(table(["mesh faces", "crossed", "cut max / steps", "F_hold N", "jitter", "step noise"],
                             [[r["faces"], r["crossed_nodes"], f"{r['max_cut_triangles']} / {r['steps_with_cut_triangles']} of {r['steps']}",
                               f"{r['hold_force_n']:.3f}", "lost" if r.get("force_jitter") is None else f"{100 * r['force_jitter']:.3f} %",
                               "lost" if r.get("force_step_noise") is None else f"{100 * r['force_step_noise']:.3f} %"] for r in lever]))
        if release:
            report.add("Clamp release: " + ", ".join(f"settled {r['settle_s']:g} s → {r['open_force_max_n']:.4f} N open, "
                                                   f"cut {r['max_cut_triangles']}" for r in release) + ".")
            report.add("")
        section = "contact in_solver" if name == "collision_in_solver" else "contact in_solver frictionless"
        report.add(targets_table([t for t in targets if t.section == section]))


def section_scaling(report, data, problems, targets):
    report.add("## Cost against mesh size — `fissure bench collision`")
    report.add("")
    col = data.get("collision")
    if not col:
        missing(report, "collision", problems)
        return
    rows = col["scaling"]

    def case_of(r):
        return r.get("case", "same_press" if r["in_contact"] else "out")
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    for method, case, field, label, marker in [
            ("paired", "same_press", "step_median_us", "paired: whole step, same press", "o"),
            ("paired", "same_press", "collision_median_us", "paired: collision only, same press", "s"),
            ("paired", "same_contact", "collision_median_us", "paired: collision only, same contact", "D"),
            ("paired", "out", "collision_median_us", "paired: collision only, out of contact", "v"),
            ("bullet", "same_press", "step_median_us", "bullet: whole step, same press", "x"),
            ("bullet", "same_press", "collision_median_us", "bullet: collision only, same press", "+")]:
        pts = sorted((r["faces"], r[field]) for r in rows if r["method"] == method and case_of(r) == case)
        if pts:
            ax.plot([p[0] for p in pts], [max(p[1], 1e-3) for p in pts], marker=marker, label=label)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("soft sphere faces")
    ax.set_ylabel("median time per host step [µs]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize="small")
    ax.set_title("host step cost against mesh size (plate pressed into the sphere)", fontsize=9)
    report.figure(fig, "cost_vs_mesh.png", "cost against mesh size")
    report.add("128 faces is the paper's sphere (Bullet's ellipsoid); larger meshes are icospheres. `out` = 2 cm above the "
               "sphere; `same_press` = the same depth on every mesh (the contact set grows with the mesh); `same_contact` = "
               "the first depth with the same number of contacted triangles on every mesh.")
    report.add("")
    report.add(table(["method", "faces", "case", "depth mm", "contacted triangles", "step median µs", "step p99 µs",
                      "collision median µs", "collision µs per triangle"],
                     [[r["method"], r["faces"], case_of(r), fmt(r["depth_m"] * 1e3) if "depth_m" in r else "—",
                       fmt(r.get("contacted_triangles", r.get("contacts"))), fmt(r["step_median_us"]), fmt(r.get("step_p99_us")),
                       fmt(r["collision_median_us"]), fmt(r.get("collision_us_per_contacted_triangle"))] for r in rows]))
    report.add(targets_table([t for t in targets if t.section == "collision scaling"]))


def section_rt(report, data, problems, targets):
    report.add("## rt_core: tick time, wake-up latency against cyclictest — `fissure bench rt`")
    report.add("")
    rt = data.get("rt")
    if not rt:
        missing(report, "rt", problems)
        return
    tick = rt.get("tick_ns", {})
    rows = []
    for key in ("patches_1", "patches_8", "reference_workload"):
        if key in tick:
            d = tick[key]
            rows.append([key.replace("_", " "), fmt(d["median"]), fmt(d["p99"]), fmt(d["p999"]), fmt(d["max"]),
                         fmt(d.get("samples"))])
    report.add("Tick compute time (ns; `reference workload` is fixed arithmetic timed the same way on the same thread: the "
               "machine's own noise):")
    report.add("")
    report.add(table(["workload", "median", "p99", "p99.9", "max", "samples"], rows))
    wake = rt.get("wakeup_us", {})
    cyc = rt.get("cyclictest_us", {})
    rates = [k for k in ("1000hz", "4000hz") if isinstance(wake.get(k), dict)]
    if rates:
        fig, axes = plt.subplots(1, len(rates), figsize=(5 * len(rates), 3.8), sharey=True)
        if len(rates) == 1:
            axes = [axes]
        stats = ["median", "p99", "p999", "max"]
        for ax, key in zip(axes, rates):
            ours = [wake[key].get(s) or 0 for s in stats]
            theirs = [cyc.get(key, {}).get(s) or 0 for s in stats] if cyc.get(key, {}).get("available") else None
            xs = range(len(stats))
            ax.bar([x - 0.2 for x in xs], [max(v, 0.1) for v in ours], width=0.4, label="rt_core loop")
            if theirs:
                ax.bar([x + 0.2 for x in xs], [max(v, 0.1) for v in theirs], width=0.4, label="cyclictest")
            ax.set_xticks(list(xs))
            ax.set_xticklabels(["median", "p99", "p99.9", "max"])
            ax.set_yscale("log")
            ax.set_title(f"{key.replace('hz', ' Hz')}: {fmt(wake[key].get('overruns'))} overruns in {fmt(wake[key].get('ticks'))} ticks",
                         fontsize=9)
            ax.grid(True, axis="y", which="both", alpha=0.3)
            ax.legend(fontsize="small")
        axes[0].set_ylabel("wake-up latency [µs]")
        # Log-scale bars start at 0: give the axis an explicit floor so the smallest bar shows.
        smallest = min([wake[k].get(s) or 1.0 for k in rates for s in stats]
                       + [cyc.get(k, {}).get(s) or 1.0 for k in rates for s in stats if cyc.get(k, {}).get("available")])
        axes[0].set_ylim(bottom=max(0.1, smallest / 2.0))
        report.figure(fig, "rt_latency_vs_cyclictest.png", "rt wake-up latency against cyclictest")
        report.add(f"SCHED_FIFO runs of {fmt(rt.get('seconds'))} s per rate against SimFalcon; {rt.get('sched_fifo_mode', '')}.")
        report.add("")
        rows = []
        for key in rates:
            w = wake[key]
            c = cyc.get(key, {})
            rows.append([key, "rt_core", fmt(w["median"]), fmt(w["p99"]), fmt(w["p999"]), fmt(w["max"]), fmt(w.get("overruns")),
                         fmt(w.get("sched_fifo"))])
            if c.get("available"):
                rows.append([key, "cyclictest", fmt(c["median"]), fmt(c["p99"]), fmt(c["p999"]), fmt(c["max"]), "—", "yes"])
            else:
                rows.append([key, "cyclictest", "unavailable: " + str(c.get("reason", "?")), "", "", "", "", ""])
        report.add(table(["rate", "loop", "median µs", "p99 µs", "p99.9 µs", "max µs", "overruns", "SCHED_FIFO"], rows))
    else:
        report.add(f"*The SCHED_FIFO part was not run: {wake.get('skipped', 'no wakeup_us in rt.json')}.*")
        report.add("")
    report.add(targets_table([t for t in targets if t.section == "rt"]))

    report.add("## Z-width against tick rate — `fissure bench rt`")
    report.add("")
    z = rt.get("zwidth") or []
    if z:
        fig, ax = plt.subplots(figsize=(6.5, 4.2))
        rates_hz = [r["rate_hz"] for r in z]
        ax.plot(rates_hz, [r["colgate_bound_k_n_per_m"] for r in z], "k--", label="Colgate–Schenkel bound 2b/T")
        ax.plot(rates_hz, [r["k_max_passivity_off_n_per_m"] for r in z], "o-", label="K max, passivity controller off")
        ax.plot(rates_hz, [r["k_max_passivity_on_n_per_m"] for r in z], "s-", label="K max, passivity controller on")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("tick rate [Hz]")
        ax.set_ylabel("largest stable and passive stiffness [N/m]")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize="small")
        ax.set_title(f"Z-width against SimFalcon's damping b = {fmt(z[0].get('device_damping_n_s_per_m'))} N·s/m (lockstep)",
                     fontsize=9)
        report.figure(fig, "zwidth_vs_rate.png", "Z-width against tick rate")
        report.add(rt.get("zwidth_method", ""))
        report.add("")
        def first_failure(f):
            # Which criterion ended the grid: the next K was unstable, active, or held back.
            if not f:
                return "—"
            why = [w for w, ok in (("unstable", f.get("stable", True)), ("active", f.get("passive", True))) if not ok]
            if not f.get("renders", True):
                why.append(f"held back: {fmt(f.get('held_force_n'))} of {fmt(f.get('expected_force_n'))} N")
            return ", ".join(why) or "—"
        report.add(table(["rate Hz", "bound 2b/T N/m", "K max PC off N/m", "next K, PC off", "K max PC on N/m", "next K, PC on", "off / bound"],
                         [[fmt(r["rate_hz"]), fmt(r["colgate_bound_k_n_per_m"]), fmt(r["k_max_passivity_off_n_per_m"]),
                           first_failure(r.get("first_failure_off")), fmt(r["k_max_passivity_on_n_per_m"]),
                           first_failure(r.get("first_failure_on")), fmt(r["ratio_off_to_bound"])] for r in z]))
        held_back = [r for r in z if not (r.get("first_failure_on") or {}).get("renders", True)]
        if held_back:
            report.add("")
            report.add(f"With the passivity controller on, {len(held_back)} of {len(z)} rates end on a wall *held back*: "
                       "the observer's energy is above its reference after the impact, the controller's reduction is "
                       "full, and a hand at rest does no work that would let it relax, so a wall the hand has sunk into "
                       "stays near 0 N. Without the 'renders' criterion (session 5) that counted as stable and passive "
                       "(the session-4 report read 5.7–21.7 kN/m here). Not fixed; a drift-compensating controller is "
                       "the known remedy.")
            report.add("")
        report.add(targets_table([t for t in targets if t.section == "zwidth"]))


def stress_summary(report, name, data, problems, targets):
    """One stress run's summary: `stress` is the ci profile, `stress_full` the full one (≥ 1e6 rt ticks per case)."""
    stress = data.get(name)
    if not stress:
        missing(report, name, problems)
        if name == "stress_full":
            report.add("(The full profile runs with `fissure bench all --stress-full`, or alone with "
                       "`fissure stress --profile full --json stress_full.json`.)")
            report.add("")
        return
    cases = stress.get("cases", [])
    passed = sum(1 for c in cases if c.get("passed"))
    known = sum(1 for c in cases if not c.get("passed") and c.get("known_failure"))
    failed = sum(1 for c in cases if not c.get("passed") and not c.get("known_failure"))
    jobs = stress.get("jobs")
    report.add(f"Profile `{stress.get('profile', '?')}`, base seed {stress.get('base_seed', '?')}: {len(cases)} cases — "
               f"**{passed} passed, {failed} failed, {known} known failures** — in {fmt(stress.get('wall_s'))} s"
               + (f" ({jobs} cases at a time, each in its own process)" if jobs else "") + ". Checked on "
               f"every tick: finite, |F| within the limit, 0 crossed nodes, energy ≤ {fmt(stress.get('energy_bound_j'))} J, only "
               f"injected faults, recovery within {fmt(stress.get('recovery_bound_s'))} s.")
    report.add("")
    groups = {}
    for c in cases:
        g = groups.setdefault(c.get("group", "?"), [0, 0, 0])
        g[0 if c.get("passed") else (2 if c.get("known_failure") else 1)] += 1
    report.add(table(["group", "passed", "failed", "known failures"], [[g, v[0], v[1], v[2]] for g, v in groups.items()]))
    rows = []
    for c in cases:
        outcome = "pass" if c.get("passed") else ("KNOWN" if c.get("known_failure") else "**FAIL**")
        contact = c.get("contact_fraction")
        rows.append([c.get("name"), c.get("group"), outcome, fmt(c.get("ticks")), fmt(c.get("force_max_n")),
                     fmt(c.get("energy_max_j")), fmt(c.get("crossed_nodes_max")),
                     "—" if contact is None else f"{100 * contact:.0f}", c.get("faults_seen", ""),
                     f"{c.get('recoveries_done', 0)}/{c.get('recoveries_required', 0)}",
                     "; ".join(c.get("failures", []))[:160]])
    report.add(table(["case", "group", "outcome", "ticks", "|F| max N", "energy max J", "crossed", "contact %", "faults seen",
                      "recovered", "failures"], rows))
    report.add(targets_table([t for t in targets if t.section == name]))


def section_stress(report, data, problems, targets):
    report.add("## Stress summary — `fissure stress --profile ci`")
    report.add("")
    stress_summary(report, "stress", data, problems, targets)
    report.add("### The full profile — `fissure stress --profile full`")
    report.add("")
    stress_summary(report, "stress_full", data, problems, targets)


def section_view(report, data, problems, targets):
    report.add("## Viewer cost — `fissure bench view`")
    report.add("")
    view = data.get("view")
    if not view:
        missing(report, "view", problems)
        return
    report.add(f"`fissure run {view.get('scene', '?')}` in real time, {view.get('repeats', '?')} run(s) per row (median over "
               "runs): without a view, writing frames, and with the window when a display exists — host step and rt "
               "tick timings side by side, so any cost of the view shows up where it would hurt.")
    report.add("")

    def publish_median(r):
        # bench view ≥ 09fe51d writes capture_publish_us_median; older JSON had {median}.
        flat = r.get("capture_publish_us_median")
        return flat if flat is not None else r.get("capture_publish_us", {}).get("median")

    report.add(table(["configuration", "host step median µs", "host step p99 µs", "rt tick interval p99 µs",
                      "rt overruns", "publish median µs", "frames written", "frames dropped"],
                     [[r.get("configuration"), fmt(r.get("host_step_us", {}).get("median")),
                       fmt(r.get("host_step_us", {}).get("p99")), fmt(r.get("rt_tick_interval_us", {}).get("p99")),
                       fmt(r.get("overruns")), fmt(publish_median(r)),
                       fmt(r.get("frames_written")), fmt(r.get("frames_dropped"))] for r in view.get("rows", [])]))
    report.add(targets_table([t for t in targets if t.section == "view"]))


def section_mesh(report, data, problems, targets):
    report.add("## Mesh import — `fissure bench mesh`")
    report.add("")
    mesh = data.get("mesh")
    if not mesh:
        missing(report, "mesh", problems)
        return
    report.add("Load time of a convex tool mesh (read, the closed / manifold / outward / convex checks, the thin-tool "
               "nodes and pairs) and of a soft-body surface mesh, against the number of triangles"
               + (" (a --quick run: no 362k-triangle rows)." if mesh.get("quick") else "."))
    report.add("")
    report.add(table(["tool mesh", "format", "triangles", "read s", "check s", "nodes s", "load s"],
                     [[r.get("mesh"), r.get("format"), r.get("triangles"), fmt(r.get("read_s")), fmt(r.get("check_s")),
                       fmt(r.get("nodes_s")), fmt(r.get("load_s"))] for r in mesh.get("tool_meshes", [])]
                     + [[r.get("mesh"), r.get("format"), r.get("triangles"), fmt(r.get("read_s")), "—", "—", "—"]
                        for r in mesh.get("tool_meshes_stl", [])]
                     + [[r.get("mesh"), "tilted", r.get("triangles"), "—", fmt(r.get("check_s")), fmt(r.get("nodes_s")), "—"]
                        for r in mesh.get("tool_meshes_tilted", [])]))
    report.add("")
    report.add(table(["soft mesh", "format", "triangles", "read s", "build s"],
                     [[r.get("mesh"), r.get("format"), r.get("triangles"), fmt(r.get("read_s")), fmt(r.get("build_s"))]
                      for r in mesh.get("soft_meshes", [])]))
    report.add(targets_table([t for t in targets if t.section == "mesh"]))


def section_grasp(report, data, problems, targets):
    report.add("## Grasp, lift and pull-out with friction — `fissure bench grasp`")
    report.add("")
    grasp = data.get("grasp")
    if not grasp:
        missing(report, "grasp", problems)
        return
    report.add("The clamp closes on the soft vessel (`scenes/clamp-vessel-lift.toml`, contact inside the solver with "
               "Coulomb friction against each node's Hunt-Crossley force), lifts it 20 mm, holds 1 s, lowers and opens; "
               "the same at μ = 0.05; then the retraction scene's end-anchored vessel is pulled through the jaws at five "
               "grips" + (" (a --quick run: three grips, a shorter pull)." if grasp.get("quick") else "."))
    report.add("")
    rows = []
    for key, label in (("lift", "shipped μ"), ("lift_slippery", "μ 0.05")):
        r = grasp[key]
        rows.append([label, f"{r['friction_static_ratio']:.2f} / {r['friction_kinetic_ratio']:.2f}", fmt(1e3 * r["jaw_rise_m"]),
                     fmt(1e3 * r["centroid_rise_m"]), fmt(1e3 * r["hold_slide_max_m"]), fmt(r["hold_grip_n"]),
                     fmt(r["hold_friction_up_n"]), fmt(9.81 * r["vessel_mass_kg"]), fmt(1e3 * r["release_delay_s"]),
                     r["crossed_nodes_max"], r["cut_triangles_max"]])
    report.add(table(["lift", "μ static / kinetic", "jaws rose mm", "vessel rose mm", "max slide mm", "grip N / jaw",
                      "friction up N", "weight N", "0 N after clearing ms", "crossed", "cut"], rows))
    report.add("")
    pull = grasp["pull_out"]
    report.add(table(["jaw gap mm", "grip N / jaw", "pull-out N", "2μ·grip N", "peak N", "slid mm"],
                     [[fmt(1e3 * r["jaw_gap_m"]), fmt(r["grip_n"]), fmt(r["pull_out_n"]), fmt(2 * pull["friction_ratio"] * r["grip_n"]),
                       fmt(r["pull_peak_n"]), fmt(1e3 * r["slip_m"])] for r in pull["runs"]]))
    report.add("")
    report.add(f"Least-squares fit: pull-out = {fmt(pull['intercept_n'])} N + {fmt(pull['slope'])} × grip "
               f"(2μ = {fmt(2 * pull['friction_ratio'])}).")
    report.add("")
    drag = grasp.get("drag")
    if drag:
        report.add("Drag felt (`scenes/spatula-ball-drag.toml`, a lockstep session: SimFalcon's hand presses the spatula onto "
                   "the ball with ~2 N and slides it 20 mm at 5 cm/s; per rt tick the force commanded to the device is split "
                   "along the contact normal rt_core evaluated; medians over the ticks the tool slides):")
        report.add("")
        report.add(table(["host Hz", "slide ticks", "speed cm/s", "normal N", "tangential N", "tangential / normal (p10–p90)",
                          "μ_k", "host's own friction / normal", "cone sliding %", "max ΔF / tick N"],
                         [[fmt(r["host_rate_hz"]), r["slide_ticks"], fmt(100 * r["slide_speed_median_m_per_s"]), fmt(r["normal_median_n"]),
                           fmt(r["tangential_median_n"]), f"{r['ratio_median']:.4f} ({r['ratio_p10']:.3f}–{r['ratio_p90']:.3f})",
                           fmt(r["friction_kinetic_ratio"]),
                           f"{r['host_friction_median_n'] / r['host_normal_median_n']:.3f}" if r["host_normal_median_n"] > 0 else "-",
                           fmt(100 * r["sliding_tick_share"]), fmt(r["max_force_step_n"])] for r in drag]))
        report.add("")
    report.add(targets_table([t for t in targets if t.section == "grasp"]))


def section_tissue(report, data, problems, targets):
    report.add("## Tissue: FEM against analytic anchors — `fissure bench tissue`")
    report.add("")
    tissue = data.get("tissue")
    if not tissue:
        missing(report, "tissue", problems)
        return
    m = tissue["material"]
    report.add("Bullet's deformable world on structured tetrahedral meshes, each against its analytic anchor; the model is "
               "named per row (`corotated_smoothed`, the default: corotated linear elasticity with face-smoothed deviatoric and "
               "node-smoothed volumetric strain; `corotated_linear`: Bullet's own force, one strain per tetrahedron, on the same "
               "meshes for comparison; `neo_hookean`: Bullet's); tissue E = " + fmt(m["youngs_modulus_pa"]) + " Pa, ν = " + fmt(m["poisson_ratio"])
               + " unless named" + (" (a --quick run: coarse meshes only)." if tissue.get("quick") else ".")
               + " Wall time is the whole quasi-static run on this machine.")
    report.add("")
    def model(r):
        return r.get("model", "corotated_linear")
    rows = [["cube 20 mm, 5 % strain", model(r), f"{r['cells_per_edge']} cells / edge", r["nodes"], f"{fmt(r['force_n'])} N",
             f"E·A·ε = {fmt(r['expected_force_n'])} N", f"{100 * r['relative_error']:+.2f} %", fmt(r["wall_s"])] for r in tissue["cube"]]
    rows += [["flat punch a = 5 mm", model(r), f"{r['cells_per_radius']} cells / radius", r["nodes"], f"{fmt(r['slope_n_per_m'])} N/m",
              f"2aE/(1−ν²) = {fmt(r['expected_slope_n_per_m'])} N/m", f"{100 * r['relative_error']:+.2f} %", fmt(r["wall_s"])] for r in tissue["punch"]]
    rows += [["cantilever 100 × 10 × 10 mm, E 5 MPa", model(r), f"{r['cells_across']} cells across", r["nodes"], f"{fmt(1e3 * r['tip_deflection_m'])} mm",
              f"qL⁴/8EI = {fmt(1e3 * r['expected_deflection_m'])} mm", f"{100 * r['relative_error']:+.2f} %", fmt(r["wall_s"])] for r in tissue["cantilever"]]
    rows += [["vessel R 15 mm, wall 2 mm, on the ground", model(r), f"{r['cells_through']} × {r['cells_around']} × {r['cells_along']} cells", r["nodes"],
              f"ΔD_V {fmt(1e3 * r['vertical_change_m'])} mm, ovalisation {100 * r['ovalisation']:.2f} %",
              f"Roark ΔD_V = {fmt(1e3 * r['expected_vertical_change_m'])} mm", f"{100 * r['vertical_relative_error']:+.2f} %", fmt(r["wall_s"])]
             for r in tissue.get("vessel", [])]
    report.add(table(["specimen", "model", "mesh", "nodes", "measured", "analytic", "error", "wall s"], rows))
    report.add("")
    report.add("Cost of one 1 ms host step (a 40 mm tissue cube resting on the ground):")
    report.add("")
    report.add(table(["model", "stepping", "nodes", "tetrahedra", "substeps", "median ms", "p95 ms", "highest host rate Hz"],
                     [[model(r), r["stepping"], r["nodes"], r["tetrahedra"], r["substeps"], fmt(r["median_ms"]), fmt(r["p95_ms"]),
                       fmt(r["highest_rate_hz"])] for r in tissue["step_cost"]]))
    report.add(targets_table([t for t in targets if t.section == "tissue"]))


SECTIONS = [section_pareto, section_tunnelling, section_contact_in_solver, section_scaling, section_rt, section_stress, section_view, section_mesh,
            section_grasp, section_tissue]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("directory", help="the --out directory of fissure bench all")
    parser.add_argument("--md", help="report file (default DIR/report.md)")
    parser.add_argument("--images", help="directory for the PNGs (default DIR)")
    args = parser.parse_args()
    md = args.md or os.path.join(args.directory, "report.md")
    images = args.images or args.directory
    os.makedirs(images, exist_ok=True)
    os.makedirs(os.path.dirname(os.path.abspath(md)), exist_ok=True)
    data, problems = load_inputs(args.directory)
    data["_directory"] = args.directory
    targets = evaluate_all(data)
    report = Report(md, images)
    section_header(report, data, problems, targets)
    broken = []
    for section in SECTIONS:
        try:
            section(report, data, problems, targets)
        except (KeyError, TypeError, ValueError, IndexError, AttributeError) as e:
            # A benchmark changed its JSON: say so in the report and on stderr, keep the rest.
            name = section.__name__.replace("section_", "")
            message = f"{type(e).__name__}: {e}"
            broken.append(f"{name}: {message}")
            report.add(f"*Section `{name}` could not be made from the JSON ({message}).*")
            report.add("")
            plt.close("all")
    with open(md, "w") as f:
        f.write(report.text())
    print(f"make_report.py: wrote {md} and {len(report.images)} plots in {images}")
    for b in broken:
        print(f"make_report.py: section {b}", file=sys.stderr)
    return 1 if broken else 0


if __name__ == "__main__":
    sys.exit(main())
