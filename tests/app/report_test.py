#!/usr/bin/python3
"""ctest app.bench_report: tools/report/make_report.py on the fixed JSON of tests/app/report_fixture/.

The fixture is a small but complete `fissure bench all --out DIR` directory (trimmed from a real
--quick run, pareto rows hand-made) in which some targets are met and some are missed (the proxy
errors, 5 crossed nodes at one pareto node spacing, a failed stress case) and one benchmark child
(view) failed. Checks: the report has every section issue 7 requires, every image it links
exists and is a PNG, the machine is named, met targets say "met", missed ones say "MISSED" (never
"met"), the failed child is reported, a benchmark whose JSON is missing is reported as such
instead of vanishing, the 10 m/s plunge frames are embedded, and a failed render's stale frame
is not.
usage: report_test.py TOOLS_REPORT_DIR FIXTURE_DIR
Exit 77 (ctest SKIP_RETURN_CODE) when matplotlib is missing.
"""
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile

try:
    import matplotlib  # noqa: F401
except ImportError:
    print("SKIP: this python3 has no matplotlib (install Debian's python3-matplotlib); the report generator needs it")
    sys.exit(77)

REQUIRED_SECTIONS = [
    "## Machine",
    "## Targets at a glance",
    "## The benchmark runs",
    "### (a) Host rate",
    "### (b) Tool node resolution",
    "### (c) Host sub-steps",
    "### (d) Forward-kinematics tolerance",
    "## Tunnelling against Bullet's own collision",
    "## Cost against mesh size",
    "## rt_core: tick time, wake-up latency against cyclictest",
    "## Z-width against tick rate",
    "## Stress summary",
    "## Mesh import",
    "## Tissue: FEM against analytic anchors",
]

failures = []


def check(condition, message):
    if not condition:
        failures.append(message)


def target_row(report, description):
    """The 'Targets at a glance' row of a target (section | target | measured | status)."""
    for line in report.splitlines():
        cells = [c.strip() for c in re.split(r"(?<!\\)\|", line)]
        if len(cells) == 6 and cells[2] == description:
            return cells
    return None


def run(script, directory, md, images):
    return subprocess.run([sys.executable, script, directory, "--md", md, "--images", images], capture_output=True, text=True)


