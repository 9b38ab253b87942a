#!/usr/bin/python3
"""ctest app.plot_session: tools/plot_session.py draws the jaw gap for a clamp session only.

A clamp trace (host_jaw_gap_m > 0) gets a fourth panel "jaw gap [mm]" with the gap in
millimetres; a spatula trace (gap 0) and a trace without the column keep the three panels.
usage: plot_session_test.py TOOLS_DIR
Exit 77 (ctest SKIP_RETURN_CODE) when matplotlib is missing.
"""
import importlib.util
import os
import sys
import tempfile

try:
    import matplotlib  # noqa: F401
except ImportError:
    print("SKIP: this python3 has no matplotlib (install Debian's python3-matplotlib)")
    sys.exit(77)

HEADER = ("time_s,tick,force_n,contact_force_n,host_force_n,penetration_m,host_penetration_m,proxy_age_ms,"
          "host_jaw_gap_m\n")


def load(tools_dir):
    spec = importlib.util.spec_from_file_location("plot_session", os.path.join(tools_dir, "plot_session.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def write_trace(directory, name, gaps_m, with_gap_column=True):
    path = os.path.join(directory, name)
    with open(path, "w") as f:
        header = HEADER if with_gap_column else HEADER.replace(",host_jaw_gap_m", "")
        f.write(header)
        for i, gap in enumerate(gaps_m):
            row = f"{i * 0.001},{i},1.0,1.0,1.0,0.001,0.001,1.0"
            f.write(row + (f",{gap}\n" if with_gap_column else "\n"))
    return path


def main() -> int:
    plot = load(sys.argv[1])
    failures = []
    with tempfile.TemporaryDirectory() as tmp:
        clamp = plot.read_trace(write_trace(tmp, "clamp.csv", [0.05, 0.04, 0.03]))
        fig = plot.build_figure(clamp)
        labels = [ax.get_ylabel() for ax in fig.axes]
        if "jaw gap [mm]" not in labels:
            failures.append(f"clamp trace: no jaw gap panel (panels {labels})")
        else:
            gap_axis = fig.axes[labels.index("jaw gap [mm]")]
            ys = list(gap_axis.lines[0].get_ydata())
            if [round(y, 6) for y in ys] != [50.0, 40.0, 30.0]:
                failures.append(f"clamp trace: jaw gap not in millimetres: {ys}")
        for name, trace in [("spatula", write_trace(tmp, "spatula.csv", [0.0, 0.0, 0.0])),
                            ("old format", write_trace(tmp, "old.csv", [0.0] * 3, with_gap_column=False))]:
            labels = [ax.get_ylabel() for ax in plot.build_figure(plot.read_trace(trace)).axes]
            if "jaw gap [mm]" in labels or len(labels) != 3:
                failures.append(f"{name} trace: panels {labels}, want the three without a jaw gap")
        png = os.path.join(tmp, "clamp.png")
        sys.argv = ["plot_session.py", os.path.join(tmp, "clamp.csv"), png]
        if plot.main() != 0 or not os.path.getsize(png):
            failures.append("main() did not write the PNG")
    for failure in failures:
        print("FAIL:", failure)
    if not failures:
        print("ok: the clamp plot shows the jaw gap, the others do not")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
