"""Writes two_blocks.msh (Gmsh 2.2) and two_blocks.inp (Abaqus, with *SURFACE): the same two-body model, a 2 x 2 x 1
"base" of unit hex8 cells below z = 1 and a "punch" of 2 x 2 x 1 cells of 0.5 x 0.5 x 0.5 on top of it (nodes of
the plane z = 1 shared where they coincide). Groups: volumes "base" and "punch"; surfaces "base_top" (z = 1, of the
base), "punch_bottom" (z = 1, of the punch), "base_bottom" (z = 0), "punch_top" (z = 1.5). Used by
tests/unit/test_two_files.py; run again (python tests/data/make_two_blocks.py) to remake the files.
"""

from pathlib import Path

import meshio
import numpy as np

HERE = Path(__file__).parent
#: C3D8 faces (Abaqus numbering): S1 bottom 1-2-3-4, S2 top 5-8-7-6
S_BOTTOM, S_TOP = 1, 2


def _grid(n, h, origin):
    """Nodes and hex8 cells (VTK = C3D8 order) of an n x n x 1 grid of cubes of side h."""
    i, j, k = np.meshgrid(np.arange(n + 1), np.arange(n + 1), np.arange(2), indexing="ij")
    pts = np.column_stack([i.ravel(), j.ravel(), k.ravel()]) * h + origin
    idx = np.arange(pts.shape[0]).reshape(n + 1, n + 1, 2)
    cells = [[idx[a, b, 0], idx[a + 1, b, 0], idx[a + 1, b + 1, 0], idx[a, b + 1, 0],
              idx[a, b, 1], idx[a + 1, b, 1], idx[a + 1, b + 1, 1], idx[a, b + 1, 1]]
             for a in range(n) for b in range(n)]
    return pts, np.array(cells)


def main() -> None:
    pb, cb = _grid(2, 1.0, np.array([0.0, 0.0, 0.0]))
    pp, cp = _grid(2, 0.5, np.array([0.5, 0.5, 1.0]))
    pts, inv = np.unique(np.round(np.vstack([pb, pp]), 12), axis=0, return_inverse=True)
    inv = inv.ravel()
    base, punch = inv[cb], inv[len(pb) + cp]
    hexes = np.vstack([base, punch])
    faces = {"base_bottom": base[:, :4], "base_top": base[:, 4:], "punch_bottom": punch[:, :4],
             "punch_top": punch[:, 4:]}
    # Gmsh: physical volumes and surfaces
    phys = [np.array([1] * len(base) + [2] * len(punch))] + [np.full(len(f), 3 + k) for k, f in enumerate(faces.values())]
    cells = [("hexahedron", hexes)] + [("quad", f) for f in faces.values()]
    field = {"base": np.array([1, 3]), "punch": np.array([2, 3])}
    field.update({name: np.array([3 + k, 2]) for k, name in enumerate(faces)})
    meshio.write(HERE / "two_blocks.msh", meshio.Mesh(pts, cells, cell_data={"gmsh:physical": phys,
                                                                          "gmsh:geometrical": phys},
                                                       field_data=field), file_format="gmsh22", binary=False)
    # Abaqus: element sets for the volumes, *SURFACE by element set and face identifier
    lines = ["*HEADING", "two blocks, the same model as two_blocks.msh", "*NODE"]
    lines += [f"{n + 1}, {x:.12g}, {y:.12g}, {z:.12g}" for n, (x, y, z) in enumerate(pts)]
    lines.append("*ELEMENT, TYPE=C3D8, ELSET=base")
    lines += [f"{e + 1}, " + ", ".join(str(v + 1) for v in c) for e, c in enumerate(base)]
    lines.append("*ELEMENT, TYPE=C3D8, ELSET=punch")
    lines += [f"{len(base) + e + 1}, " + ", ".join(str(v + 1) for v in c) for e, c in enumerate(punch)]
    for name, elset, face in (("base_bottom", "base", S_BOTTOM), ("base_top", "base", S_TOP),
                              ("punch_bottom", "punch", S_BOTTOM), ("punch_top", "punch", S_TOP)):
        lines += [f"*SURFACE, NAME={name}, TYPE=ELEMENT", f"{elset}, S{face}"]
    (HERE / "two_blocks.inp").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
