"""Generate the unstructured Gmsh 4.1 meshes used by the tests (committed; rerun only to change them).

    .venv/bin/python verification/cases/gen_meshes.py      (needs `pip install gmsh==4.15.2`)

The L-shaped polygon (0,2)^2 minus [1,2]x[1,2], h ~ 0.35, in two groupings of its sides (same mesh):
lshape.msh: physical curves "clamp" (x = 0), "loaded" (the other sides except y = 0) and "floor" (y = 0);
lshape_sides.msh: one physical curve per side, "floor" (y = 0), "right" (x = 2), "ledge" (y = 1, x > 1),
"notch" (x = 1, y > 1), "top" (y = 2), "clamp" (x = 0): the manufactured mms_lshape, whose tractions
differ from side to side.
"""
import gmsh

PTS = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]
SIDES = ["floor", "right", "ledge", "notch", "top", "clamp"]     # line i runs PTS[i] -> PTS[i+1]


def write(path, groups):
    """The L-shape meshed with its lines grouped as ``groups`` (name -> line indices)."""
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("lshape")
    p = [gmsh.model.geo.addPoint(x, y, 0, 0.35) for x, y in PTS]
    lines = [gmsh.model.geo.addLine(p[i], p[(i + 1) % 6]) for i in range(6)]
    loop = gmsh.model.geo.addCurveLoop(lines)
    surf = gmsh.model.geo.addPlaneSurface([loop])
    gmsh.model.geo.synchronize()
    for name, idx in groups.items():
        gmsh.model.addPhysicalGroup(1, [lines[i] for i in idx], name=name)
    gmsh.model.addPhysicalGroup(2, [surf], name="body")
    gmsh.model.mesh.generate(2)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.Binary", 0)
    gmsh.write(path)
    gmsh.finalize()
    print(f"wrote {path}")


write("verification/cases/lshape.msh", {"floor": [0], "clamp": [5], "loaded": [1, 2, 3, 4]})
write("verification/cases/lshape_sides.msh", {name: [i] for i, name in enumerate(SIDES)})
