"""Shape functions and integration rules of the volume cells that are not tensor products of 1D Lagrange bases:
tetrahedra (tet4, tet10), the linear wedge (wedge6) and the 20-node serendipity brick (hex20).

Node orders follow VTK (and meshio):

- ``tet4``: (0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1) in the natural coordinates (r, s, t) of the unit
  tetrahedron, L0 = 1 - r - s - t.
- ``tet10``: the corners, then the edge mid-nodes 0-1, 1-2, 2-0, 0-3, 1-3, 2-3.
- ``wedge6``: the triangle (0, 0), (1, 0), (0, 1) at zeta = -1, then at zeta = +1.
- ``hex20``: the hex8 corners (the natural coordinates of covcontact.fem.shapes), then the edge mid-nodes 0-1,
  1-2, 2-3, 3-0, 4-5, 5-6, 6-7, 7-4, 0-4, 1-5, 2-6, 3-7 (the first 20 nodes of the hex27).

Evaluated in numpy: the elements call them once, at their integration points.
"""

from __future__ import annotations

import functools

import numpy as np

from .quadrature import gauss_1d, gauss_tensor

CELLS = ("tet4", "tet10", "wedge6", "hex20")
NNODES = {"tet4": 4, "tet10": 10, "wedge6": 6, "hex20": 20}

_TET_NODES = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
_TET10_EDGES = np.array([[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]])
_HEX8 = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                  [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=float)
_HEX20_EDGES = np.array([[0, 1], [1, 2], [2, 3], [3, 0], [4, 5], [5, 6], [6, 7], [7, 4],
                         [0, 4], [1, 5], [2, 6], [3, 7]])

#: natural coordinates of the nodes
NODES = {
    "tet4": _TET_NODES,
    "tet10": np.vstack([_TET_NODES, 0.5 * (_TET_NODES[_TET10_EDGES[:, 0]] + _TET_NODES[_TET10_EDGES[:, 1]])]),
    "wedge6": np.array([[0, 0, -1], [1, 0, -1], [0, 1, -1], [0, 0, 1], [1, 0, 1], [0, 1, 1]], dtype=float),
    "hex20": np.vstack([_HEX8, 0.5 * (_HEX8[_HEX20_EDGES[:, 0]] + _HEX8[_HEX20_EDGES[:, 1]])]),
}


