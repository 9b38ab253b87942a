#!/usr/bin/python3
"""Settle a vessel scene's cylinder on the ground (jaws open) and print its middle section: the
diameters of the ellipse with the middle ring's second moments (nodes evenly spaced round an
ellipse of semi-axes a, b have the covariance diag(a², b²)/2 whatever the ring's roll), the
ovalisation (D_max − D_min) / D_rest and the highest node. Each KEY=VALUE sets (or adds) a key of
the scene's [soft_body] or [simulation] table (KEY= with no value removes it), so one scene file
gives a sweep:

usage: PYTHONPATH=build/python vessel_section.py [--scene clamp-vessel] [--settle-s 0.5] [KEY=VALUE ...]
  e.g. vessel_section.py bending_stiffness_ratio= bending_distance_count= ; vessel_section.py bending_distance_count=2 bending_stiffness_ratio=1.0
       vessel_section.py time_step_s=0.002
docs/decisions.md, "Tissue (issue 24)" (2026-12-07, branch vessel24) has the figures.
"""
import argparse
import re
import sys

import numpy as np

import fissure


def with_key(text, key, value):
    """The scene text with `key = value` replacing the key's line, or added after the soft body's
    collision_margin_m line (the collision_method line for contact_response); an empty value
    removes the line."""
    line = re.compile(r"^%s\s*=.*$" % re.escape(key), re.M)
    if not value:
        return re.sub(r"^%s\s*=.*\n" % re.escape(key), "", text, count=1, flags=re.M)
    if line.search(text):
        return line.sub("%s = %s" % (key, value), text, count=1)
    after = "collision_method" if key in ("contact_response",) else "collision_margin_m"
    return re.sub(r"^(%s\s*=.*)$" % after, r"\1\n%s = %s" % (key, value), text, count=1, flags=re.M)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--scene", default="clamp-vessel")
    parser.add_argument("--settle-s", type=float, default=0.5, help="settling time [s] (fissure sim's default: 0.5)")
    parser.add_argument("keys", nargs="*", metavar="KEY=VALUE")
    args = parser.parse_args()
    scene = fissure.Scene.load(args.scene)
    text = open(scene.source_path).read()
    for kv in args.keys:
        key, value = kv.split("=", 1)
        text = with_key(text, key.strip(), value.strip())
    cylinder = re.search(r"segments_count\s*=\s*(\d+)", text), re.search(r"rings_count\s*=\s*(\d+)", text)
    radius_m = float(re.search(r"radius_m\s*=\s*([0-9.eE+-]+)", text).group(1))
    segments, rings = int(cylinder[0].group(1)), int(cylinder[1].group(1))
    sim = fissure.HostSimulation(fissure.Scene.from_toml(text, label=args.scene, base_dir="scenes"))
    sim.settle(args.settle_s)
    nodes = sim.node_positions()
    ring = nodes[(rings // 2) * segments:(rings // 2 + 1) * segments, 1:]  # make_cylinder: ring k's node j is k·n + j; (y, z)
    ring = ring - ring.mean(axis=0)
    d_min, d_max = 2.0 * np.sqrt(2.0 * np.linalg.eigvalsh(ring.T @ ring / len(ring)))
    print("%s %s: section %.2f / %.2f mm, ovalisation %.2f %%, top %.2f mm" %
          (args.scene, " ".join(args.keys) or "(as shipped)", 1e3 * d_min, 1e3 * d_max, 100.0 * (d_max - d_min) / (2.0 * radius_m),
           1e3 * nodes[:, 1].max()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
