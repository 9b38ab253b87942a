#!/usr/bin/env python3
"""Tunnelling sweep of one thin tool: the paired-node collision against Bullet's own (SDF_RS).

The plunge-and-hold cell of `fissure bench collision` (issue 5): the 128-face ball settles, the
tool is driven 20 mm into it at each speed and held; the method-independent metrics count the
soft nodes that went through the tool and the deepest node inside it. Lockstep (simulated time):
every plotted figure is deterministic.

    PYTHONPATH=build/python python3 examples/python/tunnelling_sweep.py [--tool plate_1mm] [--quick]
"""
import argparse
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import fissure  # noqa: E402

METHODS = ("paired", "bullet")


def sweep(tool, speeds, hold_s):
    """{method: [run_plunge_hold result per speed]}."""
    rows = {}
    for method in METHODS:
        rows[method] = [fissure.run_plunge_hold(tool, method, v, hold_s=hold_s) for v in speeds]
        for r in rows[method]:
            print(f"{tool:<18} {method:<7} {r['speed_m_s']:6.2f} m/s  crossed {r['crossed_nodes']:4d}  "
                  f"penetration {r['max_penetration_m'] * 1e3:7.3f} mm  hold |F| {r['hold']['mean_n']:7.3f} N")
    return rows


def plot(tool, speeds, rows, png):
    fig, (ax_crossed, ax_depth) = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    for method, style in zip(METHODS, ("o-", "s--")):
        ax_crossed.plot(speeds, [r["crossed_nodes"] for r in rows[method]], style, label=method)
        ax_depth.plot(speeds, [r["max_penetration_m"] * 1e3 for r in rows[method]], style, label=method)
    for ax in (ax_crossed, ax_depth):
        ax.set_xscale("log")
        ax.set_xlabel("plunge speed [m/s]")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    ax_crossed.set_ylabel("crossed soft nodes (worst step)")
    ax_depth.set_ylabel("max penetration into the tool [mm]")
    ax_depth.axhline(fissure.INSIDE_TOLERANCE_M * 1e3, color="grey", lw=0.8, ls=":")
    fig.suptitle(f"Tunnelling sweep: {tool}, 20 mm plunge into the 128-face ball (1 kHz host)")
    os.makedirs(os.path.dirname(os.path.abspath(png)), exist_ok=True)
    fig.savefig(png, dpi=110)
    print(f"wrote {png}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    names = [t["name"] for t in fissure.plunge_tools()]
    parser.add_argument("--tool", default="plate_1mm", choices=names)
    parser.add_argument("--quick", action="store_true", help="three speeds and a short hold (CI)")
    parser.add_argument("--out", default="out/python/tunnelling_sweep.png", help="PNG to write")
    args = parser.parse_args(argv)
    speeds = [0.1, 2.0, 20.0] if args.quick else [0.1, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0]
    hold_s = 0.05 if args.quick else 0.5
    rows = sweep(args.tool, speeds, hold_s)
    plot(args.tool, speeds, rows, args.out)
    return rows


if __name__ == "__main__":
    main()
