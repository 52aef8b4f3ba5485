"""Hexahedral meshes turned into the other cells (tet4, tet10, wedge6, hex20), for the mesh generators and tests.

hex8 -> tet4: six tetrahedra per brick around its diagonal 0-6 (neighbouring bricks of a structured mesh then
share their faces' diagonals); tet4 -> tet10: a mid-node on every edge, shared, and in every node set that holds
both ends of its edge; hex8 -> wedge6: two wedges per
brick, cut along the diagonal plane through edges 1-5 and 3-7; hex27 -> hex20: the face and body centres
dropped. Node sets and element sets follow (an element set holds the new cells of its bricks), and face sets
(the boundary faces of the new cells whose corners lie on the old set's faces: triangles, tri6 or quad8; on wedges
the triangles or the quadrilaterals, whichever the set holds: a block's zmin and zmax are triangles, its sides
quadrilaterals).
"""

from __future__ import annotations

import numpy as np

from .faces import faces_on_nodes
from .mesh import FACE_TYPE, Mesh

_TETS = np.array([[0, 1, 2, 6], [0, 2, 3, 6], [0, 3, 7, 6], [0, 7, 4, 6], [0, 4, 5, 6], [0, 5, 1, 6]])
_WEDGES = np.array([[0, 1, 3, 4, 5, 7], [1, 2, 3, 5, 6, 7]])
_TET10_EDGES = np.array([[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]])

#: the hexahedron each conversion starts from
SOURCE = {"tet4": "hex8", "tet10": "hex8", "wedge6": "hex8", "hex20": "hex27"}


def convert(mesh: Mesh, cell: str, elements: np.ndarray | None = None) -> Mesh:
    """``mesh`` (hex8, or hex27 for hex20) as a mesh of ``cell``; with ``elements`` (hex8 -> wedge6 only) just those
    bricks, the others kept: a mixed mesh of the bricks, then the wedges (conforming where every column of bricks
    along z is split or kept whole)."""
    if mesh.cell_type != SOURCE[cell]:
        raise ValueError(f"{cell} meshes are made from {SOURCE[cell]} meshes, not {mesh.cell_type}")
    if elements is not None:
        return _split_part(mesh, np.unique(np.asarray(elements, dtype=np.int64)), cell)
    X, h = mesh.points, mesh.cells
    if cell == "hex20":
        cells, per = h[:, :20], 1
    elif cell == "wedge6":
        cells, per = h[:, _WEDGES].reshape(-1, 6), 2
    else:
        cells, per = h[:, _TETS].reshape(-1, 4), 6
    uniq = np.zeros((0, 2), dtype=np.int64)
    if cell == "tet10":
        key = np.sort(cells[:, _TET10_EDGES].reshape(-1, 2), axis=1)
        uniq, inv = np.unique(key, axis=0, return_inverse=True)
        X = np.vstack([X, 0.5 * (X[uniq[:, 0]] + X[uniq[:, 1]])])
        cells = np.hstack([cells, len(mesh.points) + inv.reshape(-1, 6)])
    used = np.unique(cells)
    new = np.full(len(X), -1, dtype=np.int64)
    new[used] = np.arange(used.size)
    out = Mesh(X[used], cell, new[cells])
    for name, nodes in mesh.node_sets.items():
        inside = np.zeros(len(mesh.points), dtype=bool)
        inside[nodes] = True
        mids = len(mesh.points) + np.flatnonzero(inside[uniq[:, 0]] & inside[uniq[:, 1]])  # edges within the set
        k = new[np.concatenate([nodes, mids])]
        if np.any(k >= 0):
            out.add_node_set(name, k[k >= 0])
    for name, elems in mesh.element_sets.items():
        out.element_sets[name] = (per * np.asarray(elems)[:, None] + np.arange(per)).ravel()
    if cell in FACE_TYPE or cell == "wedge6":
        for name, faces in mesh.face_sets.items():
            corners = new[np.unique(faces[:, :4])]
            try:
                f = faces_on_nodes(out, corners[corners >= 0], corners_only=True)
            except ValueError:  # wedges: triangles and quadrilaterals on these nodes (no face set of one type)
                continue
            if len(f):
                out.add_face_set(name, f)
    return out


def _split_part(mesh: Mesh, elements: np.ndarray, cell: str) -> Mesh:
    """The bricks ``elements`` of a hex8 mesh cut into two wedges each, the others kept (before them)."""
    if cell != "wedge6":
        raise ValueError(f"only wedges (not {cell}) replace part of a hex8 mesh: their quadrilateral faces meet the "
                         f"bricks'")
    split = np.zeros(mesh.n_cells, dtype=bool)
    split[elements] = True
    kept = np.flatnonzero(~split)
    out = Mesh.of_blocks(mesh.points, [("hex8", mesh.cells[kept]), ("wedge6", mesh.cells[elements][:, _WEDGES]
                                                                     .reshape(-1, 6))])
    out.node_sets = {k: v.copy() for k, v in mesh.node_sets.items()}
    where = np.empty(mesh.n_cells, dtype=np.int64)
    where[kept] = np.arange(kept.size)
    where[elements] = kept.size + 2 * np.arange(elements.size)
    for name, elems in mesh.element_sets.items():
        e = np.asarray(elems)
        out.element_sets[name] = np.unique(np.concatenate([where[e[~split[e]]], where[e[split[e]]],
                                                           where[e[split[e]]] + 1]))
    for name, faces in mesh.face_sets.items():
        try:
            f = faces_on_nodes(out, np.unique(faces), corners_only=True)
        except ValueError:  # triangles and quadrilaterals on these nodes (no face set of one type)
            continue
        if len(f):
            out.add_face_set(name, f)
    return out
