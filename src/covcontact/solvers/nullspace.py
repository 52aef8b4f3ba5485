"""The rigid-body modes of a body's nodes: the near-null space that AMG preconditioners are given
(``LinearSolver.set_near_null_space``), and an orthonormal basis of them computed with every sum in a fixed
order (PETSc's GAMG on a distributed run)."""

from __future__ import annotations

import numpy as np
from numba import njit


def rigid_body_modes(X: np.ndarray, constrained: np.ndarray | None = None) -> np.ndarray:
    """The six rigid-body modes of the nodes ``X``: the near-null space of an elastic stiffness.

    Columns: the unit translations along x, y, z, then the infinitesimal rotations about the x, y, z
    axes through the centroid of ``X``, u = e_k x (x - c) / L, with L the root-mean-square distance of
    the nodes from the centroid, so that every column has entries of order one whatever the units.
    Row 3a+i belongs to direction i of node a.

    Args:
        X: (nnode, 3) node coordinates: the reference ones, or the current ones X + u for the tangent at
            a deformed state (whose kernel is spanned by rotations of the current configuration).
        constrained: either a bool mask (3 nnode,) of the Dirichlet-constrained dofs, whose rows are set
            to zero to match a matrix with those rows and columns eliminated (result (3 nnode, 6)); or
            an integer array of distinct global dofs, the unknowns of a reduced system (result
            (len(dofs), 6), rows in that order); or None: all dofs, nothing zeroed.
    """
    X = np.asarray(X, dtype=np.float64)
    if X.ndim != 2 or X.shape[1] != 3:
        raise ValueError(f"node coordinates must have shape (nnode, 3), got {X.shape}")
    ndof = 3 * X.shape[0]
    mask = None
    if constrained is None:
        dofs = np.arange(ndof)
    else:
        c = np.asarray(constrained)
        if c.dtype == bool:
            if c.shape != (ndof,):
                raise ValueError(f"the constrained mask must have shape ({ndof},), got {c.shape}")
            dofs, mask = np.arange(ndof), c
        elif np.issubdtype(c.dtype, np.integer) and c.ndim == 1:
            dofs = c.astype(np.int64)
            if dofs.size and (dofs.min() < 0 or dofs.max() >= ndof or np.unique(dofs).size != dofs.size):
                raise ValueError(f"dofs must be distinct integers in [0, {ndof}); pass a constrained mask "
                                 "as a bool array")
        else:
            raise TypeError(f"constrained must be a bool mask or integer dofs, got {c.dtype} {c.shape}")
    node, i = dofs // 3, dofs % 3
    c0 = X.mean(axis=0) if X.shape[0] else np.zeros(3)
    L = float(np.sqrt(np.mean(np.sum((X - c0) ** 2, axis=1)))) if X.shape[0] else 0.0
    x = (X[node] - c0) / (L if L > 0.0 else 1.0)
    B = np.zeros((dofs.size, 6))
    rows = np.arange(dofs.size)
    B[rows, i] = 1.0
    for k in range(3):  # rotation about axis k: u = e_k x x
        rot = np.zeros((dofs.size, 3))
        rot[:, (k + 2) % 3] = x[:, (k + 1) % 3]
        rot[:, (k + 1) % 3] = -x[:, (k + 2) % 3]
        B[:, 3 + k] = rot[rows, i]
    if mask is not None:
        B[mask] = 0.0
    return B


@njit(cache=True)
def _dots(Q, k, v):  # pragma: no cover - compiled
    """Q[:, j] . v for j < k, each summed in index order (a fixed order: the same bits on every run)."""
    out = np.zeros(k)
    for j in range(k):
        acc = 0.0
        for i in range(v.size):
            acc += Q[i, j] * v[i]
        out[j] = acc
    return out


@njit(cache=True)
def _column_sums(X):  # pragma: no cover - compiled
    """The sums of X's columns, each in index order."""
    out = np.zeros(X.shape[1])
    for i in range(X.shape[0]):
        for d in range(X.shape[1]):
            out[d] += X[i, d]
    return out


def rigid_body_basis(coords: np.ndarray, sum_ranks=None) -> np.ndarray:
    """An orthonormal basis (3 m, 6) of the :func:`rigid_body_modes` at ``coords`` (m, 3), on a distributed run
    this rank's share of the nodes (``sum_ranks``: the sum of an array over the ranks, in a fixed order, e.g.
    parallel.comm.sum_all), rows x, y, z interleaved, the same bits on every run: the modes about the centroid
    of all ranks' nodes, orthonormalised by Gram-Schmidt twice over with every sum taken in a fixed order.
    (PETSc's MatNullSpaceCreateRigidBody sums with BLAS, whose rounding depends on where its vectors lie in
    memory: its modes, and with them GAMG's hierarchy, differed in the last bit between runs of the same
    problem.)"""

    def total(a: np.ndarray) -> np.ndarray:
        return sum_ranks(a) if sum_ranks is not None else np.asarray(a, dtype=np.float64)

    # one layout: numpy's reductions in rigid_body_modes add in an order that depends on it
    X = np.ascontiguousarray(coords, dtype=np.float64)
    n_all = total(np.array([float(X.shape[0])]))[0]
    B = rigid_body_modes(X - total(_column_sums(X)) / max(n_all, 1.0))
    Q = np.zeros_like(B)
    for k in range(B.shape[1]):
        v = B[:, k].copy()
        for _ in range(2):
            coef = total(_dots(Q, k, v))
            for j in range(k):  # elementwise: no sum whose order could vary
                v -= coef[j] * Q[:, j]
        norm = float(np.sqrt(total(_dots(v[:, None], 1, v))[0]))
        Q[:, k] = v / norm if norm > 0.0 else 0.0
    return Q


def near_null_candidates(B: np.ndarray | None, geometry: tuple | None, n: int) -> tuple[np.ndarray | None, bool]:
    """The near-null space an AMG backend hands to its set-up for a matrix of size n, and whether its rows
    are 3 dofs per node: the rigid-body modes of ``geometry`` = (points, dofs) when given (set by
    ``set_geometry``), else ``B`` (set by ``set_near_null_space``; full size 3 nnode), else (None, True)."""
    nodal = True
    if geometry is not None:
        B, nodal = rigid_body_modes(*geometry), geometry[1] is None
    if B is not None and B.shape[0] != n:
        raise ValueError(f"the near-null space has {B.shape[0]} rows, the matrix {n}")
    return B, nodal


def _near_null_array(B) -> np.ndarray | None:
    """B as a C-contiguous float64 (n, k) array with k >= 1 (a vector is one column), checked finite."""
    if B is None:
        return None
    B = np.array(B, dtype=np.float64, order="C", ndmin=1)
    if B.ndim == 1:
        B = B[:, None]
    if B.ndim != 2 or B.shape[1] == 0:
        raise ValueError(f"the near-null space must have shape (n, k), k >= 1, got {B.shape}")
    if not np.isfinite(B).all():
        raise ValueError("the near-null space has non-finite entries")
    return B
