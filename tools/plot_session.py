#!/usr/bin/python3
"""Plot a `fissure run` trace: force (and rt_core's rendered friction, where there is any), penetration, proxy
age and, for a clamp, the jaw gap and the per-jaw normal and friction force against time.

usage: plot_session.py TRACE.csv OUT.png [--title TEXT]
Uses only the standard library's csv module and matplotlib (Debian's python3-matplotlib).
"""
import argparse
import csv
import sys

import matplotlib

matplotlib.use("Agg")  # headless: CI and SSH sessions have no display
import matplotlib.pyplot as plt  # noqa: E402

REQUIRED_COLUMNS = ["time_s", "force_n", "contact_force_n", "host_force_n", "penetration_m",
                    "host_penetration_m", "proxy_age_ms"]
# Traces written before the jaw gap was recorded have no such column: they plot without it.
OPTIONAL_COLUMNS = ["host_jaw_gap_m", "host_jaw_a_normal_n", "host_jaw_a_friction_n", "host_jaw_b_normal_n",
                    "host_jaw_b_friction_n", "friction_n"]


def read_trace(path):
    columns = {key: [] for key in REQUIRED_COLUMNS}
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        present = [key for key in OPTIONAL_COLUMNS if key in (reader.fieldnames or [])]
        for key in present:
            columns[key] = []
        for row in reader:
            for key, values in columns.items():
                values.append(float(row[key]))
    return columns


def is_clamp(columns):
    """A clamp session: the host applied a jaw gap (0 for every other tool)."""
    return any(v > 0.0 for v in columns.get("host_jaw_gap_m", []))


def build_figure(columns, title=""):
    t = columns["time_s"]
    clamp = is_clamp(columns)
    has_jaw_forces = clamp and all(f"host_jaw_{jaw}_{part}_n" in columns for jaw in ("a", "b") for part in ("normal", "friction"))
    rows = (5 if has_jaw_forces else 4) if clamp else 3
    fig, axes = plt.subplots(rows, 1, sharex=True, figsize=(9, 2.5 * rows))
    axes[0].plot(t, columns["force_n"], label="commanded |F| (device)", lw=1.0)
    axes[0].plot(t, columns["contact_force_n"], label="proxy |F| (before safety)", lw=0.8, ls="--")
    axes[0].plot(t, columns["host_force_n"], label="host |F| (last host step)", lw=0.8, alpha=0.7)
    if any(v > 0.0 for v in columns.get("friction_n", [])):
        axes[0].plot(t, columns["friction_n"], label="of which friction (rt)", lw=0.9, ls=":")
    axes[0].set_ylabel("force [N]")
    axes[0].legend(loc="upper right", fontsize="small")
    axes[1].plot(t, [1e3 * v for v in columns["penetration_m"]], label="contact depth (rt, proxy)", lw=1.0)
    axes[1].plot(t, [1e3 * v for v in columns["host_penetration_m"]], label="soft nodes inside the tool (host)", lw=1.0)
    axes[1].set_ylabel("penetration [mm]")
    axes[1].legend(loc="upper right", fontsize="small")
    axes[2].plot(t, columns["proxy_age_ms"], lw=0.8)
    axes[2].set_ylabel("proxy age [ms]")
    if clamp:
        axes[3].plot(t, [1e3 * v for v in columns["host_jaw_gap_m"]], lw=1.0, label="gap between the jaws (host)")
        axes[3].set_ylabel("jaw gap [mm]")
        axes[3].legend(loc="upper right", fontsize="small")
    if has_jaw_forces:
        # The paper's Fig. 5: the force on the grabbed object, per jaw, normal and friction parts.
        ax = axes[4]
        for jaw in ("a", "b"):
            ax.plot(t, columns[f"host_jaw_{jaw}_normal_n"], lw=0.9, label=f"jaw {jaw.upper()} normal (host)")
            ax.plot(t, columns[f"host_jaw_{jaw}_friction_n"], lw=0.9, ls="--", label=f"jaw {jaw.upper()} friction (host)")
        ax.set_ylabel("jaw force [N]")
        ax.legend(loc="upper right", fontsize="small")
    axes[-1].set_xlabel("time [s]")
    for ax in axes:
        ax.grid(True, alpha=0.3)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("trace")
    parser.add_argument("png")
    parser.add_argument("--title", default="")
    args = parser.parse_args()
    columns = read_trace(args.trace)
    if not columns["time_s"]:
        print(f"plot_session.py: {args.trace} has no samples", file=sys.stderr)
        return 1
    build_figure(columns, args.title).savefig(args.png, dpi=110)
    return 0


if __name__ == "__main__":
    sys.exit(main())
