#!/usr/bin/env python3
"""Quasi-static force–indentation of a flat soft slab, fitted to Hunt-Crossley's F = k·xⁿ.

A 40 × 40 mm plate (2 mm thick) is pressed into an 80 × 80 × 20 mm slab (no gravity, pose
matching as in `fissure bench collision`'s indentation part) in steps of depth; each depth is
held until the damping term has decayed and the force is read. Fitting log F = log k + n·log x
recovers the scene's exponent n; the scene's k is per unit area, so the fitted k is compared with
k × the plate's area (the contact set under a plate smaller than the slab is fixed).

    PYTHONPATH=build/python python3 examples/python/force_indentation.py [--quick]
"""
import argparse
import os
import re

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import fissure  # noqa: E402

PLATE_SIZE_M = (0.04, 0.002, 0.04)
APPROACH_SPEED_M_S = 0.01  # quasi-static
SETTLE_S = 0.3


def slab_scene():
    """spatula-sphere's file with the soft body replaced by a slab, no gravity, a 40 × 40 mm plate."""
    path = os.path.join(os.environ["FISSURE_SCENES_DIR"], "spatula-sphere.toml")
    with open(path, encoding="utf-8") as f:
        text = f.read()
    replacements = [
        (r'shape = "sphere"\n(?:.*\n)*?faces_count = \d+\n',
         'shape = "slab"\ncenter_world_m = [0.0, 0.0125, 0.0]\nsize_m = [0.08, 0.02, 0.08]\n'
         "top_cells_x_count = 16\ntop_cells_z_count = 16\n"),
        (r"gravity_world_m_per_s2 = \[[^\]]*\]", "gravity_world_m_per_s2 = [0.0, 0.0, 0.0]"),
        (r"size_m = \[0\.03, 0\.002, 0\.06\]", "size_m = [%g, %g, %g]" % PLATE_SIZE_M),
        (r"node_spacing_m = [0-9.]+", "node_spacing_m = 0.002"),
    ]
    for pattern, replacement in replacements:
        text, count = re.subn(pattern, replacement, text, count=1)
        if count != 1:
            raise RuntimeError(f"spatula-sphere.toml changed: '{pattern}' not found")
    return fissure.Scene.from_toml(text, label="slab-indentation (from spatula-sphere.toml)")


def indentation_curve(scene, depths_m, hold_s):
    sim = fissure.HostSimulation(scene, method="paired")
    start = scene.trajectory_start
    sim.step([start.position[0], 0.3, start.position[2]])  # the plate well clear of the slab while it settles
    sim.settle(SETTLE_S)
    top_m = sim.soft_bounds()[1, 1]
    half_thickness_m = 0.5 * PLATE_SIZE_M[1]
    dt = scene.time_step_s
    y = top_m + 0.002 + half_thickness_m
    forces = []
    for depth in depths_m:
        target = top_m - depth + half_thickness_m
        while y > target:
            y = max(target, y - APPROACH_SPEED_M_S * dt)
            sim.step([0.0, y, 0.0])
        for _ in range(int(round(hold_s / dt))):
            result = sim.step([0.0, y, 0.0])
        forces.append(float(np.linalg.norm(result.force)))
        print(f"depth {depth * 1e3:5.2f} mm  |F| {forces[-1]:8.4f} N  contacts {result.contact_count}")
    return np.array(forces)


def fit_hunt_crossley(depths_m, forces_n):
    """Least squares on log F = log k + n log x: (k [N/mⁿ], n)."""
    n, log_k = np.polyfit(np.log(depths_m), np.log(forces_n), 1)
    return float(np.exp(log_k)), float(n)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="four depths and short holds (CI)")
    parser.add_argument("--out", default="out/python/force_indentation.png", help="PNG to write")
    args = parser.parse_args(argv)
    depths = np.array([0.0005, 0.001, 0.002, 0.004] if args.quick else [0.0005, 0.001, 0.0015, 0.002, 0.003, 0.004])
    hold_s = 0.1 if args.quick else 0.3
    scene = slab_scene()
    hc = scene.hunt_crossley
    forces = indentation_curve(scene, depths, hold_s)
    k_fit, n_fit = fit_hunt_crossley(depths, forces)
    plate_area_m2 = PLATE_SIZE_M[0] * PLATE_SIZE_M[2]
    k_expected = hc["k"] * plate_area_m2 if hc["per_unit_area"] else float("nan")
    print(f"fitted n = {n_fit:.4f} (scene: {hc['n']}); fitted k = {k_fit:.4g} N/m^n "
          f"(scene k × plate area = {k_expected:.4g} N/m^n, ratio {k_fit / k_expected:.3f})")

    fig, ax = plt.subplots(figsize=(6, 4.5), constrained_layout=True)
    ax.loglog(depths * 1e3, forces, "o", label="HostSimulation (paired), held")
    x = np.geomspace(depths[0], depths[-1], 50)
    ax.loglog(x * 1e3, k_fit * x**n_fit, "-", label=f"fit: k = {k_fit:.3g} N/m^n, n = {n_fit:.3f}")
    ax.loglog(x * 1e3, k_expected * x ** hc["n"], ":", label=f"scene: k·A = {k_expected:.3g}, n = {hc['n']}")
    ax.set_xlabel("indentation depth [mm]")
    ax.set_ylabel("|F| on the plate [N]")
    ax.set_title("Force–indentation, 40 × 40 mm plate into a soft slab")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    fig.savefig(args.out, dpi=110)
    print(f"wrote {args.out}")
    return {"depths_m": depths, "forces_n": forces, "k_fit": k_fit, "n_fit": n_fit, "k_expected": k_expected, "n_scene": hc["n"]}


if __name__ == "__main__":
    main()
