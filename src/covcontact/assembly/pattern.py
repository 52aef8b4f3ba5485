"""Node-structured global sparsity pattern and race-free scatter into its CSR data array.

The pattern is built once per topology from connectivity blocks (global node ids). It holds a node
graph (``node_ptr``, ``node_adj``: sorted neighbours of every node, diagonal included) and the
scalar CSR with 3 dofs per node: row 3A+i has the columns 3B+j for each neighbour B of A (in order)
and j = 0, 1, 2. Entry (3A+i, 3B+j) therefore sits at data offset

    9 * node_ptr[A] + 3 * i * deg(A) + 3 * k + j,    k = rank of B in the adjacency of A,

so an element only needs a (nen, nen) table of ranks, not a map per dof pair.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from numba import get_num_threads, njit, prange

_INT32_MAX = np.iinfo(np.int32).max


@njit(cache=True)
def _incidence(n_nodes, eptr, enodes):
    """Node -> element incidence of a ragged element list, as CSR (nptr, inc)."""
    nptr = np.zeros(n_nodes + 1, dtype=np.int64)
    for q in range(enodes.size):
        nptr[enodes[q] + 1] += 1
    for A in range(n_nodes):
        nptr[A + 1] += nptr[A]
    pos = nptr[:-1].copy()
    inc = np.empty(enodes.size, dtype=np.int64)
    for e in range(eptr.size - 1):
        for q in range(eptr[e], eptr[e + 1]):
            A = enodes[q]
            inc[pos[A]] = e
            pos[A] += 1
    return nptr, inc


@njit(parallel=True, cache=True)
def _node_graph(n_nodes, eptr, enodes, nptr, inc, node_ptr, node_adj, fill, nthreads):
    """Degrees (fill=False, written to node_ptr[1:]) or sorted adjacency (fill=True) of every node."""
    nblk = min(nthreads, max(n_nodes, 1))
    for t in prange(nblk):
        lo = t * n_nodes // nblk
        hi = (t + 1) * n_nodes // nblk
        marker = np.full(n_nodes, -1, dtype=np.int64)
        for A in range(lo, hi):
            marker[A] = A
            d = 1
            if fill:
                p0 = node_ptr[A]
                node_adj[p0] = A
            for p in range(nptr[A], nptr[A + 1]):
                e = inc[p]
                for q in range(eptr[e], eptr[e + 1]):
                    B = enodes[q]
                    if marker[B] != A:
                        marker[B] = A
                        if fill:
                            node_adj[p0 + d] = B
                        d += 1
            if fill:
                # insertion sort of the (short) neighbour list
                for r in range(p0 + 1, p0 + d):
                    v = node_adj[r]
                    s = r - 1
                    while s >= p0 and node_adj[s] > v:
                        node_adj[s + 1] = node_adj[s]
                        s -= 1
                    node_adj[s + 1] = v
            else:
                node_ptr[A + 1] = d


@njit(parallel=True, cache=True)
def _scalar_csr(node_ptr, node_adj, indptr, indices):
    n = node_ptr.size - 1
    for A in prange(n):
        p0 = node_ptr[A]
        d = node_ptr[A + 1] - p0
        for i in range(3):
            r0 = 9 * p0 + 3 * i * d
            indptr[3 * A + i] = r0
            for k in range(d):
                B = node_adj[p0 + k]
                for j in range(3):
                    indices[r0 + 3 * k + j] = 3 * B + j
    indptr[3 * n] = 9 * node_ptr[n]


@njit(cache=True, inline="always")
def _rank(node_ptr, node_adj, A, B):
    lo = node_ptr[A]
    hi = node_ptr[A + 1]
    p0 = lo
    while lo < hi:
        mid = (lo + hi) // 2
        if node_adj[mid] < B:
            lo = mid + 1
        else:
            hi = mid
    if lo < node_ptr[A + 1] and node_adj[lo] == B:
        return lo - p0
    return -1


@njit(parallel=True, cache=True)
def _ranks(node_ptr, node_adj, conn, offset, out):
    ne, nen = conn.shape
    for e in prange(ne):
        for a in range(nen):
            A = conn[e, a] + offset
            for b in range(nen):
                out[e, a, b] = _rank(node_ptr, node_adj, A, conn[e, b] + offset)


@njit(parallel=True, cache=True)
def _diag_offsets(node_ptr, node_adj, out):
    n = node_ptr.size - 1
    for A in prange(n):
        p0 = node_ptr[A]
        d = node_ptr[A + 1] - p0
        k = _rank(node_ptr, node_adj, A, A)
        for i in range(3):
            out[3 * A + i] = 9 * p0 + 3 * i * d + 3 * k + i


@njit(cache=True)
def scatter_matrices(data, node_ptr, conn, offset, ranks, Ke, e0):
    """data += element matrices Ke (nc, 3 nen, 3 nen) of elements e0 .. e0 + nc - 1 (serial).

    ``conn`` holds node ids relative to ``offset`` (global node = conn + offset) and ``ranks`` is
    the table of :meth:`Pattern.ranks` for the same block.
    """
    nc = Ke.shape[0]
    nen = conn.shape[1]
    for c in range(nc):
        e = e0 + c
        for a in range(nen):
            A = conn[e, a] + offset
            p0 = node_ptr[A]
            stride = 3 * (node_ptr[A + 1] - p0)
            base = 9 * p0
            for b in range(nen):
                off = base + 3 * ranks[e, a, b]
                for i in range(3):
                    row = off + i * stride
                    for j in range(3):
                        data[row + j] += Ke[c, 3 * a + i, 3 * b + j]


@njit(cache=True)
def scatter_vectors(rhs, conn, offset, fe, e0):
    """rhs[3 (conn + offset) + i] += element vectors fe (nc, 3 nen) of elements e0 .. (serial)."""
    nc = fe.shape[0]
    nen = conn.shape[1]
    for c in range(nc):
        e = e0 + c
        for a in range(nen):
            A = conn[e, a] + offset
            for i in range(3):
                rhs[3 * A + i] += fe[c, 3 * a + i]


class Pattern:
    """Global node-structured CSR pattern with 3 dofs per node.

    Args:
        n_nodes: number of global nodes (every node gets its diagonal block).
        blocks: connectivity arrays (nelem, nen) of global node ids; every pair of nodes of an
            element is coupled.
        extra_pairs: optional (npairs, 2) node pairs to couple as well (e.g. contact).
    """

    def __init__(
        self, n_nodes: int, blocks: list[np.ndarray], extra_pairs: np.ndarray | None = None
    ) -> None:
        n_nodes = int(n_nodes)
        if n_nodes < 1:
            raise ValueError("a pattern needs at least one node")
        parts = [np.ascontiguousarray(b, dtype=np.int64) for b in blocks]
        if extra_pairs is not None:
            parts.append(np.ascontiguousarray(np.asarray(extra_pairs, dtype=np.int64).reshape(-1, 2)))
        eptrs = [np.zeros(1, dtype=np.int64)]
        start = 0
        for k, b in enumerate(parts):
            if b.ndim != 2:
                raise ValueError(f"connectivity block {k} must be 2D (nelem, nen), got shape {b.shape}")
            if b.size and (b.min() < 0 or b.max() >= n_nodes):
                raise ValueError(f"connectivity block {k} has node ids outside [0, {n_nodes})")
            eptrs.append(start + b.shape[1] * np.arange(1, b.shape[0] + 1, dtype=np.int64))
            start += b.size
        eptr = np.concatenate(eptrs)
        enodes = np.concatenate([b.ravel() for b in parts]) if parts else np.zeros(0, np.int64)
        nptr, inc = _incidence(n_nodes, eptr, enodes)
        node_ptr = np.zeros(n_nodes + 1, dtype=np.int64)
        dummy = np.zeros(0, dtype=np.int64)
        _node_graph(n_nodes, eptr, enodes, nptr, inc, node_ptr, dummy, False, get_num_threads())
        np.cumsum(node_ptr, out=node_ptr)
        adj_type = np.int32 if n_nodes <= _INT32_MAX else np.int64
        node_adj = np.empty(node_ptr[-1], dtype=adj_type)
        _node_graph(n_nodes, eptr, enodes, nptr, inc, node_ptr, node_adj, True, get_num_threads())
        del nptr, inc, eptr, enodes
        self.n_nodes = n_nodes
        self.node_ptr = node_ptr
        self.node_adj = node_adj
        self.n_dofs = 3 * n_nodes
        self.nnz = int(9 * node_ptr[-1])
        itype = np.int32 if max(self.nnz, self.n_dofs) <= _INT32_MAX else np.int64
        self.indptr = np.empty(self.n_dofs + 1, dtype=itype)
        self.indices = np.empty(self.nnz, dtype=itype)
        _scalar_csr(node_ptr, node_adj, self.indptr, self.indices)

    @property
    def node_deg(self) -> np.ndarray:
        """Number of neighbours (diagonal included) of every node."""
        return np.diff(self.node_ptr)

    def zeros(self) -> np.ndarray:
        """A zero CSR data array (nnz,) float64."""
        return np.zeros(self.nnz, dtype=np.float64)

    def ranks(self, conn: np.ndarray, node_offset: int = 0, strict: bool = True) -> np.ndarray:
        """(nelem, nen, nen) int32: rank of node b in the adjacency of node a, for each element.

        Raises ValueError if a pair of ``conn + node_offset`` is not in the pattern (``strict``), else
        marks such pairs with -1.
        """
        conn = np.ascontiguousarray(conn, dtype=np.int64)
        if conn.ndim != 2:
            raise ValueError(f"conn must be 2D (nelem, nen), got shape {conn.shape}")
        if conn.size and (conn.min() + node_offset < 0 or conn.max() + node_offset >= self.n_nodes):
            raise ValueError(f"conn + node_offset has node ids outside [0, {self.n_nodes})")
        out = np.empty((conn.shape[0], conn.shape[1], conn.shape[1]), dtype=np.int32)
        _ranks(self.node_ptr, self.node_adj, conn, np.int64(node_offset), out)
        if strict and out.size and out.min() < 0:
            e = int(np.flatnonzero((out < 0).any(axis=(1, 2)))[0])
            raise ValueError(f"element {e} couples nodes that are not in the pattern")
        return out

    def diag_offsets(self) -> np.ndarray:
        """(n_dofs,) int64 data offsets of the diagonal entries (3A+i, 3A+i)."""
        out = np.empty(self.n_dofs, dtype=np.int64)
        _diag_offsets(self.node_ptr, self.node_adj, out)
        return out

    def scatter(self, data: np.ndarray, conn: np.ndarray, Ke: np.ndarray, ranks: np.ndarray | None = None,
                node_offset: int = 0) -> None:
        """data += the element matrices Ke (nelem, 3 nen, 3 nen) of block ``conn`` (+ node_offset)."""
        conn = np.ascontiguousarray(conn, dtype=np.int64)
        if ranks is None:
            ranks = self.ranks(conn, node_offset)
        nd = 3 * conn.shape[1]
        Ke = np.ascontiguousarray(Ke, dtype=np.float64)
        if Ke.shape != (conn.shape[0], nd, nd):
            raise ValueError(f"Ke must have shape {(conn.shape[0], nd, nd)}, got {Ke.shape}")
        scatter_matrices(data, self.node_ptr, conn, np.int64(node_offset), ranks, Ke, 0)

    def csr(self, data: np.ndarray) -> sp.csr_matrix:
        """scipy CSR matrix sharing ``data``, ``indices`` and ``indptr`` (no copy)."""
        if data.shape != (self.nnz,) or data.dtype != np.float64:
            raise ValueError(f"data must be float64 of shape ({self.nnz},)")
        A = sp.csr_matrix((data, self.indices, self.indptr), shape=(self.n_dofs, self.n_dofs), copy=False)
        A.has_sorted_indices = True
        return A