def _barycentric(p):
    r, s, t = p[:, 0], p[:, 1], p[:, 2]
    L = np.stack([1.0 - r - s - t, r, s, t], axis=1)
    dL = np.array([[-1.0, -1.0, -1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    return L, dL


def shapes(cell: str, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """N (npts, nen) and dN/dxi (npts, nen, 3) of ``cell`` at ``points`` (npts, 3)."""
    p = np.atleast_2d(np.asarray(points, dtype=np.float64))
    n = len(p)
    if cell == "tet4":
        L, dL = _barycentric(p)
        return L, np.broadcast_to(dL, (n, 4, 3)).copy()
    if cell == "tet10":
        L, dL = _barycentric(p)
        N = np.empty((n, 10))
        dN = np.empty((n, 10, 3))
        N[:, :4] = L * (2.0 * L - 1.0)
        dN[:, :4] = (4.0 * L - 1.0)[:, :, None] * dL[None]
        a, b = _TET10_EDGES[:, 0], _TET10_EDGES[:, 1]
        N[:, 4:] = 4.0 * L[:, a] * L[:, b]
        dN[:, 4:] = 4.0 * (L[:, a, None] * dL[None, b] + L[:, b, None] * dL[None, a])
        return N, dN
    if cell == "wedge6":
        r, s, z = p[:, 0], p[:, 1], p[:, 2]
        T = np.stack([1.0 - r - s, r, s], axis=1)
        dT = np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]])
        N = np.empty((n, 6))
        dN = np.empty((n, 6, 3))
        for k, sz in enumerate((-1.0, 1.0)):
            h = 0.5 * (1.0 + sz * z)
            N[:, 3 * k: 3 * k + 3] = T * h[:, None]
            dN[:, 3 * k: 3 * k + 3, :2] = h[:, None, None] * dT[None]
            dN[:, 3 * k: 3 * k + 3, 2] = T * 0.5 * sz
        return N, dN
    if cell == "hex20":
        X = NODES["hex20"]
        N = np.empty((n, 20))
        dN = np.empty((n, 20, 3))
        for a in range(20):
            xa = X[a]
            f = 1.0 + p * xa  # (n, 3): 1 + xi_i xi_ai
            if a < 8:
                s = (p * xa).sum(axis=1) - 2.0
                prod = f.prod(axis=1)
                N[:, a] = 0.125 * prod * s
                for i in range(3):
                    others = np.prod(np.delete(f, i, axis=1), axis=1)
                    dN[:, a, i] = 0.125 * xa[i] * (others * s + prod)
            else:
                zero = int(np.flatnonzero(xa == 0.0)[0])  # the direction along the edge
                g = np.where(np.arange(3) == zero, 1.0 - p ** 2, f)
                N[:, a] = 0.25 * g.prod(axis=1)
                for i in range(3):
                    others = np.prod(np.delete(g, i, axis=1), axis=1)
                    dg = -2.0 * p[:, i] if i == zero else xa[i] * np.ones(n)
                    dN[:, a, i] = 0.25 * dg * others
        return N, dN
    raise ValueError(f"unknown cell type {cell!r}; known: {', '.join(CELLS)}")


def _tet_rule(n: int) -> tuple[np.ndarray, np.ndarray]:
    if n == 1:
        return np.array([[0.25, 0.25, 0.25]]), np.array([1.0 / 6.0])
    if n == 4:  # degree 2
        a, b = 0.5854101966249685, 0.1381966011250105
        pts = np.array([[b, b, b], [a, b, b], [b, a, b], [b, b, a]])
        return pts, np.full(4, 1.0 / 24.0)
    if n == 11:  # Keast, degree 4
        a, b = 0.0714285714285714, 0.785714285714286
        c, d = 0.399403576166799, 0.100596423833201
        pts = [[0.25, 0.25, 0.25], [a, a, a], [b, a, a], [a, b, a], [a, a, b],
               [c, d, d], [d, c, d], [d, d, c], [c, c, d], [c, d, c], [d, c, c]]
        w = [-0.01315555555555555] + [0.007622222222222222] * 4 + [0.02488888888888889] * 6
        return np.array(pts), np.array(w)
    raise ValueError(f"tetrahedra have 1, 4 and 11 point rules, not {n}")


def _triangle_rule() -> tuple[np.ndarray, np.ndarray]:
    """3 points, degree 2, on the unit triangle (area 1/2)."""
    return np.array([[1 / 6, 1 / 6], [2 / 3, 1 / 6], [1 / 6, 2 / 3]]), np.full(3, 1.0 / 6.0)


#: default rules: tet4 1 point, tet10 4 points, wedge6 3 x 2, hex20 3 x 3 x 3
DEFAULT_POINTS = {"tet4": 1, "tet10": 4, "wedge6": 6, "hex20": 27}


def rule(cell: str, npts: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(points (n, 3), weights (n,)) of ``cell``: ``npts`` points (tet: 1, 4, 11; wedge6: 6; hex20: 27 or 8, the
    reduced rule of C3D20R), by default :data:`DEFAULT_POINTS`."""
    npts = npts or DEFAULT_POINTS[cell]
    if cell in ("tet4", "tet10"):
        return _tet_rule(npts)
    if cell == "wedge6":
        if npts != 6:
            raise ValueError("wedge6 has a 6 point rule (3 in the triangle, 2 across)")
        tp, tw = _triangle_rule()
        zp, zw = gauss_1d(2)
        pts = np.array([[a, b, z] for (a, b) in tp for z in zp])
        return pts, np.array([u * v for u in tw for v in zw])
    if cell == "hex20":
        if npts not in (27, 8):
            raise ValueError("hex20 has the 27 point (full) and 8 point (reduced) rules")
        return gauss_tensor((3, 3, 3) if npts == 27 else (2, 2, 2))
    raise ValueError(f"unknown cell type {cell!r}; known: {', '.join(CELLS)}")


# ----------------------------------------------------------------------------------------------- faces
#: face types of the cells' boundaries: corners counter-clockwise seen from outside, then the edge mid-nodes
FACE_CELLS = ("tri3", "tri6", "quad8")
FACE_NNODES = {"tri3": 3, "tri6": 6, "quad8": 8}
#: the face type with this many nodes
FACE_BY_NODES = {3: "tri3", 4: "quad4", 6: "tri6", 8: "quad8", 9: "quad9"}
#: corner count of every face type (faces are matched by their corners)
CORNERS = {"tri3": 3, "tri6": 3, "quad4": 4, "quad8": 4, "quad9": 4}


def face_shapes(ftype: str, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """N (npts, nfn) and dN/dxi (npts, nfn, 2) of a tri3 (natural coordinates on the unit triangle), tri6 (mid-nodes
    0-1, 1-2, 2-0) or quad8 (serendipity on [-1, 1]^2, mid-nodes 0-1, 1-2, 2-3, 3-0) face."""
    p = np.atleast_2d(np.asarray(points, dtype=np.float64))
    n = len(p)
    if ftype in ("tri3", "tri6"):
        L = np.stack([1.0 - p[:, 0] - p[:, 1], p[:, 0], p[:, 1]], axis=1)
        dL = np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]])
        if ftype == "tri3":
            return L, np.broadcast_to(dL, (n, 3, 2)).copy()
        a, b = np.array([0, 1, 2]), np.array([1, 2, 0])
        N = np.hstack([L * (2.0 * L - 1.0), 4.0 * L[:, a] * L[:, b]])
        dN = np.concatenate([(4.0 * L - 1.0)[:, :, None] * dL[None],
                             4.0 * (L[:, a, None] * dL[None, b] + L[:, b, None] * dL[None, a])], axis=1)
        return N, dN
    if ftype == "quad8":
        xa = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1], [0, -1], [1, 0], [0, 1], [-1, 0]], dtype=float)
        N = np.empty((n, 8))
        dN = np.empty((n, 8, 2))
        x, y = p[:, 0], p[:, 1]
        for k, (u, v) in enumerate(xa):
            if k < 4:
                N[:, k] = 0.25 * (1 + u * x) * (1 + v * y) * (u * x + v * y - 1)
                dN[:, k, 0] = 0.25 * u * (1 + v * y) * (2 * u * x + v * y)
                dN[:, k, 1] = 0.25 * v * (1 + u * x) * (u * x + 2 * v * y)
            elif u == 0:
                N[:, k] = 0.5 * (1 - x * x) * (1 + v * y)
                dN[:, k, 0] = -x * (1 + v * y)
                dN[:, k, 1] = 0.5 * v * (1 - x * x)
            else:
                N[:, k] = 0.5 * (1 + u * x) * (1 - y * y)
                dN[:, k, 0] = 0.5 * u * (1 - y * y)
                dN[:, k, 1] = -y * (1 + u * x)
        return N, dN
    raise ValueError(f"unknown face type {ftype!r}; known: {', '.join(FACE_CELLS)}")


def face_rule(ftype: str) -> tuple[np.ndarray, np.ndarray]:
    """Face rules: tri3 and tri6 3 points (degree 2), quad8 3 x 3 Gauss."""
    if ftype in ("tri3", "tri6"):
        return _triangle_rule()
    pts, w = gauss_1d(3)
    return np.array([[a, b] for b in pts for a in pts]), np.array([u * v for v in w for u in w])


@functools.lru_cache(maxsize=None)
def any_face(nfn: int, n_gauss: int | None = None):
    """(N (npts, nfn), dN (npts, nfn, 2), weights) of the face type with ``nfn`` nodes (quad4, quad9 by their Gauss
    rules of ``n_gauss`` points per direction, default full; tri3, tri6, quad8 by :func:`face_rule`); computed once
    per face type and rule (read-only arrays: pressures ask for them at every evaluation)."""
    return tuple(_read_only(a) for a in _any_face(nfn, n_gauss))


def _read_only(a: np.ndarray) -> np.ndarray:
    a = np.array(a)
    a.flags.writeable = False
    return a


def _any_face(nfn: int, n_gauss: int | None = None):
    from .quadrature import gauss_quad
    from .shapes import shape_functions

    if nfn in (4, 9):
        pts, w = gauss_quad(n_gauss or (2 if nfn == 4 else 3))
        N, dN, _ = shape_functions("quad4" if nfn == 4 else "quad9", pts)
        return N, dN, w
    ftype = {3: "tri3", 6: "tri6", 8: "quad8"}[nfn]
    pts, w = face_rule(ftype)
    N, dN = face_shapes(ftype, pts)
    return N, dN, w
