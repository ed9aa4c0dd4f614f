#!/usr/bin/env python3
"""One-off generator of gmsh_pentagon.msh (the external suite's Gmsh scene, ``pentagon_tresca.toml``): a
pentagon meshed by Gmsh's own mesher (Frontal-Delaunay, mesh size 0.75: 11 triangles, angles 36°–102°),
written as Gmsh 4.1 ASCII; every level of the suite is a red refinement of it.

Needs the ``gmsh`` module (PyPI ``gmsh==4.15.2``, not in requirements.txt: the committed .msh is what the
suite reads): ``python gmsh_pentagon_gen.py``. Boundary parts (1D physical groups): ``contact`` y = 0,
0 ≤ x ≤ 1 (Γ_C), ``right``, ``top`` (the side from (1.2, 0.7) to (0.4, 1.3), of unit length with outward
normal (0.6, 0.8): the Neumann side) and ``left`` (two segments).
"""
from pathlib import Path

import gmsh

VERTICES = [(0.0, 0.0), (1.0, 0.0), (1.2, 0.7), (0.4, 1.3), (-0.2, 0.6)]
SIZE = 0.75


def main():
    gmsh.initialize(["-noenv"])
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("pentagon")
    p = [gmsh.model.geo.addPoint(x, y, 0.0, SIZE) for x, y in VERTICES]
    lines = [gmsh.model.geo.addLine(p[i], p[(i + 1) % len(p)]) for i in range(len(p))]
    surf = gmsh.model.geo.addPlaneSurface([gmsh.model.geo.addCurveLoop(lines)])
    gmsh.model.geo.synchronize()
    for tag, (name, curves) in enumerate((("contact", lines[:1]), ("right", lines[1:2]), ("top", lines[2:3]),
                                          ("left", lines[3:])), start=1):
        gmsh.model.addPhysicalGroup(1, curves, tag, name)
    gmsh.model.addPhysicalGroup(2, [surf], 10, "body")
    gmsh.option.setNumber("Mesh.Algorithm", 6)
    gmsh.model.mesh.generate(2)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.Binary", 0)
    out = Path(__file__).with_name("gmsh_pentagon.msh")
    gmsh.write(str(out))
    _, _, nodes = gmsh.model.mesh.getElements(2)
    print(f"wrote {out}: {len(nodes[0]) // 3} triangles")
    gmsh.finalize()


if __name__ == "__main__":
    main()