def main():
    tools_dir, fixture = sys.argv[1], sys.argv[2]
    script = os.path.join(tools_dir, "make_report.py")
    with tempfile.TemporaryDirectory() as tmp:
        # Written as docs/benchmarks.md with images in docs/images/bench: links must be relative to docs/.
        md = os.path.join(tmp, "docs", "benchmarks.md")
        images = os.path.join(tmp, "docs", "images", "bench")
        # The fixture plus the two 10 m/s plunge frames bench all renders (tiny stand-in PNGs).
        full = os.path.join(tmp, "full")
        shutil.copytree(fixture, full)
        import matplotlib.pyplot as plt
        for method in ("bullet", "paired"):
            os.makedirs(os.path.join(full, "plunge-" + method))
            fig = plt.figure(figsize=(1, 1))
            fig.savefig(os.path.join(full, "plunge-" + method, "frame_000000.png"))
            plt.close(fig)
        # The in-solver run with the tool's friction (synthetic: one cell over the jitter target, no
        # cut, the clamp lets go); the frictionless run is left out, so its section says so.
        def cell(method, speed, jitter):
            return {"method": method, "tool": "plate_4mm", "speed_m_s": speed, "crossed_nodes": 0, "hold_in_contact": True,
                    "force_jitter": jitter, "force_step_noise": 0.001, "hold_max_cut_triangles": 0,
                    "hold_steps_with_cut_triangles": 0, "step_median_us": 50.0 if method == "paired" else 25.0}
        in_solver = {"contact_response": "in_solver", "in_solver_tool_friction": True,
                     "sweep_body": {"faces": 128}, "sweep_fine_body": {"faces": 1280},
                     "sweep": [cell("bullet", 0.1, 0.5), cell("paired", 0.1, 0.002), cell("bullet", 10.0, 0.5), cell("paired", 10.0, 0.02)],
                     "sweep_fine": [cell("paired", 0.1, 0.001), cell("paired", 10.0, 0.001)],
                     "lever": [{"method": "paired", "faces": f, "crossed_nodes": 0, "max_cut_triangles": 0, "steps_with_cut_triangles": 0,
                                "steps": 900, "hold_force_n": 19.4, "force_jitter": 0.0001, "force_step_noise": 0.00002} for f in (128, 1280)],
                     "clamp_release": [{"method": "paired", "settle_s": t, "open_force_max_n": 0.0, "max_cut_triangles": 0}
                                       for t in (0.1, 0.2, 0.3, 0.5)]}
        json.dump(in_solver, open(os.path.join(full, "collision_in_solver.json"), "w"))
        result = run(script, full, md, images)
        check(result.returncode == 0, f"make_report.py exited {result.returncode}: {result.stderr.strip()}")
        if not os.path.exists(md):
            print("\n".join(failures))
            return 1
        report = open(md).read()
        for section in REQUIRED_SECTIONS:
            check(any(line.startswith(section) for line in report.splitlines()), f"section missing: {section}")
        check("could not be made" not in report and "could not evaluate" not in report,
              "a section or target could not be made from the fixture JSON")
        check("bench all --out out/bench --docs docs" in report, "the regeneration command is not in the report")
        check("added lag 25 µs" in report, "the force position's added lag (proxy.json force_position) is not in the report")
        check("Intel(R) Xeon(R) Processor @ 2.10GHz" in report and "PREEMPT_DYNAMIC" in report,
              "the machine (CPU model, kernel) is not in the report")
        links = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", report)
        check(len(links) >= 8, f"expected at least 8 plots, found {len(links)}")
        for link in links:
            check(not os.path.isabs(link), f"image link is absolute: {link}")
            path = os.path.join(os.path.dirname(md), link)
            check(os.path.isfile(path), f"linked image does not exist: {link}")
            if os.path.isfile(path):
                with open(path, "rb") as f:
                    check(f.read(8) == b"\x89PNG\r\n\x1a\n", f"{link} is not a PNG")
        for name in ["pareto_host_rate.png", "pareto_node_spacing.png", "pareto_substeps.png", "pareto_fk_tolerance.png",
                     "tunnelling.png", "rt_latency_vs_cyclictest.png", "cost_vs_mesh.png", "zwidth_vs_rate.png",
                     "plunge_10mps_bullet.png", "plunge_10mps_paired.png"]:
            check(any(link.endswith("/" + name) for link in links), f"plot not linked: {name}")

        expectations = {
            # description: expected status (the fixture's numbers decide it)
            "RMS force error ≤ 0.5 % at 1 kHz host rate": "**MISSED**",          # 9.15 %
            "RMS force error ≤ 2 % at 100 Hz host rate": "**MISSED**",           # 15.9 %
            "0 crossed nodes at every node spacing setting": "**MISSED**",       # 5 at 6 mm
            "0 crossed nodes at every sub-steps setting": "met",
            "warm FK median ≤ 500 ns": "met",                                    # 330 ns
            "paired: 0 crossed nodes in every sweep cell": "met",
            "tick median ≤ 1 µs (8 patches)": "met",                             # 654 ns
            "tick p99.9 ≤ 5 µs (8 patches)": "**MISSED**",                       # 5777 ns
            "zero overruns at 1 kHz over 30 s (idle machine)": "not checked",    # a 2 s run
            "no stress case fails (other than known failures)": "**MISSED**",    # one FAIL case
            "ci profile runs in under 5 minutes": "met",
            "full profile passes (every case, ≥ 1e6 rt ticks each)": "not checked",  # no stress_full.json
            # 41 160 → 361 600 triangles, 0.34 → 3.26 s: exponent 1.04
            "convex tool mesh load time grows at most as n log n (exponent ≤ 1.1 between the two largest meshes)": "met",
            # tissue.json (a full `fissure bench tissue` run): the bench's own checks, shown as judged
            "vessel ovalisation on the ground (finest)": "met",                  # 1.84 % (bound 10 %)
            "vessel flattening / Roark - 1 (finest)": "**MISSED**",              # -65.8 % (locking)
            "ms per step near 4,807 nodes": "**MISSED**",                        # 20.8 ms (bound 2 ms)
        }
        in_solver_expectations = {
            "in_solver, tool friction 0.5 / 0.4: paired: 0 triangles cut deeper than 0.1 mm (both sweep meshes over the hold; levering and clamp cells over every step)": "met",
            "in_solver, tool friction 0.5 / 0.4: paired: hold jitter ≤ 1 % up to 10 m/s, ≤ 3 % at 20–50 m/s (both meshes)": "**MISSED**",  # 2 % at 10 m/s
            "in_solver, tool friction 0.5 / 0.4: an opened jaw carries 0 N within 5 ms at every settling time": "met",
            "in_solver, frictionless: paired: hold jitter ≤ 1 % up to 10 m/s, ≤ 3 % at 20–50 m/s (both meshes)": "not checked",
        }
        expectations.update(in_solver_expectations)
        check("## Contact inside the solver" in report and "### in_solver, tool friction 0.5 / 0.4" in report,
              "no in-solver contact section")
        check("| plate_4mm | 0 / 0.20% / 0.10% / 0·0 | 0 / 2.00% / 0.10% / 0·0 | 50 / 25 |" in report, "in-solver sweep row wrong")
        check("*No data: no collision_in_solver_frictionless.json.*" in report, "a missing frictionless run is not reported")
        for description, status in expectations.items():
            row = target_row(report, description)
            check(row is not None, f"target row missing: {description}")
            if row is not None:
                check(row[4] == status, f"target '{description}': status '{row[4]}', expected '{status}'")
        check("**FAILED**: exit 1" in report, "the failed view child is not reported as FAILED")
        # The sweep's cut-triangle table: most on one step / steps with any (fixture: bullet 1 / 7).
        check("Soft triangles cut by the tool during the hold" in report and "of 100." in report, "no cut-triangle table")
        check(any(line.startswith("| plate_4mm | bullet | 1 / 7 |") for line in report.splitlines()) and
              any(line.startswith("| plate_4mm | paired | 0 / 0 |") for line in report.splitlines()), "cut-triangle cells wrong")

        # The full stress profile (bench all --stress-full): its own summary and target. The
        # fixture's ci rows relabelled as a full run: its failing case must fail the target.
        with_full = os.path.join(tmp, "with-full")
        shutil.copytree(full, with_full)
        stress_full = json.load(open(os.path.join(full, "stress.json")))
        stress_full["profile"] = "full"
        for case in stress_full["cases"]:
            case["ticks"] = max(case.get("ticks", 0), 1000000) if case.get("ticks", 0) > 0 else 0
        json.dump(stress_full, open(os.path.join(with_full, "stress_full.json"), "w"))
        md_full = os.path.join(tmp, "with-full.md")
        result = run(script, with_full, md_full, os.path.join(tmp, "with-full-images"))
        check(result.returncode == 0, f"report with stress_full.json failed: {result.stderr}")
        report_full = open(md_full).read()
        check("### The full profile — `fissure stress --profile full`" in report_full, "no full-profile section")
        row = target_row(report_full, "full profile passes (every case, ≥ 1e6 rt ticks each)")
        check(row is not None and row[4] == "**MISSED**", f"full-profile target with a failing case: {row}")

        # A benchmark with no JSON: reported, its targets "not checked", never silently gone.
        partial = os.path.join(tmp, "partial")
        shutil.copytree(full, partial)
        os.remove(os.path.join(partial, "pareto.json"))
        # A failed render child: its (stale) frame must not be shown.
        record_path = os.path.join(partial, "bench_all.json")
        record = json.load(open(record_path))
        record["children"]["plunge_bullet"] = {"name": "plunge_bullet", "command": "fissure render", "exit_code": 1, "signal": 0,
                                               "error": "", "ok": False, "wall_s": 1.0}
        json.dump(record, open(record_path, "w"))
        md2 = os.path.join(tmp, "partial.md")
        result = run(script, partial, md2, os.path.join(tmp, "partial-images"))
        check(result.returncode == 0, f"make_report.py without pareto.json exited {result.returncode}: {result.stderr.strip()}")
        if os.path.exists(md2):
            report2 = open(md2).read()
            check("*No data: no pareto.json.*" in report2, "a missing pareto.json is not reported in its section")
            check("*No 10 m/s plunge frames" in report2, "a failed plunge render still shows a frame")
            row = target_row(report2, "0 crossed nodes at every node spacing setting")
            check(row is not None and row[4] == "not checked", "targets of a missing benchmark are not 'not checked'")
    if failures:
        print("report_test.py: FAILED\n  " + "\n  ".join(failures))
        return 1
    print(f"report_test.py: ok ({len(REQUIRED_SECTIONS)} sections, {len(links)} plots, {len(expectations)} target statuses)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
