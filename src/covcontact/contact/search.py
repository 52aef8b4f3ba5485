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


@njit(cache=True, error_model="numpy", inline="always")
def _box_dist2(x0, x1, x2, lo, hi, f):
    """Squared distance from the point (x0, x1, x2) to box f of (lo, hi) (nf, 3) (scalars and indices, no array
    views: a view costs a reference count in the hot loops)."""
    d2 = 0.0
    for k in range(3):
        v = x0 if k == 0 else (x1 if k == 1 else x2)
        if v < lo[f, k]:
            d2 += (lo[f, k] - v) ** 2
        elif v > hi[f, k]:
            d2 += (v - hi[f, k]) ** 2
    return d2


@njit(cache=True, error_model="numpy", inline="always")
def _cell_span(blo, bhi, origin, h, f):
    """The grid cells (i0, j0, k0, i1, j1, k1), inclusive, that inflated box f overlaps."""
    return (int(np.floor((blo[f, 0] - origin[0]) / h)), int(np.floor((blo[f, 1] - origin[1]) / h)),
            int(np.floor((blo[f, 2] - origin[2]) / h)), int(np.floor((bhi[f, 0] - origin[0]) / h)),
            int(np.floor((bhi[f, 1] - origin[1]) / h)), int(np.floor((bhi[f, 2] - origin[2]) / h)))


@njit(cache=True, error_model="numpy")
def _grid_entries(blo, bhi, origin, h, dims):
    """(cell key, facet) pairs of every cell that an inflated box overlaps."""
    nf = blo.shape[0]
    cnt = np.zeros(nf + 1, dtype=np.int64)
    for f in range(nf):
        i0, j0, k0, i1, j1, k1 = _cell_span(blo, bhi, origin, h, f)
        cnt[f + 1] = cnt[f] + (i1 - i0 + 1) * (j1 - j0 + 1) * (k1 - k0 + 1)
    keys = np.empty(cnt[nf], dtype=np.int64)
    fac = np.empty(cnt[nf], dtype=np.int64)
    for f in range(nf):
        i0, j0, k0, i1, j1, k1 = _cell_span(blo, bhi, origin, h, f)
        m = cnt[f]
        for i in range(i0, i1 + 1):
            for j in range(j0, j1 + 1):
                for k in range(k0, k1 + 1):
                    keys[m] = (i * dims[1] + j) * dims[2] + k
                    fac[m] = f
                    m += 1
    return keys, fac


@njit(cache=True, error_model="numpy")
def _sort_segment(x0, x1, x2, lo, hi, facets, a, b, dist):
    """Insertion sort of facets[a:b] by box distance to (x0, x1, x2) (lists are short)."""
    for m in range(a, b):
        dist[m] = _box_dist2(x0, x1, x2, lo, hi, facets[m])
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


@njit(cache=True, error_model="numpy")
def counting_order(key, nkeys):
    """The indices 0..n-1 ordered by key (ints in [0, nkeys]), stable: a counting sort in O(n + nkeys)."""
    n = key.shape[0]
    cnt = np.zeros(nkeys + 2, dtype=np.int64)
    for s in range(n):
        cnt[key[s] + 1] += 1
    for k in range(nkeys + 1):
        cnt[k + 1] += cnt[k]
    order = np.empty(n, dtype=np.int64)
    for s in range(n):
        order[cnt[key[s]]] = s
        cnt[key[s]] += 1
    return order


@njit(cache=True, error_model="numpy")
def _coherent_order(cell, nbucket):
    """Slaves ordered by cell (nbucket buckets of consecutive cells); slaves outside the grid (cell -1) last."""
    ns = cell.shape[0]
    cmax = 0
    for s in range(ns):
        cmax = max(cmax, cell[s])
    key = np.empty(ns, dtype=np.int64)
    for s in range(ns):
        key[s] = nbucket if cell[s] < 0 else (cell[s] * nbucket) // (cmax + 1)
    return counting_order(key, nbucket)


