"""Lagrange shape functions of the tensor-product cells used by covcontact.

Node orders follow VTK (and meshio):

- ``quad4``: corners (-1,-1), (1,-1), (1,1), (-1,1).
- ``quad9``: the corners, the edge mid-nodes 0-1, 1-2, 2-3, 3-0, then the centre.
- ``hex8``: the quad4 corners at t = -1, then at t = +1.
- ``hex18``: a quad9 at t = -1, then a quad9 at t = +1 (biquadratic in-plane, linear in t;
  the solid-shell layout).
- ``hex27``: VTK_TRIQUADRATIC_HEXAHEDRON: corners, twelve edge mid-nodes (0-1, 1-2, 2-3, 3-0,
  4-5, 5-6, 6-7, 7-4, 0-4, 1-5, 2-6, 3-7), face centres (x-, x+, y-, y+, z-, z+), body centre.

Every cell is a tensor product of 1D Lagrange bases: linear with nodes (-1, 1), quadratic with
nodes (-1, 1, 0). ``IDX[cell][a, d]`` is the 1D node index of node ``a`` in direction ``d``.
The compiled evaluators write into caller-provided arrays and never allocate.
"""

from __future__ import annotations

import numpy as np
from numba import njit

# 1D orders per direction of each cell type
ORDER = {
    "quad4": np.array([1, 1], dtype=np.int64),
    "quad9": np.array([2, 2], dtype=np.int64),
    "hex8": np.array([1, 1, 1], dtype=np.int64),
    "hex18": np.array([2, 2, 1], dtype=np.int64),
    "hex27": np.array([2, 2, 2], dtype=np.int64),
}

# 1D node index -> natural coordinate
_COORD1D = np.array([-1.0, 1.0, 0.0])

_Q4 = [(0, 0), (1, 0), (1, 1), (0, 1)]
_Q9 = _Q4 + [(2, 0), (1, 2), (2, 1), (0, 2), (2, 2)]
_H8 = [(i, j, 0) for i, j in _Q4] + [(i, j, 1) for i, j in _Q4]
_H18 = [(i, j, 0) for i, j in _Q9] + [(i, j, 1) for i, j in _Q9]
_H27 = (
    _H8
    + [(i, j, 0) for i, j in _Q9[4:8]]
    + [(i, j, 1) for i, j in _Q9[4:8]]
    + [(i, j, 2) for i, j in _Q4]
    + [(0, 2, 2), (1, 2, 2), (2, 0, 2), (2, 1, 2), (2, 2, 0), (2, 2, 1), (2, 2, 2)]
)

IDX = {
    "quad4": np.array(_Q4, dtype=np.int64),
    "quad9": np.array(_Q9, dtype=np.int64),
    "hex8": np.array(_H8, dtype=np.int64),
    "hex18": np.array(_H18, dtype=np.int64),
    "hex27": np.array(_H27, dtype=np.int64),
}

#: natural coordinates of the nodes, (nen, dim)
NODES = {name: _COORD1D[idx] for name, idx in IDX.items()}

NNODES = {name: idx.shape[0] for name, idx in IDX.items()}
DIM = {name: idx.shape[1] for name, idx in IDX.items()}


@njit(cache=True, inline="always")
def lagrange1d(order, k, x):
    """Value, first and second derivative of 1D basis function ``k`` of ``order`` (1 or 2) at x."""
    if order == 1:
        if k == 0:
            return 0.5 * (1.0 - x), -0.5, 0.0
        return 0.5 * (1.0 + x), 0.5, 0.0
    if k == 0:
        return 0.5 * x * (x - 1.0), x - 0.5, 1.0
    if k == 1:
        return 0.5 * x * (x + 1.0), x + 0.5, 1.0
    return 1.0 - x * x, -2.0 * x, -2.0


@njit(cache=True)
def eval_shape(idx, order, x, N, dN, ddN):
    """Evaluate a tensor-product Lagrange basis at one point.

    Args:
        idx: (nen, dim) 1D node indices (``IDX[cell]``).
        order: (dim,) 1D orders (``ORDER[cell]``).
        x: (dim,) natural coordinates.
        N: (nen,) out, values.
        dN: (nen, dim) out, first derivatives.
        ddN: (nen, dim, dim) out, second derivatives.
    """
    nen, dim = idx.shape
    v = np.empty(3)
    d = np.empty(3)
    dd = np.empty(3)
    for a in range(nen):
        for k in range(dim):
            v[k], d[k], dd[k] = lagrange1d(order[k], idx[a, k], x[k])
        prod = 1.0
        for k in range(dim):
            prod *= v[k]
        N[a] = prod
        for i in range(dim):
            g = d[i]
            for k in range(dim):
                if k != i:
                    g *= v[k]
            dN[a, i] = g
            for j in range(dim):
                if j == i:
                    h = dd[i]
                    for k in range(dim):
                        if k != i:
                            h *= v[k]
                else:
                    h = d[i] * d[j]
                    for k in range(dim):
                        if k != i and k != j:
                            h *= v[k]
                ddN[a, i, j] = h


@njit(cache=True)
def eval_surface(nen, xi1, xi2, N, dN, ddN):
    """Shape functions of a quad4 (nen = 4) or quad9 (nen = 9) facet at (xi1, xi2).

    Writes N (nen,), dN (nen, 2) and ddN (nen, 2, 2); the compiled entry point used by contact.
    """
    x = np.empty(2)
    x[0] = xi1
    x[1] = xi2
    if nen == 4:
        eval_shape(_IDX_Q4, _ORD_Q, x, N, dN, ddN)
    else:
        eval_shape(_IDX_Q9, _ORD_Q9, x, N, dN, ddN)


_IDX_Q4 = IDX["quad4"]
_IDX_Q9 = IDX["quad9"]
_ORD_Q = ORDER["quad4"]
_ORD_Q9 = ORDER["quad9"]


def shape_functions(cell: str, points: np.ndarray):
    """Shape functions of ``cell`` at ``points`` (npts, dim).

    Returns:
        N (npts, nen), dN (npts, nen, dim) and ddN (npts, nen, dim, dim).
    """
    if cell not in IDX:
        raise ValueError(f"unknown cell type {cell!r}; known: {', '.join(IDX)}")
    pts = np.atleast_2d(np.asarray(points, dtype=np.float64))
    idx, order = IDX[cell], ORDER[cell]
    nen, dim = idx.shape
    if pts.shape[1] != dim:
        raise ValueError(f"{cell} needs points with {dim} coordinates, got {pts.shape[1]}")
    npts = pts.shape[0]
    N = np.empty((npts, nen))
    dN = np.empty((npts, nen, dim))
    ddN = np.empty((npts, nen, dim, dim))
    for p in range(npts):
        eval_shape(idx, order, np.ascontiguousarray(pts[p]), N[p], dN[p], ddN[p])
    return N, dN, ddN
