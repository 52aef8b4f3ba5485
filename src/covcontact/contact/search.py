"""Global contact search: candidate master facets per slave node.

A facet is a candidate for a slave point when the point lies in the facet's bounding box inflated by
``margin`` in every direction. Boxes bound the facet itself, not only its nodes (see
:func:`covcontact.contact.surface.facet_boxes`), so no facet within ``margin`` of a point is missed.
The search is rebuilt once per load step (or whenever the caller wants) from current positions.

Two methods give the same exact set:

- ``"grid"`` (default): a bucket grid in numba. Every inflated box is entered in the cells it
  overlaps; the (cell key, facet) pairs are grouped by cell (counting sort on a dense grid when it
  has at most 4 cells per entry or 2^20 cells, else a sorted hashed list searched by bisection), and
  a slave tests the boxes listed in its own cell. O(nf + ns log ns).
- ``"kdtree"``: ``scipy.spatial.cKDTree`` on box centres queried with the largest inflated
  half-diagonal as radius, then the same exact box test.

Each slave's list is ordered by the distance from the slave to the (un-inflated) facet box, nearest
first: a lower bound of the distance to the facet that the projection driver uses to stop early.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from .surface import MeshSurface, facet_boxes

_MAX_DIM = 1 << 20  # cells per direction; keys fit in int64


@njit(cache=True)
def _box_dist2(p, lo, hi):
    d2 = 0.0
    for k in range(3):
        if p[k] < lo[k]:
            d2 += (lo[k] - p[k]) ** 2
        elif p[k] > hi[k]:
            d2 += (p[k] - hi[k]) ** 2
    return d2


@njit(cache=True)
def _grid_entries(blo, bhi, origin, h, dims):
    """(cell key, facet) pairs of every cell that an inflated box overlaps."""
    nf = blo.shape[0]
    cnt = np.zeros(nf + 1, dtype=np.int64)
    for f in range(nf):
        c = 1
        for k in range(3):
            c *= int(np.floor((bhi[f, k] - origin[k]) / h)) - int(np.floor((blo[f, k] - origin[k]) / h)) + 1
        cnt[f + 1] = cnt[f] + c
    keys = np.empty(cnt[nf], dtype=np.int64)
    fac = np.empty(cnt[nf], dtype=np.int64)
    for f in range(nf):
        i0 = int(np.floor((blo[f, 0] - origin[0]) / h))
        j0 = int(np.floor((blo[f, 1] - origin[1]) / h))
        k0 = int(np.floor((blo[f, 2] - origin[2]) / h))
        i1 = int(np.floor((bhi[f, 0] - origin[0]) / h))
        j1 = int(np.floor((bhi[f, 1] - origin[1]) / h))
        k1 = int(np.floor((bhi[f, 2] - origin[2]) / h))
        m = cnt[f]
        for i in range(i0, i1 + 1):
            for j in range(j0, j1 + 1):
                for k in range(k0, k1 + 1):
                    keys[m] = (i * dims[1] + j) * dims[2] + k
                    fac[m] = f
                    m += 1
    return keys, fac


@njit(cache=True)
def _sort_segment(p, lo, hi, facets, a, b, dist):
    """Insertion sort of facets[a:b] by box distance to p (lists are short)."""
    for m in range(a, b):
        dist[m] = _box_dist2(p, lo[facets[m]], hi[facets[m]])
    for m in range(a + 1, b):
        f = facets[m]
        d = dist[m]
        q = m - 1
        while q >= a and dist[q] > d:
            facets[q + 1] = facets[q]
            dist[q + 1] = dist[q]
            q -= 1
        facets[q + 1] = f
        dist[q + 1] = d


@njit(cache=True)
def _counting_sort(keys, fac, ncells):
    """Dense cell lists: (cptr (ncells + 1,), facets grouped by cell) in O(E + ncells)."""
    cptr = np.zeros(ncells + 1, dtype=np.int64)
    for m in range(keys.shape[0]):
        cptr[keys[m] + 1] += 1
    for c in range(ncells):
        cptr[c + 1] += cptr[c]
    pos = cptr[:-1].copy()
    out = np.empty(keys.shape[0], dtype=np.int64)
    for m in range(keys.shape[0]):
        out[pos[keys[m]]] = fac[m]
        pos[keys[m]] += 1
    return cptr, out


@njit(cache=True, parallel=True)
def _grid_query(xs, dense, ukeys, cptr, cfac, blo, bhi, lo, hi, origin, h, dims):
    """CSR of the facets whose inflated box holds each slave, nearest box first.

    Slaves are visited in cell order (better cache use for unordered slave sets); the lists are
    written at each slave's own position.
    """
    ns = xs.shape[0]
    cell = np.full(ns, -1, dtype=np.int64)
    for s in prange(ns):
        key = 0
        for k in range(3):
            c = np.floor((xs[s, k] - origin[k]) / h)
            if not (c >= 0.0 and c < dims[k]):  # also rejects NaN
                key = -1
                break
            key = key * dims[k] + int(c)
        if key < 0:
            continue
        if dense:
            cell[s] = key
        else:
            u = np.searchsorted(ukeys, key)
            if u < ukeys.shape[0] and ukeys[u] == key:
                cell[s] = u
    order = np.argsort(cell)
    count = np.zeros(ns + 1, dtype=np.int64)
    for q in prange(ns):
        s = order[q]
        u = cell[s]
        if u < 0:
            continue
        n = 0
        for m in range(cptr[u], cptr[u + 1]):
            f = cfac[m]
            if _box_dist2(xs[s], blo[f], bhi[f]) == 0.0:
                n += 1
        count[s + 1] = n
    ptr = np.cumsum(count)
    out = np.empty(ptr[ns], dtype=np.int64)
    dist = np.empty(ptr[ns])
    for q in prange(ns):
        s = order[q]
        u = cell[s]
        if u < 0:
            continue
        n = ptr[s]
        for m in range(cptr[u], cptr[u + 1]):
            f = cfac[m]
            if _box_dist2(xs[s], blo[f], bhi[f]) == 0.0:
                out[n] = f
                n += 1
        _sort_segment(xs[s], lo, hi, out, ptr[s], ptr[s + 1], dist)
    return ptr, out


@njit(cache=True, parallel=True)
def _filter_pairs(xs, ptr_in, fac_in, blo, bhi, lo, hi):
    """Exact box test and ordering of a superset CSR (from the tree)."""
    ns = xs.shape[0]
    count = np.zeros(ns + 1, dtype=np.int64)
    for s in prange(ns):
        n = 0
        for m in range(ptr_in[s], ptr_in[s + 1]):
            if _box_dist2(xs[s], blo[fac_in[m]], bhi[fac_in[m]]) == 0.0:
                n += 1
        count[s + 1] = n
    ptr = np.cumsum(count)
    out = np.empty(ptr[ns], dtype=np.int64)
    dist = np.empty(ptr[ns])
    for s in prange(ns):
        n = ptr[s]
        for m in range(ptr_in[s], ptr_in[s + 1]):
            if _box_dist2(xs[s], blo[fac_in[m]], bhi[fac_in[m]]) == 0.0:
                out[n] = fac_in[m]
                n += 1
        _sort_segment(xs[s], lo, hi, out, ptr[s], ptr[s + 1], dist)
    return ptr, out


def _grid(xs, lo, hi, blo, bhi, cell_factor):
    ext = bhi - blo
    h = cell_factor * float(np.mean(ext.max(axis=1)))
    origin = blo.min(axis=0)
    span = float((bhi.max(axis=0) - origin).max())
    h = max(h, span / (_MAX_DIM - 2), 1e-300)
    # a few very large boxes among small ones would fill many cells: coarsen until the table is small
    while True:
        per_box = np.prod(np.floor((bhi - origin) / h) - np.floor((blo - origin) / h) + 1.0, axis=1)
        if per_box.sum() <= 16.0 * len(blo) + 1e6:
            break
        h *= 2.0
    dims = (np.floor((bhi.max(axis=0) - origin) / h).astype(np.int64) + 1).astype(np.int64)
    keys, fac = _grid_entries(blo, bhi, origin, h, dims)
    ncells = int(dims[0]) * int(dims[1]) * int(dims[2])
    if ncells <= max(4 * keys.size, 1 << 20):
        cptr, fac = _counting_sort(keys, fac, ncells)
        return _grid_query(xs, True, keys[:0], cptr, fac, blo, bhi, lo, hi, origin, h, dims)
    order = np.argsort(keys, kind="stable")
    keys, fac = keys[order], fac[order]
    starts = np.flatnonzero(np.concatenate(([True], keys[1:] != keys[:-1])))
    cptr = np.concatenate((starts, [keys.size])).astype(np.int64)
    return _grid_query(xs, False, keys[starts], cptr, fac, blo, bhi, lo, hi, origin, h, dims)


def _kdtree(xs, lo, hi, blo, bhi):
    from scipy.spatial import cKDTree

    centre = 0.5 * (blo + bhi)
    radius = float(np.linalg.norm(0.5 * (bhi - blo), axis=1).max()) * (1.0 + 1e-12)
    tree = cKDTree(centre)
    lists = tree.query_ball_point(xs, radius, return_sorted=False)
    counts = np.fromiter((len(v) for v in lists), dtype=np.int64, count=xs.shape[0])
    ptr = np.concatenate(([0], np.cumsum(counts))).astype(np.int64)
    fac = np.fromiter((f for v in lists for f in v), dtype=np.int64, count=int(ptr[-1]))
    return _filter_pairs(xs, ptr, fac, blo, bhi, lo, hi)


def candidates(
    x_nodes: np.ndarray,
    surface: MeshSurface,
    slave_xyz: np.ndarray,
    margin: float,
    method: str = "grid",
    cell_factor: float = 1.0,
) -> tuple[np.ndarray, np.ndarray]:
    """Candidate facets per slave point.

    Args:
        x_nodes: (n, 3) current node positions.
        surface: the master surface.
        slave_xyz: (ns, 3) slave positions.
        margin: search distance added to every side of each facet box (>= 0).
        method: "grid" (numba bucket grid) or "kdtree" (scipy cKDTree).
        cell_factor: grid cell size as a multiple of the mean inflated box size ("grid" only).

    Returns:
        ptr (ns + 1,) and facets (m,) int64: the facets of slave s are ``facets[ptr[s]:ptr[s+1]]``,
        exactly those whose inflated box contains the slave, nearest box first.
    """
    if margin < 0.0 or not np.isfinite(margin):
        raise ValueError(f"margin must be finite and >= 0, got {margin}")
    xs = np.ascontiguousarray(slave_xyz, dtype=np.float64).reshape(-1, 3)
    if surface.n_facets == 0 or xs.shape[0] == 0:
        return np.zeros(xs.shape[0] + 1, dtype=np.int64), np.zeros(0, dtype=np.int64)
    lo, hi = facet_boxes(x_nodes, surface.faces)
    blo, bhi = lo - margin, hi + margin
    if method == "grid":
        return _grid(xs, lo, hi, blo, bhi, cell_factor)
    if method == "kdtree":
        return _kdtree(xs, lo, hi, blo, bhi)
    raise ValueError(f"unknown search method {method!r}; known: grid, kdtree")


def candidates_brute(
    x_nodes: np.ndarray, surface: MeshSurface, slave_xyz: np.ndarray, margin: float
) -> list[np.ndarray]:
    """Reference: for every slave, all facets whose inflated box contains it (O(ns * nf), tests only)."""
    lo, hi = facet_boxes(x_nodes, surface.faces)
    xs = np.asarray(slave_xyz, dtype=np.float64).reshape(-1, 3)
    out = []
    for p in xs:
        ok = np.all((p >= lo - margin) & (p <= hi + margin), axis=1)
        out.append(np.flatnonzero(ok))
    return out
