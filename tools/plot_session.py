#!/usr/bin/python3
"""Plot a `fissure run` trace: force, penetration and proxy age against time.

usage: plot_session.py TRACE.csv OUT.png [--title TEXT]
Uses only the standard library's csv module and matplotlib (Debian's python3-matplotlib).
"""
import argparse
import csv
import sys

import matplotlib

matplotlib.use("Agg")  # headless: CI and SSH sessions have no display
import matplotlib.pyplot as plt  # noqa: E402


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("trace")
    parser.add_argument("png")
    parser.add_argument("--title", default="")
    args = parser.parse_args()

    columns = {"time_s": [], "force_n": [], "contact_force_n": [], "host_force_n": [],
               "penetration_m": [], "host_penetration_m": [], "proxy_age_ms": []}
    with open(args.trace, newline="") as f:
        for row in csv.DictReader(f):
            for key, values in columns.items():
                values.append(float(row[key]))
    if not columns["time_s"]:
        print(f"plot_session.py: {args.trace} has no samples", file=sys.stderr)
        return 1
    t = columns["time_s"]
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(9, 7.5))
    axes[0].plot(t, columns["force_n"], label="commanded |F| (device)", lw=1.0)
    axes[0].plot(t, columns["contact_force_n"], label="proxy |F| (before safety)", lw=0.8, ls="--")
    axes[0].plot(t, columns["host_force_n"], label="host |F| (last host step)", lw=0.8, alpha=0.7)
    axes[0].set_ylabel("force [N]")
    axes[0].legend(loc="upper right", fontsize="small")
    axes[1].plot(t, [1e3 * v for v in columns["penetration_m"]], label="contact depth (rt, proxy)", lw=1.0)
    axes[1].plot(t, [1e3 * v for v in columns["host_penetration_m"]], label="soft nodes inside the tool (host)", lw=1.0)
    axes[1].set_ylabel("penetration [mm]")
    axes[1].legend(loc="upper right", fontsize="small")
    axes[2].plot(t, columns["proxy_age_ms"], lw=0.8)
    axes[2].set_ylabel("proxy age [ms]")
    axes[2].set_xlabel("time [s]")
    for ax in axes:
        ax.grid(True, alpha=0.3)
    if args.title:
        fig.suptitle(args.title)
    fig.tight_layout()
    fig.savefig(args.png, dpi=110)
    return 0


if __name__ == "__main__":
    sys.exit(main())
