"""Generate the unstructured Gmsh 4.1 meshes used by the tests (committed; rerun only to change them).

    .venv/bin/python verification/cases/gen_meshes.py      (needs `pip install gmsh==4.15.2`)

lshape.msh: the L-shaped polygon (0,2)^2 minus [1,2]x[1,2], h ~ 0.35, physical curves
"clamp" (x = 0), "loaded" (the other sides except y = 0) and "floor" (y = 0).
"""
import gmsh

gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("lshape")
pts = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]
p = [gmsh.model.geo.addPoint(x, y, 0, 0.35) for x, y in pts]
lines = [gmsh.model.geo.addLine(p[i], p[(i + 1) % 6]) for i in range(6)]
loop = gmsh.model.geo.addCurveLoop(lines)
surf = gmsh.model.geo.addPlaneSurface([loop])
gmsh.model.geo.synchronize()
gmsh.model.addPhysicalGroup(1, [lines[0]], name="floor")
gmsh.model.addPhysicalGroup(1, [lines[5]], name="clamp")
gmsh.model.addPhysicalGroup(1, lines[1:5], name="loaded")
gmsh.model.addPhysicalGroup(2, [surf], name="body")
gmsh.model.mesh.generate(2)
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
gmsh.option.setNumber("Mesh.Binary", 0)
gmsh.write("verification/cases/lshape.msh")
gmsh.finalize()
print("wrote verification/cases/lshape.msh")
