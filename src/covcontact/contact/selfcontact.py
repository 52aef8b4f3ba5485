"""Self-contact: one surface is slave and master of itself (docs/theory.md, section 13).

Every slave (a node of the surface, or a Gauss point of one of its facets) searches the whole surface except
its own facets: those around the slave node, or the slave point's facet. The rest is
told apart geometrically, since a surface meets itself face to face: a candidate facet counts only if its normal
opposes the slave's own outward normal (n_s . n_f < 0, at the facet's centre), and an edge or vertex point only
if the slave lies in front of it (the unit vector from the point to the slave within 60 degrees of -n_s); a
slave that had a contact point at the last iterate keeps them up to a cosine 0.5 larger (hysteresis). A
neighbour along a smooth surface is seen sideways (its closest point lies on the boundary of the excluded
facets, in the tangent direction), never in front, so it gives no contact however the surface curves, while the
other side of a fold does, however close along the surface it is.
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


#: an edge or vertex point counts if the slave lies within this cosine of the direction -n_s from it
FRONT_COS = 0.5
#: hysteresis: a slave with a contact point at the last iterate keeps facets and points up to this much more
#: cosine (a slave passing round a fold otherwise loses and regains its contact point from one iterate to the
#: next, and Newton cycles)
HOLD_COS = 0.5


def excluded_facets(faces: np.ndarray, n_nodes: int, slave_nodes: np.ndarray | None = None,
                    slave_facets: np.ndarray | None = None) -> np.ndarray:
    """(ns, width) facets each slave never contacts, -1 padded: for slave nodes the facets around the node, for
    slave points (given by their facet) the point's facet. Their neighbours face the same way and are dropped by
    the facing test (a wider exclusion hid real contacts at a tight fold: points next to a flattened tube's lobe
    lost their partners across it)."""
    A = _incidence(faces, n_nodes)
    if slave_nodes is not None:
        ring = A.T.tocsr()[slave_nodes]
    else:
        ring = sp.csr_matrix((np.ones(len(slave_facets)), (np.arange(len(slave_facets)), slave_facets)),
                             shape=(len(slave_facets), len(faces)))
    return _padded(ring)


@njit(cache=True)
def drop_excluded(ptr, fac, excl, own, fn, cos_max):
    """The candidate CSR (ptr, fac) without each slave's excluded facets (rows of ``excl``, -1 padded) and the
    facets whose normal ``fn`` (nf, 3) makes a cosine of ``cos_max[s]`` or more with the slave's own normal
    ``own`` (ns, 3)."""
    ns = ptr.shape[0] - 1
    out_ptr = np.zeros(ns + 1, dtype=np.int64)
    out = np.empty(fac.shape[0], dtype=np.int64)
    m = 0
    for s in range(ns):
        for k in range(ptr[s], ptr[s + 1]):
            f = fac[k]
            hit = own[s, 0] * fn[f, 0] + own[s, 1] * fn[f, 1] + own[s, 2] * fn[f, 2] >= cos_max[s]
            for e in range(excl.shape[1]):
                if hit:
                    break
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


def slave_normals(xe: np.ndarray, surface, slaves: np.ndarray, own_facet: np.ndarray | None,
                  fn: np.ndarray | None = None) -> np.ndarray:
    """The slaves' own outward normals: their facet's (points) or the mean of the facets around them (nodes);
    ``fn`` the facet normals if at hand."""
    fn = facet_normals(xe, surface.faces) if fn is None else fn
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
