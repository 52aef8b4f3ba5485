"""Self-contact: one surface is slave and master of itself (docs/theory.md, section 13).

Every slave (a node of the surface, or a Gauss point of one of its facets) searches the whole surface except
its own neighbourhood: the facets that share a node with a facet around the slave node, or with the slave
point's own facet (a topological distance of two facets; a surface folding back onto itself closer than that is
not resolved by its mesh anyway). Among the contact points found, only those whose master normal opposes the
slave's own outward normal count (n_s . n_m < 0): a surface meets itself face to face, so a point seen from the
same side is its own neighbourhood seen along the surface, never a contact.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from numba import njit


def _incidence(faces: np.ndarray, n_nodes: int) -> sp.csr_matrix:
    nf, nen = faces.shape
    return sp.csr_matrix((np.ones(faces.size), (np.repeat(np.arange(nf), nen), faces.ravel())),
                         shape=(nf, n_nodes))


def _padded(M: sp.csr_matrix) -> np.ndarray:
    """Rows of a sparse pattern as a (rows, width) array of column ids padded with -1."""
    M = M.tocsr()
    M.sort_indices()
    counts = np.diff(M.indptr)
    out = np.full((M.shape[0], max(int(counts.max(initial=0)), 1)), -1, dtype=np.int64)
    rows = np.repeat(np.arange(M.shape[0]), counts)
    cols = np.arange(M.indices.size) - np.repeat(M.indptr[:-1], counts)
    out[rows, cols] = M.indices
    return out


def excluded_facets(faces: np.ndarray, n_nodes: int, slave_nodes: np.ndarray | None = None,
                    slave_facets: np.ndarray | None = None) -> np.ndarray:
    """(ns, width) facets each slave never contacts, -1 padded: for slave nodes the facets sharing a node with a
    facet around the node, for slave points (given by their facet) those sharing a node with a facet sharing a
    node with the point's facet."""
    A = _incidence(faces, n_nodes)
    near = (A @ A.T).astype(bool)                 # facet -> facets sharing a node
    if slave_nodes is not None:
        ring = (A.T.tocsr()[slave_nodes] @ near).astype(bool)
    else:
        ring = (near[slave_facets] @ near).astype(bool)
    return _padded(ring)


@njit(cache=True)
def drop_excluded(ptr, fac, excl):
    """The candidate CSR (ptr, fac) without each slave's excluded facets (rows of ``excl``, -1 padded)."""
    ns = ptr.shape[0] - 1
    out_ptr = np.zeros(ns + 1, dtype=np.int64)
    out = np.empty(fac.shape[0], dtype=np.int64)
    m = 0
    for s in range(ns):
        for k in range(ptr[s], ptr[s + 1]):
            f = fac[k]
            hit = False
            for e in range(excl.shape[1]):
                if excl[s, e] == f:
                    hit = True
                    break
                if excl[s, e] < 0:
                    break
            if not hit:
                out[m] = f
                m += 1
        out_ptr[s + 1] = m
    return out_ptr, out[:m]


def facet_normals(xe: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Unit outward normal of each facet at its centre (the corner diagonals' cross product)."""
    n = np.cross(xe[faces[:, 2]] - xe[faces[:, 0]], xe[faces[:, 3]] - xe[faces[:, 1]])
    ln = np.linalg.norm(n, axis=1, keepdims=True)
    return np.divide(n, ln, out=np.zeros_like(n), where=ln > 0)


def slave_normals(xe: np.ndarray, surface, slaves: np.ndarray, own_facet: np.ndarray | None) -> np.ndarray:
    """The slaves' own outward normals: their facet's (points) or the mean of the facets around them (nodes)."""
    fn = facet_normals(xe, surface.faces)
    if own_facet is not None:
        return fn[own_facet]
    out = np.zeros((len(slaves), 3))
    ptr, fac = surface.node_ptr, surface.node_facets
    counts = ptr[slaves + 1] - ptr[slaves]
    rows = np.repeat(np.arange(len(slaves)), counts)
    within = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    idx = fac[np.repeat(ptr[slaves], counts) + within]
    for k in range(3):
        out[:, k] = np.bincount(rows, fn[idx, k], minlength=len(slaves))
    ln = np.linalg.norm(out, axis=1, keepdims=True)
    return np.divide(out, ln, out=np.zeros_like(out), where=ln > 0)
