"""Structured planar meshes (x-y plane) for plane strain, plane stress and axisymmetric bodies: a rectangle, an
annulus sector and a full disc (an O-grid), of quad4, quad8, quad9, tri3 or tri6 cells, with named node and edge sets.

A structured lattice of parameters u in [0, 1]^2 (with mid-nodes at the parameter midpoints for the quadratic
cells) is mapped through the exact geometry, so the mid-nodes of an annulus lie on its circles. Triangles split each
lattice square along one diagonal (tri6: the quad9 square, its centre the diagonal's mid-node). Every cell is
counter-clockwise; an edge set is made for every node set whose nodes carry boundary edges.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from ..fem.planar_cells import PLANAR_CELLS
from .faces import boundary_faces
from .mesh import Mesh

# local lattice offsets (i, j) of each cell's nodes, in steps of one (linear) or one half (quadratic) cell
_Q4 = [(0, 0), (1, 0), (1, 1), (0, 1)]
_Q9 = [(0, 0), (2, 0), (2, 2), (0, 2), (1, 0), (2, 1), (1, 2), (0, 1), (1, 1)]
_T3 = [[(0, 0), (1, 0), (1, 1)], [(0, 0), (1, 1), (0, 1)]]
_T6 = [[(0, 0), (2, 0), (2, 2), (1, 0), (2, 1), (1, 1)], [(0, 0), (2, 2), (0, 2), (1, 1), (1, 2), (0, 1)]]


def _check(cell: str) -> None:
    if cell not in PLANAR_CELLS:
        raise ValueError(f"unknown planar cell type {cell!r}; use one of {', '.join(PLANAR_CELLS)}")


def _count(name: str, value) -> int:
    if int(value) != value or value < 1:
        raise ValueError(f"{name} must be a positive integer, got {value!r}")
    return int(value)


def _positive(name: str, value) -> float:
    if not float(value) > 0.0:
        raise ValueError(f"{name} must be positive, got {value!r}")
    return float(value)


def _lattice(cell: str, n0: int, n1: int, bias0: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Parameters U (m, 2) and cells of an n0 x n1 lattice of ``cell`` (direction 0 fastest); element sizes in
    direction 0 grow by the ratio ``bias0`` from one to the next."""
    p = 1 if cell in ("quad4", "tri3") else 2
    if bias0 == 1.0:
        b0 = np.linspace(0.0, 1.0, n0 + 1)
    else:
        h = bias0 ** np.arange(n0)
        b0 = np.concatenate([[0.0], np.cumsum(h) / h.sum()])
        b0[-1] = 1.0  # exactly: the last row of nodes makes the "outer" and "xmax" sets
    b1 = np.linspace(0.0, 1.0, n1 + 1)

    def refine(b):
        if p == 1:
            return b
        u = np.empty(2 * b.size - 1)
        u[0::2], u[1::2] = b, 0.5 * (b[:-1] + b[1:])
        return u

    u0, u1 = refine(b0), refine(b1)
    m0 = u0.size
    g1, g0 = np.meshgrid(u1, u0, indexing="ij")
    U = np.column_stack([g0.ravel(), g1.ravel()])
    cells = []
    for j in range(n1):
        for i in range(n0):
            def node(di, dj):
                return (p * j + dj) * m0 + p * i + di
            if cell == "quad4":
                cells.append([node(*o) for o in _Q4])
            elif cell in ("quad8", "quad9"):
                c = [node(*o) for o in _Q9]
                cells.append(c[:8] if cell == "quad8" else c)
            elif cell == "tri3":
                cells += [[node(*o) for o in t] for t in _T3]
            else:
                cells += [[node(*o) for o in t] for t in _T6]
    return U, np.array(cells, dtype=np.int64)


def _build(cell: str, U: np.ndarray, cells: np.ndarray, place: Callable[[np.ndarray], np.ndarray],
           sets: dict[str, np.ndarray]) -> Mesh:
    """The mesh of the lattice placed by ``place`` (U -> (m, 2) x-y points), unused nodes (quad8 centres) dropped,
    with the node sets ``sets`` (masks over U) and their edge sets."""
    used = np.unique(cells)
    new = np.full(len(U), -1, dtype=np.int64)
    new[used] = np.arange(used.size)
    xy = place(U[used])
    X = np.column_stack([xy, np.zeros(len(used))])
    mesh = Mesh(X, cell, new[cells])
    faces, _, _ = boundary_faces(mesh)
    for name, mask in sets.items():
        nodes = new[np.flatnonzero(mask)]
        nodes = nodes[nodes >= 0]
        if not nodes.size:
            continue
        mesh.add_node_set(name, nodes)
        if name == "all":
            continue
        on = np.zeros(mesh.n_nodes, dtype=bool)
        on[nodes] = True
        f = faces[np.all(on[faces], axis=1)]
        if len(f):
            mesh.add_face_set(name, f)
    return mesh