@njit(cache=True, error_model="numpy", parallel=True)
def _grid_query(xs, dense, ukeys, cptr, cfac, blo, bhi, lo, hi, origin, h, dims):
    """CSR of the facets whose inflated box holds each slave, nearest box first.

    The slaves are first put in cell order (a counting sort) and processed in that order with their
    coordinates copied alongside, so that the box tests and list writes run through memory in sequence
    whatever the slave numbering; one final pass moves each list to its slave's position. The first pass
    keeps, per slave, a bit mask of the hits among the first 64 facets of its cell, so the second tests
    only the boxes beyond those.
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
    order = _coherent_order(cell, ns)
    xq = np.empty((ns, 3))
    cq = np.empty(ns, dtype=np.int64)
    count_q = np.zeros(ns + 1, dtype=np.int64)
    mask = np.zeros(ns, dtype=np.uint64)
    for q in prange(ns):
        s = order[q]
        u = cell[s]
        x0, x1, x2 = xs[s, 0], xs[s, 1], xs[s, 2]
        xq[q, 0] = x0
        xq[q, 1] = x1
        xq[q, 2] = x2
        cq[q] = u
        if u < 0:
            continue
        n = 0
        bits = np.uint64(0)
        for m in range(cptr[u], cptr[u + 1]):
            if _box_dist2(x0, x1, x2, blo, bhi, cfac[m]) == 0.0:
                n += 1
                if m - cptr[u] < 64:
                    bits |= np.uint64(1) << np.uint64(m - cptr[u])
        count_q[q + 1] = n
        mask[q] = bits
    ptr_q = np.cumsum(count_q)
    out_q = np.empty(ptr_q[ns], dtype=np.int64)
    dist = np.empty(ptr_q[ns])
    for q in prange(ns):
        u = cq[q]
        if u < 0:
            continue
        x0, x1, x2 = xq[q, 0], xq[q, 1], xq[q, 2]
        n = ptr_q[q]
        bits = mask[q]
        c0 = cptr[u]
        for m in range(c0, min(cptr[u + 1], c0 + 64)):
            if (bits >> np.uint64(m - c0)) & np.uint64(1):
                out_q[n] = cfac[m]
                n += 1
        for m in range(c0 + 64, cptr[u + 1]):
            if _box_dist2(x0, x1, x2, blo, bhi, cfac[m]) == 0.0:
                out_q[n] = cfac[m]
                n += 1
        _sort_segment(x0, x1, x2, lo, hi, out_q, ptr_q[q], ptr_q[q + 1], dist)
    count = np.zeros(ns + 1, dtype=np.int64)
    for q in range(ns):
        count[order[q] + 1] = count_q[q + 1]
    ptr = np.cumsum(count)
    out = np.empty(ptr[ns], dtype=np.int64)
    for q in prange(ns):
        n = ptr[order[q]]
        for m in range(ptr_q[q], ptr_q[q + 1]):
            out[n] = out_q[m]
            n += 1
    return ptr, out


@njit(cache=True, error_model="numpy", parallel=True)
def _filter_pairs(xs, ptr_in, fac_in, blo, bhi, lo, hi):
    """Exact box test and ordering of a superset CSR (from the tree)."""
    ns = xs.shape[0]
    count = np.zeros(ns + 1, dtype=np.int64)
    for s in prange(ns):
        n = 0
        for m in range(ptr_in[s], ptr_in[s + 1]):
            if _box_dist2(xs[s, 0], xs[s, 1], xs[s, 2], blo, bhi, fac_in[m]) == 0.0:
                n += 1
        count[s + 1] = n
    ptr = np.cumsum(count)
    out = np.empty(ptr[ns], dtype=np.int64)
    dist = np.empty(ptr[ns])
    for s in prange(ns):
        n = ptr[s]
        for m in range(ptr_in[s], ptr_in[s + 1]):
            if _box_dist2(xs[s, 0], xs[s, 1], xs[s, 2], blo, bhi, fac_in[m]) == 0.0:
                out[n] = fac_in[m]
                n += 1
        _sort_segment(xs[s, 0], xs[s, 1], xs[s, 2], lo, hi, out, ptr[s], ptr[s + 1], dist)
    return ptr, out


@njit(cache=True, error_model="numpy")
def _grid_plan(blo, bhi, cell_factor, max_dim):
    """Cell size h, origin and dims of the bucket grid, and its number of (cell, facet) entries.

    h starts at cell_factor times the mean largest box extent; a few very large boxes among small ones
    would fill many cells, so h doubles until the table holds at most 16 entries per box (+ 1e6).
    """
    nf = blo.shape[0]
    origin = np.empty(3)
    top = np.empty(3)
    mean_ext = 0.0
    for k in range(3):
        origin[k] = np.inf
        top[k] = -np.inf
    for f in range(nf):
        e = 0.0
        for k in range(3):
            origin[k] = min(origin[k], blo[f, k])
            top[k] = max(top[k], bhi[f, k])
            e = max(e, bhi[f, k] - blo[f, k])
        mean_ext += e
    h = cell_factor * mean_ext / nf
    span = max(top[0] - origin[0], top[1] - origin[1], top[2] - origin[2])
    h = max(h, span / (max_dim - 2), 1e-300)
    while True:
        total = 0.0
        for f in range(nf):
            i0, j0, k0, i1, j1, k1 = _cell_span(blo, bhi, origin, h, f)
            total += float(i1 - i0 + 1) * float(j1 - j0 + 1) * float(k1 - k0 + 1)
        if total <= 16.0 * nf + 1e6:
            break
        h *= 2.0
    dims = np.empty(3, dtype=np.int64)
    for k in range(3):
        dims[k] = int(np.floor((top[k] - origin[k]) / h)) + 1
    return h, origin, dims, int(total)


@njit(cache=True, error_model="numpy")
def _dense_cells(blo, bhi, origin, h, dims):
    """Cell lists of a dense grid, (cptr (ncells + 1,), facets by cell, ascending within a cell): the boxes
    are counted per cell, then entered, without an intermediate (key, facet) list."""
    nf = blo.shape[0]
    ncells = dims[0] * dims[1] * dims[2]
    cptr = np.zeros(ncells + 1, dtype=np.int64)
    for f in range(nf):
        i0, j0, k0, i1, j1, k1 = _cell_span(blo, bhi, origin, h, f)
        for i in range(i0, i1 + 1):
            for j in range(j0, j1 + 1):
                for k in range(k0, k1 + 1):
                    cptr[(i * dims[1] + j) * dims[2] + k + 1] += 1
    for c in range(ncells):
        cptr[c + 1] += cptr[c]
    pos = cptr[:-1].copy()
    out = np.empty(cptr[ncells], dtype=np.int64)
    for f in range(nf):
        i0, j0, k0, i1, j1, k1 = _cell_span(blo, bhi, origin, h, f)
        for i in range(i0, i1 + 1):
            for j in range(j0, j1 + 1):
                for k in range(k0, k1 + 1):
                    key = (i * dims[1] + j) * dims[2] + k
                    out[pos[key]] = f
                    pos[key] += 1
    return cptr, out


def _grid(xs, lo, hi, blo, bhi, cell_factor):
    h, origin, dims, total = _grid_plan(blo, bhi, float(cell_factor), float(_MAX_DIM))
    ncells = int(dims[0]) * int(dims[1]) * int(dims[2])
    if ncells <= max(4 * total, 1 << 20):
        cptr, fac = _dense_cells(blo, bhi, origin, h, dims)
        return _grid_query(xs, True, np.zeros(0, np.int64), cptr, fac, blo, bhi, lo, hi, origin, h, dims)
    keys, fac = _grid_entries(blo, bhi, origin, h, dims)
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
