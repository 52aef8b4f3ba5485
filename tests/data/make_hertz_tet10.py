"""Writes hertz_tet10.msh: the quarter (x >= 0, y >= 0) of a half-ball of radius 1 (centre (0, 0, 1), flat face
z = 1, pole at the origin) in tet10 elements, graded toward the pole, by Gmsh (pip install gmsh).

Physical groups: volume "ball"; surfaces "curved", "flat", "symx" (x = 0), "symy" (y = 0). Element size h_min at
the pole up to r = 0.06, growing to h_max at r = 0.7; second-order nodes on the sphere. Used by
tests/verification/test_hertz_tet10.py; run again (python tests/data/make_hertz_tet10.py) to remake the file.
"""

from pathlib import Path

import gmsh

H_MIN, H_MAX = 0.016, 0.25


def main(path: Path | None = None) -> None:
    path = Path(__file__).with_name("hertz_tet10.msh") if path is None else path
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("hertz")
    occ = gmsh.model.occ
    ball = occ.addSphere(0.0, 0.0, 1.0, 1.0)
    box = occ.addBox(0.0, 0.0, 0.0, 1.0, 1.0, 1.0)
    (vol,), _ = occ.intersect([(3, ball)], [(3, box)])
    occ.synchronize()
    groups = {"curved": [], "flat": [], "symx": [], "symy": []}
    for dim, tag in gmsh.model.getBoundary([vol], oriented=False):
        x, y, z = gmsh.model.occ.getCenterOfMass(dim, tag)
        name = "symx" if abs(x) < 1e-9 else "symy" if abs(y) < 1e-9 else "flat" if abs(z - 1.0) < 1e-9 else "curved"
        groups[name].append(tag)
    gmsh.model.addPhysicalGroup(3, [vol[1]], name="ball")
    for name, tags in groups.items():
        gmsh.model.addPhysicalGroup(2, tags, name=name)
    pole = occ.addPoint(0.0, 0.0, 0.0)
    occ.synchronize()
    dist = gmsh.model.mesh.field.add("Distance")
    gmsh.model.mesh.field.setNumbers(dist, "PointsList", [pole])
    thr = gmsh.model.mesh.field.add("Threshold")
    gmsh.model.mesh.field.setNumber(thr, "InField", dist)
    for key, val in (("SizeMin", H_MIN), ("SizeMax", H_MAX), ("DistMin", 0.06), ("DistMax", 0.7)):
        gmsh.model.mesh.field.setNumber(thr, key, val)
    gmsh.model.mesh.field.setAsBackgroundMesh(thr)
    for key in ("MeshSizeExtendFromBoundary", "MeshSizeFromPoints", "MeshSizeFromCurvature"):
        gmsh.option.setNumber(f"Mesh.{key}", 0)
    gmsh.option.setNumber("Mesh.Algorithm3D", 1)
    gmsh.model.mesh.generate(3)
    gmsh.model.mesh.setOrder(2)
    gmsh.option.setNumber("Mesh.MshFileVersion", 2.2)
    gmsh.option.setNumber("Mesh.SaveAll", 0)
    gmsh.write(str(path))
    gmsh.finalize()


if __name__ == "__main__":
    main()