def rectangle(lx: float, ly: float, nx: int, ny: int, cell: str = "quad4",
              origin: Sequence[float] = (0.0, 0.0)) -> Mesh:
    """Rectangle [0, lx] x [0, ly] + origin in the x-y plane with nx x ny cells (tri3, tri6: 2 nx ny triangles).

    Sets: node and edge sets "xmin", "xmax", "ymin", "ymax"; node set "all". For an axisymmetric body x is the
    radius (origin[0] >= 0) and y the axis.
    """
    _check(cell)
    size = np.array([_positive("lx", lx), _positive("ly", ly)])
    U, cells = _lattice(cell, _count("nx", nx), _count("ny", ny))
    o = np.asarray(origin, dtype=float).reshape(-1)[:2]
    sets = {"all": np.ones(len(U), dtype=bool), "xmin": U[:, 0] == 0.0, "xmax": U[:, 0] == 1.0,
            "ymin": U[:, 1] == 0.0, "ymax": U[:, 1] == 1.0}
    return _build(cell, U, cells, lambda u: o + u * size, sets)


def annulus(r_inner: float, r_outer: float, nr: int, nt: int, angle: float = 90.0, cell: str = "quad8",
            center: Sequence[float] = (0.0, 0.0), bias: float = 1.0) -> Mesh:
    """Annulus sector r_inner <= r <= r_outer, 0 <= theta <= angle (degrees, at most 360) about ``center`` in the x-y
    plane, nr cells across the wall (sizes growing outward by the ratio ``bias``) and nt around.

    Sets: node and edge sets "inner", "outer" (the circles), "angle0" (theta = 0, along +x), "angle1" (theta =
    angle); node set "all". A full ring (angle = 360) is closed: its angle0 and angle1 nodes are one.
    """
    _check(cell)
    a, b = _positive("r_inner", r_inner), _positive("r_outer", r_outer)
    if not b > a:
        raise ValueError(f"r_outer must exceed r_inner, got {r_outer!r} <= {r_inner!r}")
    ang = _positive("angle", angle)
    if ang > 360.0:
        raise ValueError(f"angle must lie in (0, 360] degrees, got {angle!r}")
    U, cells = _lattice(cell, _count("nr", nr), _count("nt", nt), _positive("bias", bias))
    c = np.asarray(center, dtype=float).reshape(-1)[:2]
    closed = ang == 360.0
    if closed:  # the last column of lattice nodes is the first
        m = len(U)
        first = np.flatnonzero(U[:, 1] == 0.0)
        last = np.flatnonzero(U[:, 1] == 1.0)
        alias = np.arange(m)
        alias[last] = first[np.argsort(U[first, 0])][np.argsort(np.argsort(U[last, 0]))]
        cells = alias[cells]
    sets = {"all": np.ones(len(U), dtype=bool), "inner": U[:, 0] == 0.0, "outer": U[:, 0] == 1.0}
    if not closed:
        sets["angle0"], sets["angle1"] = U[:, 1] == 0.0, U[:, 1] == 1.0

    def place(u):
        r = a + (b - a) * u[:, 0]
        t = math.radians(ang) * u[:, 1]
        return c + np.column_stack([r * np.cos(t), r * np.sin(t)])

    return _build(cell, U, cells, place, sets)


