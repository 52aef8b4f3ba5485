"""Slave points of segment-to-surface contact: the Gauss points of the slave facets (docs/theory.md, section 12).

A segment-to-surface pass treats each Gauss point of a slave facet as a slave of its own, at the position
x_g = sum_a N_a(xi_g) x_a of the facet's nodes, with the penalty eps_N w_g J_g (w_g the Gauss weight, J_g the
reference area element): the node-to-surface kernels then integrate the gap over the slave surface. The points get
ids after the extended node numbering (deformable nodes, rigid-mesh nodes), so the search, projection, kernels,
friction history and state index them like nodes; :meth:`VirtualPoints.expand` maps an element block's rows and
columns of a point onto the facet's nodes (R_a = N_a R_g, K_ab = N_a N_b K_gg, ...), which keeps every tangent
part exact, since x_g is linear in the nodes.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from ..fem.quadrature import gauss_quad
from ..fem.shapes import shape_functions


def default_order(nen: int) -> int:
    """Gauss points per direction of a slave facet: 2 for quad4, 3 for quad9."""
    return 2 if nen == 4 else 3


def gauss_points(X: np.ndarray, faces: np.ndarray, order: int | None = None):
    """The Gauss points of ``faces`` (nf, 4|9) at reference positions X.

    Returns (conn (ng, nen) the facet nodes of each point, N (ng, nen) their shape values, weight (ng,) the
    reference area w_g J_g, facet (ng,) the index of the point's facet in ``faces``).
    """
    faces = np.asarray(faces, dtype=np.int64)
    nen = faces.shape[1]
    pts, w = gauss_quad(order or default_order(nen))
    N, dN, _ = shape_functions("quad4" if nen == 4 else "quad9", pts)
    t = np.einsum("pad,fai->fpdi", dN, X[faces])
    jac = np.linalg.norm(np.cross(t[:, :, 0], t[:, :, 1]), axis=2)
    return (np.repeat(faces, len(w), axis=0), np.tile(N, (len(faces), 1)), (jac * w).ravel(),
            np.repeat(np.arange(len(faces)), len(w)))


class VirtualPoints:
    """Every segment-to-surface point of a problem: ids ``offset + j`` (offset: the extended node count)."""

    def __init__(self, offset: int):
        self.offset = offset
        self.conn = np.zeros((0, 9), dtype=np.int64)
        self.N = np.zeros((0, 9))
        self.nen = np.zeros(0, dtype=np.int64)

    @property
    def count(self) -> int:
        return len(self.nen)

    def add(self, conn: np.ndarray, N: np.ndarray) -> np.ndarray:
        """Register points (conn, N); returns their ids."""
        m, nen = conn.shape
        c = np.zeros((m, 9), dtype=np.int64)
        c[:, :nen] = conn
        c[:, nen:] = conn[:, :1]
        n = np.zeros((m, 9))
        n[:, :nen] = N
        ids = self.offset + self.count + np.arange(m)
        self.conn = np.vstack([self.conn, c])
        self.N = np.vstack([self.N, n])
        self.nen = np.concatenate([self.nen, np.full(m, nen)])
        return ids

    def positions(self, xe: np.ndarray) -> np.ndarray:
        """(count, 3) point positions from the extended node positions xe."""
        return np.einsum("ga,gai->gi", self.N, xe[self.conn])

    def nodes(self, ids: np.ndarray) -> np.ndarray:
        """The facet nodes of points ``ids`` (ids below the offset are nodes and pass through)."""
        ids = np.asarray(ids, dtype=np.int64)
        node = ids < self.offset
        j = ids[~node] - self.offset
        rows = [ids[node]] + [self.conn[j[self.nen[j] == k], :k].ravel() for k in (4, 9)]
        return np.unique(np.concatenate(rows))

    def smooth(self, ids: np.ndarray, weight: np.ndarray, values: np.ndarray, n: int) -> tuple[np.ndarray,
                                                                                              np.ndarray]:
        """Point values as a nodal field: the lumped L2 projection sum_g N_a w_g v_g / sum_g N_a w_g over
        nodes 0..n-1; returns (field, mask of the nodes that carry points)."""
        j = np.asarray(ids, dtype=np.int64) - self.offset
        wN = self.N[j] * weight[:, None]
        conn = self.conn[j].ravel()
        den = np.bincount(conn, wN.ravel(), minlength=n)[:n]
        num = np.bincount(conn, (wN * values[:, None]).ravel(), minlength=n)[:n]
        has = den > 0.0
        return np.divide(num, den, out=np.zeros(n), where=has), has

    def expand(self, conn: np.ndarray, R: np.ndarray, K: np.ndarray | None):
        """An element block whose node lists hold points, with each point's rows and columns distributed to
        its facet's nodes (x_g = sum_a N_a x_a). Columns of points must hold points in every row of the block
        (one pass's slaves)."""
        cols = np.flatnonzero(conn[0] >= self.offset)
        for j in cols[::-1]:
            conn, R, K = self._expand_column(conn, R, K, int(j))
        return conn, R, K

    def _expand_column(self, conn, R, K, j):
        g = conn[:, j] - self.offset
        nen = int(self.nen[g[0]])
        Nv = np.ascontiguousarray(self.N[g, :nen])
        new_conn = np.hstack([conn[:, :j], self.conn[g, :nen], conn[:, j + 1:]])
        Rn = _expand_rows(np.ascontiguousarray(R), j, Nv)
        Kn = None if K is None else _expand_matrices(np.ascontiguousarray(K), j, Nv)
        return new_conn, Rn, Kn


@njit(cache=True, inline="always")
def _source(q, j, nen, Nv, e):
    """Node q of the expanded element: (its node in the point's element, its weight)."""
    if q < j:
        return q, 1.0
    if q < j + nen:
        return j, Nv[e, q - j]
    return q - nen + 1, 1.0


@njit(cache=True)
def _expand_rows(R, j, Nv):
    m, nen = Nv.shape
    n2 = R.shape[1] // 3 - 1 + nen
    out = np.empty((m, 3 * n2))
    for e in range(m):
        for q in range(n2):
            o, w = _source(q, j, nen, Nv, e)
            for i in range(3):
                out[e, 3 * q + i] = w * R[e, 3 * o + i]
    return out


@njit(cache=True, parallel=True)
def _expand_matrices(K, j, Nv):
    """K_ab = N_a N_b K_gg and the mixed blocks, for every element of a block (point column j)."""
    m, nen = Nv.shape
    n2 = K.shape[1] // 3 - 1 + nen
    out = np.empty((m, 3 * n2, 3 * n2))
    for e in prange(m):
        for q in range(n2):
            oq, wq = _source(q, j, nen, Nv, e)
            for r in range(n2):
                orr, wr = _source(r, j, nen, Nv, e)
                w = wq * wr
                for i in range(3):
                    for k in range(3):
                        out[e, 3 * q + i, 3 * r + k] = w * K[e, 3 * oq + i, 3 * orr + k]
    return out
