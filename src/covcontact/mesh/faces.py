"""Local face tables, boundary faces and orientation checks of hexahedral meshes.

A face is listed with the node order of a ``quad4`` or ``quad9`` facet (corners counter-clockwise
seen from outside, then edge mid-nodes 0-1, 1-2, 2-3, 3-0, then the centre), so that the facet
normal rho_1 x rho_2 points out of the element. The tables are built from the natural node
coordinates of ``covcontact.fem.shapes``: each face is a map (xi1, xi2) -> (r, s, t) of the
reference cube whose tangents have an outward cross product.

``hex8`` and ``hex27`` have six faces (x-, x+, y-, y+, z-, z+). ``hex18`` has only its two quad9
faces t = -1 and t = +1: its side faces are 3 x 2 nodes and are never contact faces.
"""

from __future__ import annotations

import numpy as np

from ..fem import cells as other_cells
from ..fem.quadrature import default_rule
from ..fem.shapes import NODES, shape_functions
from ..fem.planar_cells import CENTRE as PLANAR_CENTRE
from ..fem.planar_cells import EDGES as PLANAR_EDGES
from ..fem.planar_cells import reference_jacobians
from .mesh import Mesh

# face label -> (fixed axis, fixed value, axis of xi1, axis of xi2); tangents e_(xi1) x e_(xi2)
# equal the outward normal (sign of the fixed value) times e_(fixed axis)
_FACE_MAPS = {
    "x-": (0, -1.0, 2, 1),
    "x+": (0, 1.0, 1, 2),
    "y-": (1, -1.0, 0, 2),
    "y+": (1, 1.0, 2, 0),
    "z-": (2, -1.0, 1, 0),
    "z+": (2, 1.0, 0, 1),
}

#: local face labels of each cell type, in the order of the rows of ``FACES``
FACE_LABELS = {
    "hex8": ("x-", "x+", "y-", "y+", "z-", "z+"),
    "hex27": ("x-", "x+", "y-", "y+", "z-", "z+"),
    "hex18": ("z-", "z+"),
}


def _face_table(cell: str, face: str) -> np.ndarray:
    ftype = "quad4" if cell == "hex8" else "quad9"
    axis, value, a1, a2 = _FACE_MAPS[face]
    nat = NODES[cell]
    rows = []
    for xi1, xi2 in NODES[ftype]:
        x = np.empty(3)
        x[axis], x[a1], x[a2] = value, xi1, xi2
        hit = np.nonzero(np.all(np.abs(nat - x) < 1e-12, axis=1))[0]
        rows.append(int(hit[0]))
    return np.array(rows, dtype=np.int64)


#: cell type -> (nface, 4 | 9) local node indices of its contact faces, outward ordered
FACES = {c: np.stack([_face_table(c, f) for f in labels]) for c, labels in FACE_LABELS.items()}


def _tet_faces(quadratic: bool) -> np.ndarray:
    """The four faces of a tetrahedron, corners counter-clockwise seen from outside (the opposite vertex behind),
    then (tet10) the mid-nodes of the face's edges in the tri6 order."""
    from ..fem.cells import NODES as CELL_NODES

    nat = CELL_NODES["tet10"]
    mids = {frozenset(e): 4 + k for k, e in enumerate([(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)])}
    rows = []
    for opposite in (3, 2, 0, 1):
        a, b, c = [v for v in range(4) if v != opposite]
        if np.dot(np.cross(nat[b] - nat[a], nat[c] - nat[a]), nat[opposite] - nat[a]) > 0:
            b, c = c, b
        row = [a, b, c]
        if quadratic:
            row += [mids[frozenset((a, b))], mids[frozenset((b, c))], mids[frozenset((c, a))]]
        rows.append(row)
    return np.array(rows, dtype=np.int64)


def _outward(nat: np.ndarray, rows: list[list[int]]) -> np.ndarray:
    """Face corner rows of a cell with natural node coordinates ``nat``, each turned so that its normal
    (first three corners' cross product) points away from the cell's centroid."""
    centre = nat.mean(axis=0)
    out = []
    for row in rows:
        a, b, c = nat[row[0]], nat[row[1]], nat[row[2]]
        out.append(row if np.dot(np.cross(b - a, c - a), a - centre) > 0 else [row[0]] + row[1:][::-1])
    return np.array(out, dtype=np.int64)


FACES["tet4"] = _tet_faces(False)
FACES["tet10"] = _tet_faces(True)
FACES["hex20"] = FACES["hex27"][:, :8].copy()  # the hex27's faces without their centres (hex20 = its first 20 nodes)
#: wedge6 faces by type: the triangles 0-1-2 and 3-4-5, the quadrilaterals through the edges 0-3, 1-4, 2-5
WEDGE_FACES = {"tri3": _outward(other_cells.NODES["wedge6"], [[0, 1, 2], [3, 4, 5]]),
               "quad4": _outward(other_cells.NODES["wedge6"], [[0, 1, 4, 3], [1, 2, 5, 4], [2, 0, 3, 5]])}