def disc(radius: float, n: int, nr: int, cell: str = "quad4", center: Sequence[float] = (0.0, 0.0),
         core: float = 0.5, bias: float = 1.0) -> Mesh:
    """A full disc of ``radius`` about ``center`` in the x-y plane by an O-grid: a square core of n x n cells (half
    side ``core`` times the radius) and four blocks of nr x n cells between its sides and the circle (nr across,
    sizes changing outward by the ratio ``bias``: below 1 refines toward the circle). Mid-nodes lie on the exact
    geometry (those of the circle on it). An axisymmetric O-ring section is a disc with center = (mean radius, 0).

    Sets: node and edge set "outer" (the circle); node sets "all", "core" (the square), "top", "bottom", "left",
    "right" (the nodes of the circle with y - cy >= 0, <= 0, x - cx <= 0, >= 0) with their edge sets.
    """
    _check(cell)
    a = _positive("radius", radius)
    n = _count("n", n)
    nr = _count("nr", nr)
    s = _positive("core", core) * a
    if not 0.0 < core < 0.9:
        raise ValueError(f"core must lie in (0, 0.9), got {core!r}")
    c = np.asarray(center, dtype=float).reshape(-1)[:2]
    pts, cls, outer = [], [], []
    offset = 0
    # the core
    U, cells = _lattice(cell, n, n)
    pts.append(-s + 2.0 * s * U)
    cls.append(cells)
    outer.append(np.zeros(len(U), dtype=bool))
    offset += len(U)
    for k in range(4):  # east, north, west, south: u0 outward, u1 counter-clockwise
        U, cells = _lattice(cell, nr, n, _positive("bias", bias))
        t = U[:, 1]
        inner = np.column_stack([np.full(len(U), s), -s + 2.0 * s * t])
        th = math.pi / 2.0 * (t - 0.5)
        out = a * np.column_stack([np.cos(th), np.sin(th)])
        xy = (1.0 - U[:, [0]]) * inner + U[:, [0]] * out
        ck, sk = math.cos(k * math.pi / 2.0), math.sin(k * math.pi / 2.0)
        xy = xy @ np.array([[ck, sk], [-sk, ck]])
        pts.append(xy)
        cls.append(cells + offset)
        outer.append(U[:, 0] == 1.0)
        offset += len(U)
    xy = np.concatenate(pts)
    cells = np.concatenate(cls)
    on_circle = np.concatenate(outer)
    # merge the nodes the blocks share (equal coordinates up to round-off)
    key = np.round(xy / (a * 1e-9)).astype(np.int64)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.ravel()
    cells = inverse[cells]
    xy = xy[first]
    circle = np.zeros(len(first), dtype=bool)
    circle[inverse[on_circle]] = True
    used = np.unique(cells)
    new = np.full(len(first), -1, dtype=np.int64)
    new[used] = np.arange(used.size)
    xy = xy[used]
    circle = circle[used]
    X = np.column_stack([c + xy, np.zeros(len(used))])
    mesh = Mesh(X, cell, new[cells])
    faces, _, _ = boundary_faces(mesh)
    tol = 1e-9 * a
    sets = {"all": np.ones(len(used), dtype=bool), "core": np.all(np.abs(xy) <= s + tol, axis=1), "outer": circle,
            "top": circle & (xy[:, 1] >= -tol), "bottom": circle & (xy[:, 1] <= tol),
            "left": circle & (xy[:, 0] <= tol), "right": circle & (xy[:, 0] >= -tol)}
    _node_and_edge_sets(mesh, sets, faces)
    return mesh


def _node_and_edge_sets(mesh: Mesh, sets: dict, faces: np.ndarray) -> None:
    """Each mask of ``sets`` as a node set of ``mesh`` and (but "all" and "core") as the edge set of the boundary
    ``faces`` whose nodes all lie in it."""
    for name, mask in sets.items():
        nodes = np.flatnonzero(mask)
        mesh.add_node_set(name, nodes)
        if name in ("all", "core"):
            continue
        on = np.zeros(mesh.n_nodes, dtype=bool)
        on[nodes] = True
        f = faces[np.all(on[faces], axis=1)]
        if len(f):
            mesh.add_face_set(name, f)


def quarter_disc(radius: float, n: int, nr: int, cell: str = "quad4", center: Sequence[float] = (0.0, 0.0),
                 core: float = 0.5, bias: float = 1.0) -> Mesh:
    """The quarter x >= cx, y >= cy of :func:`disc` (n, which must be even, the cells along the quarter circle; the
    other arguments as there): a ball's or a cylinder's section with its symmetry lines on the axes (an axisymmetric
    ball: center on the axis, x = cx).

    Sets: node and edge sets "arc" (the quarter circle), "xmin" (the line x = cx) and "ymin" (y = cy); node sets
    "all" and "core" (the square's quarter).
    """
    n = _count("n", n)
    if n % 2:
        raise ValueError(f"n must be even (the cells along the quarter circle, half of each of two O-grid blocks), "
                         f"got {n}")
    whole = disc(radius, n, nr, cell, (0.0, 0.0), core, bias)
    nc = 3 if cell.startswith("tri") else 4
    centre = whole.points[whole.cells[:, :nc]].mean(axis=1)
    cells = whole.cells[(centre[:, 0] > 0.0) & (centre[:, 1] > 0.0)]
    used = np.unique(cells)
    new = np.full(whole.n_nodes, -1, dtype=np.int64)
    new[used] = np.arange(used.size)
    xy = whole.points[used, :2].copy()
    tol = 1e-9 * float(radius)
    xy[np.abs(xy) < tol] = 0.0
    c = np.asarray(center, dtype=float).reshape(-1)[:2]
    mesh = Mesh(np.column_stack([c + xy, np.zeros(len(used))]), cell, new[cells])
    faces, _, _ = boundary_faces(mesh)
    core_nodes = np.isin(used, whole.node_sets["core"])
    sets = {"all": np.ones(len(used), dtype=bool), "core": core_nodes,
            "arc": np.abs(np.hypot(xy[:, 0], xy[:, 1]) - float(radius)) < tol,
            "xmin": xy[:, 0] == 0.0, "ymin": xy[:, 1] == 0.0}
    _node_and_edge_sets(mesh, sets, faces)
    return mesh


for _fn in (rectangle, annulus, disc, quarter_disc):
    _fn.planar = True
