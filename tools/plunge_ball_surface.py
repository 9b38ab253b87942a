#!/usr/bin/python3
"""Write the collision sweep's ball surface (`fissure bench collision`: the paper's 128-face shell,
or the 1280-face icosphere) as an OFF file, vertex for vertex as the bench builds it, for TetGen
to fill with tetrahedra while keeping that surface (-Y): the volumetric sweep ball of
`fissure bench collision --soft-model fem` (host_sim/plunge_hold.hpp, volumetric_plunge_scene).

usage: PYTHONPATH=build/python tools/plunge_ball_surface.py FACES OUT.off      (FACES: 128 or 1280)
then:  tetgen -pYq1.4/15 -Q OUT.off      # OUT.1.node / OUT.1.ele
The shipped pair (scenes/meshes/plunge-ball-128.1.*, plunge-ball-1280.1.*) is exactly this.
"""
import sys

import numpy as np

import fissure


def main() -> int:
    if len(sys.argv) != 3 or sys.argv[1] not in ("128", "1280"):
        print(__doc__, file=sys.stderr)
        return 2
    faces = int(sys.argv[1])
    scene = fissure.plunge_scene("plate_4mm", icosphere_faces=0 if faces == 128 else faces)
    sim = fissure.HostSimulation(scene)  # as built: the rest shape, before any step
    nodes = np.asarray(sim.node_positions())
    triangles = np.asarray(sim.faces())
    with open(sys.argv[2], "w", encoding="ascii") as out:
        out.write(f"OFF\n{len(nodes)} {len(triangles)} 0\n")
        for p in nodes:
            out.write(f"{p[0]!r} {p[1]!r} {p[2]!r}\n")
        for t in triangles:
            out.write(f"3 {t[0]} {t[1]} {t[2]}\n")
    print(f"wrote {sys.argv[2]}: {len(nodes)} vertices, {len(triangles)} triangles")
    return 0


if __name__ == "__main__":
    sys.exit(main())
