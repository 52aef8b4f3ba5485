"""Writes mixed_block.msh (Gmsh 2.2): a block [0, 2] x [0, 1] x [0, 1] of hexahedra (x < 1, from a structured quad
mesh) and wedges (x > 1, from an unstructured triangle mesh), both extruded along z in two layers, sharing the
quadrilateral faces on x = 1. Groups: the volume "block"; the surfaces "xmin" (x = 0, quadrilaterals of the bricks),
"xmax" (x = 2, quadrilaterals of the wedges), "zmin" and "zmax" (quadrilaterals and triangles). Used by
tests/unit/test_mixed_mesh.py; needs the gmsh module (pip install gmsh) to run again:
python tests/data/make_mixed_block.py.
"""

from pathlib import Path

import gmsh

HERE = Path(__file__).parent


def main() -> None:
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("mixed")
    geo = gmsh.model.geo
    h = 0.34
    p = [geo.addPoint(x, y, 0.0, h) for x, y in ((0, 0), (1, 0), (2, 0), (2, 1), (1, 1), (0, 1))]
    lines = [geo.addLine(p[i], p[(i + 1) % 6]) for i in range(6)]
    mid = geo.addLine(p[1], p[4])
    left = geo.addPlaneSurface([geo.addCurveLoop([lines[0], mid, lines[4], lines[5]])])
    right = geo.addPlaneSurface([geo.addCurveLoop([lines[1], lines[2], lines[3], -mid])])
    for c in (lines[0], lines[4], lines[5], mid):
        geo.mesh.setTransfiniteCurve(c, 4)
    geo.mesh.setTransfiniteSurface(left)
    geo.mesh.setRecombine(2, left)
    out = geo.extrude([(2, left), (2, right)], 0.0, 0.0, 1.0, numElements=[2], recombine=True)
    geo.synchronize()
    vols = [t for d, t in out if d == 3]
    gmsh.model.addPhysicalGroup(3, vols, name="block")

    def faces_at(axis: int, value: float) -> list[int]:
        lo = [-1e-6] * 3
        hi = [2.0 + 1e-6, 1.0 + 1e-6, 1.0 + 1e-6]
        lo[axis], hi[axis] = value - 1e-6, value + 1e-6
        return [t for _, t in gmsh.model.getEntitiesInBoundingBox(*lo, *hi, dim=2)]

    for name, axis, value in (("xmin", 0, 0.0), ("xmax", 0, 2.0), ("zmin", 2, 0.0), ("zmax", 2, 1.0)):
        gmsh.model.addPhysicalGroup(2, faces_at(axis, value), name=name)
    gmsh.model.mesh.generate(3)
    gmsh.option.setNumber("Mesh.MshFileVersion", 2.2)
    gmsh.write(str(HERE / "mixed_block.msh"))
    gmsh.finalize()


if __name__ == "__main__":
    main()
