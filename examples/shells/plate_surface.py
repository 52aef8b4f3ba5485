"""The mid-surface mesh of the seed paper's plate (90 x 40 mm, 18 x 8 quad9 cells) with Gmsh: physical curves
xmin (clamped), xmax and ymax (loaded) and the physical surface "plate"; writes plate_surface.msh (committed beside,
so the example runs without Gmsh). Needs the gmsh Python package.

    python plate_surface.py
"""

from pathlib import Path

import gmsh

gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("plate")
g = gmsh.model.geo
p = [g.addPoint(x, y, 0.0) for x, y in ((0, 0), (90, 0), (90, 40), (0, 40))]
lines = [g.addLine(p[i], p[(i + 1) % 4]) for i in range(4)]  # ymin, xmax, ymax, xmin
loop = g.addCurveLoop(lines)
surface = g.addPlaneSurface([loop])
for line, n in zip(lines, (19, 9, 19, 9)):
    g.mesh.setTransfiniteCurve(line, n)
g.mesh.setTransfiniteSurface(surface, cornerTags=p)
g.mesh.setRecombine(2, surface)
g.synchronize()
for name, line in (("xmin", lines[3]), ("xmax", lines[1]), ("ymax", lines[2])):
    gmsh.model.setPhysicalName(1, gmsh.model.addPhysicalGroup(1, [line]), name)
gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, [surface]), "plate")
gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 0)  # quad9, not quad8
gmsh.model.mesh.generate(2)
gmsh.model.mesh.setOrder(2)
gmsh.option.setNumber("Mesh.MshFileVersion", 2.2)
gmsh.write(str(Path(__file__).with_name("plate_surface.msh")))
gmsh.finalize()
