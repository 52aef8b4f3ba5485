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

from .facets import patch_gauss_points


def default_order(nen: int) -> int:
    """Gauss points per direction of a slave facet (or of each quadrilateral of its patch): 2 for quad4 and tri3, 3
    for quad9, tri6 and quad8."""
    return 2 if nen in (3, 4) else 3


def gauss_points(X: np.ndarray, faces: np.ndarray, order: int | None = None):
    """The Gauss points of ``faces`` (nf, nen) at reference positions X: ``order`` per direction on each facet (quad4,
    quad9) or on each quadrilateral of its patch (tri3, tri6, quad8: :mod:`.facets`).

    Returns (conn (ng, nen) the facet nodes of each point, N (ng, nen) their shape values, weight (ng,) the
    reference area w_g J_g, facet (ng,) the index of the point's facet in ``faces``).
    """
    faces = np.asarray(faces, dtype=np.int64)
    N, weight = patch_gauss_points(X, faces, order or default_order(faces.shape[1]))
    per = N.shape[0]
    return (np.repeat(faces, per, axis=0), np.tile(N, (len(faces), 1)), weight.ravel(),
            np.repeat(np.arange(len(faces)), per))


class VirtualPoints:
    """Every point of a problem that is a fixed combination of nodes, ids ``offset + j`` (offset: the extended node
    count): the segment-to-surface slave points, and the master points of the patches of tri3, tri6 and quad8 facets
    (:mod:`.facets`, flagged ``master``)."""

    def __init__(self, offset: int):
        self.offset = offset
        self.conn = np.zeros((0, 9), dtype=np.int64)
        self.N = np.zeros((0, 9))
        self.nen = np.zeros(0, dtype=np.int64)
        self.master = np.zeros(0, dtype=np.bool_)

    @property
    def count(self) -> int:
        return len(self.nen)

    def add(self, conn: np.ndarray, N: np.ndarray, master: bool = False) -> np.ndarray:
        """Register points (conn, N) (master: patch points of master facets); returns their ids."""
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
        self.master = np.concatenate([self.master, np.full(m, master)])
        return ids

    def positions(self, xe: np.ndarray) -> np.ndarray:
        """(count, 3) point positions from the extended node positions xe."""
        return np.einsum("ga,gai->gi", self.N, xe[self.conn])

    def nodes(self, ids: np.ndarray) -> np.ndarray:
        """The facet nodes of points ``ids`` (ids below the offset are nodes and pass through)."""
        ids = np.asarray(ids, dtype=np.int64)
        node = ids < self.offset
        j = ids[~node] - self.offset
        rows = [ids[node]] + [self.conn[j[self.nen[j] == k], :k].ravel() for k in np.unique(self.nen[j])]
        return np.unique(np.concatenate(rows))

    def smooth(self, ids: np.ndarray, weight: np.ndarray, values: np.ndarray, n: int) -> tuple[np.ndarray,
                                                                                              np.ndarray]:
        """Point values as a nodal field: the lumped L2 projection sum_g N_a w_g v_g / sum_g N_a w_g over
        nodes 0..n-1; returns (field, mask of the nodes that carry points). On tri6 and quad8 facets, whose corner
        shape functions integrate to zero or less, the weights are N_a^2 w_g (a positive weighted mean; a constant
        field stays exact)."""
        j = np.asarray(ids, dtype=np.int64) - self.offset
        Nj = self.N[j]
        wN = np.where(np.isin(self.nen[j], (6, 8))[:, None], Nj * Nj, Nj) * weight[:, None]
        conn = self.conn[j].ravel()
        den = np.bincount(conn, wN.ravel(), minlength=n)[:n]
        num = np.bincount(conn, (wN * values[:, None]).ravel(), minlength=n)[:n]
        has = den > 0.0
        return np.divide(num, den, out=np.zeros(n), where=has), has

    def expand(self, conn: np.ndarray, R: np.ndarray, K: np.ndarray | None):
        """An element block whose node lists hold points, with each point's rows and columns distributed to
        its facet's nodes (x_g = sum_a N_a x_a). Columns of slave points must hold points in every row of the block
        (one pass's slaves). A block with master patch points is expanded row by row onto the distinct nodes of
        each row (a patch quadrilateral's nodes are combinations of its face's few nodes)."""
        conn = np.asarray(conn, dtype=np.int64)
        virtual = conn >= self.offset
        if virtual.any() and self.master[conn[virtual] - self.offset].any():
            return _compact(conn, np.ascontiguousarray(R), None if K is None else np.ascontiguousarray(K),
                            self.offset, self.conn, self.N, self.nen)
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


@njit(cache=True)
def _parents(conn, offset, vconn, vN, vnen):
    """Per row e and column q the nodes (pidx, into the row's distinct nodes ``uniq``) and weights (pw) the column
    stands for; returns (uniq (m, width) padded with the row's first node, pidx, pw, pn)."""
    m, nc = conn.shape
    uniq = np.empty((m, 9 * nc), dtype=np.int64)
    count = np.zeros(m, dtype=np.int64)
    pidx = np.zeros((m, nc, 9), dtype=np.int64)
    pw = np.zeros((m, nc, 9))
    pn = np.zeros((m, nc), dtype=np.int64)
    for e in range(m):
        for q in range(nc):
            node = conn[e, q]
            n_par = 1 if node < offset else vnen[node - offset]
            for a in range(n_par):
                if node < offset:
                    par, w = node, 1.0
                else:
                    par, w = vconn[node - offset, a], vN[node - offset, a]
                    if w == 0.0:
                        continue
                u = -1
                for k in range(count[e]):
                    if uniq[e, k] == par:
                        u = k
                        break
                if u < 0:
                    u = count[e]
                    uniq[e, u] = par
                    count[e] += 1
                pidx[e, q, pn[e, q]] = u
                pw[e, q, pn[e, q]] = w
                pn[e, q] += 1
    width = 1
    for e in range(m):
        width = max(width, count[e])
    out = np.empty((m, width), dtype=np.int64)
    for e in range(m):
        for k in range(width):
            out[e, k] = uniq[e, k] if k < count[e] else uniq[e, 0]
    return out, pidx, pw, pn


@njit(cache=True, parallel=True)
def _compact_blocks(R, K, pidx, pw, pn, width, want_K):
    m, nc = pn.shape
    Ro = np.zeros((m, 3 * width))
    Ko = np.zeros((m, 3 * width, 3 * width)) if want_K else np.zeros((1, 1, 1))
    for e in prange(m):
        for q in range(nc):
            for a in range(pn[e, q]):
                u = pidx[e, q, a]
                wq = pw[e, q, a]
                for i in range(3):
                    Ro[e, 3 * u + i] += wq * R[e, 3 * q + i]
                if not want_K:
                    continue
                for r in range(nc):
                    for b in range(pn[e, r]):
                        v = pidx[e, r, b]
                        w = wq * pw[e, r, b]
                        for i in range(3):
                            for k in range(3):
                                Ko[e, 3 * u + i, 3 * v + k] += w * K[e, 3 * q + i, 3 * r + k]
    return Ro, Ko


def _compact(conn, R, K, offset, vconn, vN, vnen):
    """The block with every row expanded onto its distinct nodes: R_a = sum_v w_va R_v, K_ab = sum_vw w_va w_wb K_vw."""
    out, pidx, pw, pn = _parents(conn, offset, vconn, vN, vnen)
    Ro, Ko = _compact_blocks(R, np.zeros((1, 1, 1)) if K is None else K, pidx, pw, pn, out.shape[1], K is not None)
    return out, Ro, (Ko if K is not None else None)