def _corners(ftype_nodes: int) -> int:
    """Corners of a face of ``ftype_nodes`` nodes: triangles 3, quadrilaterals 4."""
    return 3 if ftype_nodes in (3, 6) else 4


def cell_face_tables(cell_type: str) -> list[np.ndarray]:
    """The face tables of a cell type: one, or for wedges the triangles', then the quadrilaterals' (planar cells:
    their edges)."""
    if cell_type in PLANAR_EDGES:
        return [PLANAR_EDGES[cell_type]]
    return list(WEDGE_FACES.values()) if cell_type == "wedge6" else [FACES[cell_type]]


def _ncorners(mesh: Mesh, nfn: int) -> int:
    """Corners of a face of ``nfn`` nodes of ``mesh``: edges of planar meshes 2, else :func:`_corners`."""
    return 2 if mesh.is_planar else _corners(nfn)


def _face_sizes(mesh: Mesh) -> list[int]:
    """Nodes per face of the mesh's face types (triangles first)."""
    return sorted({t.shape[1] for c in mesh.cell_types for t in cell_face_tables(c)})


def boundary_faces(mesh: Mesh, nfn: int | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Faces used by exactly one element (for hex18 only the t = -1 and t = +1 faces); of a mesh with triangular
    and quadrilateral faces (wedges, mixed meshes) those of ``nfn`` nodes (3: triangles, 4: quadrilaterals; default
    the first of its face types).

    Returns:
        faces (nf, nfn) outward ordered, elem (nf,) owning element, local_face (nf,) row of the owner's cell type's
        face table of that face type (``FACES``, ``WEDGE_FACES``).
    """
    sizes = _face_sizes(mesh)
    nfn = sizes[0] if nfn is None or nfn not in sizes else nfn
    allf, elem, local = [], [], []
    for b in mesh.blocks:
        table = next((t for t in cell_face_tables(b.cell_type) if t.shape[1] == nfn), None)
        if table is None:
            continue
        nlf = table.shape[0]
        allf.append(b.cells[:, table].reshape(-1, nfn))
        k = np.arange(len(b.cells) * nlf)
        elem.append(b.first + k // nlf)
        local.append(k % nlf)
    allf = np.concatenate(allf)
    corners = np.sort(allf[:, :_ncorners(mesh, nfn)], axis=1)
    _, inv, cnt = np.unique(corners, axis=0, return_inverse=True, return_counts=True)
    idx = np.nonzero(cnt[inv.ravel()] == 1)[0]
    return np.ascontiguousarray(allf[idx]), np.concatenate(elem)[idx], np.concatenate(local)[idx]


def all_boundary_faces(mesh: Mesh) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """:func:`boundary_faces` of every face type of the mesh (one, or two for wedges and mixed meshes)."""
    return [boundary_faces(mesh, n) for n in _face_sizes(mesh)]


def nonconforming_cells(mesh: Mesh) -> np.ndarray:
    """Pairs (cell with a triangular face, cell with a quadrilateral face) where the triangle's corners are three
    corners of the quadrilateral (a tetrahedron or wedge against a brick: the mesh is not conforming), (n, 2)."""
    sizes = _face_sizes(mesh)
    if 3 not in sizes or 4 not in sizes:
        return np.zeros((0, 2), dtype=np.int64)
    tri, tel, _ = boundary_faces(mesh, 3)
    quad, qel, _ = boundary_faces(mesh, 4)
    sub = np.sort(quad[:, [[0, 1, 2], [1, 2, 3], [2, 3, 0], [3, 0, 1]]], axis=2).reshape(-1, 3)
    keys = np.sort(tri, axis=1)
    both = np.concatenate([sub, keys])
    _, inv = np.unique(both, axis=0, return_inverse=True)
    inv = inv.ravel()
    owner = np.full(inv.max() + 1, -1, dtype=np.int64)
    owner[inv[: len(sub)]] = np.repeat(qel, 4)
    hit = owner[inv[len(sub):]]
    return np.column_stack([tel[hit >= 0], hit[hit >= 0]])


def faces_on_nodes(mesh: Mesh, node_ids: np.ndarray, corners_only: bool = False) -> np.ndarray:
    """Boundary faces (outward ordered) whose nodes (or corners) all lie in ``node_ids``. On a wedge mesh the faces
    of one type: a ValueError if both types have such faces (a face set holds one type)."""
    mask = np.zeros(mesh.n_nodes, dtype=bool)
    mask[np.asarray(node_ids, dtype=np.int64)] = True
    found = []
    for faces, _, _ in all_boundary_faces(mesh):
        part = faces[:, :_ncorners(mesh, faces.shape[1])] if corners_only else faces
        found.append(np.ascontiguousarray(faces[np.all(mask[part], axis=1)]))
    hit = [f for f in found if len(f)]
    if len(hit) > 1:
        raise ValueError(f"these nodes carry {len(hit[0])} triangular and {len(hit[1])} quadrilateral faces; a face "
                         f"set holds faces of one type")
    return hit[0] if hit else found[0]


def match_boundary_faces(mesh: Mesh, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Outward-ordered boundary faces with the same corners as ``faces`` (any order; on a wedge mesh triangles
    are matched with 3 corners given, quadrilaterals with 4 or more).

    Returns:
        matched (nm, nfn) boundary faces in the order of ``faces``, and found (nf,) bool.
    """
    given = np.asarray(faces).shape[1] if np.ndim(faces) == 2 else 4
    bf, _, _ = boundary_faces(mesh, 3 if given == 3 else 4) if len(_face_sizes(mesh)) > 1 else boundary_faces(mesh)
    nc = _ncorners(mesh, bf.shape[1])
    query = np.sort(np.asarray(faces, dtype=np.int64)[:, :nc], axis=1)
    if query.shape[0] == 0 or bf.shape[0] == 0:
        return np.empty((0, bf.shape[1]), dtype=np.int64), np.zeros(query.shape[0], dtype=bool)
    keys = np.sort(bf[:, :nc], axis=1)
    both = np.concatenate([keys, query])
    _, inv = np.unique(both, axis=0, return_inverse=True)
    inv = inv.ravel()
    owner = np.full(inv.max() + 1, -1, dtype=np.int64)
    owner[inv[: keys.shape[0]]] = np.arange(keys.shape[0])
    hit = owner[inv[keys.shape[0]:]]
    found = hit >= 0
    return np.ascontiguousarray(bf[hit[found]]), found


def face_normals(points: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Unnormalised normals rho_1 x rho_2 at the centre (0, 0) of each face, (nf, 3) (triangles and quad8: the
    cross product of the corner diagonals or edges, the same direction)."""
    if faces.shape[1] in (3, 6):
        x = points[faces]
        return np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
    if faces.shape[1] == 8:
        x = points[faces]
        return np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 1])
    ftype = "quad4" if faces.shape[1] == 4 else "quad9"
    _, dN, _ = shape_functions(ftype, np.zeros((1, 2)))
    rho = np.einsum("fai,aj->fji", points[faces], dN[0])
    return np.cross(rho[:, 0], rho[:, 1])


def edge_normals(points: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """Unnormalised outward normals of the edges of a planar mesh: the chord from the first to the second corner
    turned clockwise, (t_y, -t_x, 0), (nf, 3)."""
    t = points[edges[:, 1]] - points[edges[:, 0]]
    return np.column_stack([t[:, 1], -t[:, 0], np.zeros(len(t))])


def jacobian_determinants(mesh: Mesh, points: np.ndarray | None = None) -> np.ndarray:
    """det(dX/dxi) of every element of a mesh of one cell type at natural ``points`` (npts, 3), (nelem, npts).

    The default points are the full Gauss rule of the cell type.
    """
    mesh.connectivity()
    if mesh.cell_type in PLANAR_EDGES:
        return reference_jacobians(mesh.cell_type, mesh.points, mesh.cells, points)
    if mesh.cell_type in other_cells.CELLS:
        pts = other_cells.rule(mesh.cell_type)[0] if points is None else np.atleast_2d(points)
        dN = other_cells.shapes(mesh.cell_type, pts)[1]
    else:
        pts = default_rule(mesh.cell_type)[0] if points is None else np.atleast_2d(points)
        _, dN, _ = shape_functions(mesh.cell_type, pts)
    J = np.einsum("eai,paj->epij", mesh.points[mesh.cells], dN)
    return np.asarray(np.linalg.det(J))


#: natural coordinates of the centre of each cell type (hexahedra: the origin)
_CENTRE = {"tet4": (0.25, 0.25, 0.25), "tet10": (0.25, 0.25, 0.25), "wedge6": (1.0 / 3.0, 1.0 / 3.0, 0.0)}


def check_orientation(mesh: Mesh) -> list[int]:
    """Elements whose Jacobian at the element centre is not positive (inverted node order)."""
    bad = []
    for first, piece in mesh.pieces():
        centre = PLANAR_CENTRE.get(piece.cell_type) or _CENTRE.get(piece.cell_type, (0.0, 0.0, 0.0))
        det = jacobian_determinants(piece, np.array([centre]))[:, 0]
        bad += [first + int(e) for e in np.nonzero(~(det > 0.0))[0]]
    return bad
