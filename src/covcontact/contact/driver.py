"""Contact point of every slave node on a whole master surface (docs/theory.md section 4).

For each slave the driver walks over its candidate facets (from :mod:`.search`, nearest box first;
the previous facet of the slave first when one is given, started from its previous xi) and runs the
single-facet projection on each:

- a converged projection inside ``[-1, 1]^2`` enlarged by ``tol_inside`` is *accepted*, unless it
  lies through the body on the far face (``g < -gmax``) or, with a previous facet, on a facet whose
  normal turned by more than ``acos(min_cos)`` from the previous normal (a thin body's other side);
- a projection outside hands over to the neighbour across the edge it left through (the edge with
  the larger overshoot), at most ``max_hops`` times, starting there at the same point of the edge;
- once a facet is accepted, candidates whose box lies farther away than the best ``|g|`` are skipped;
- among accepted facets (concave regions) the smallest ``|g|`` wins, with hysteresis: the previous
  facet is kept unless another is better by more than the relative tolerance ``hysteresis``;
- if no facet accepts the point but projections left through interior edges (the blind spot of a
  convex edge or vertex, or below a concave edge), the point is projected onto those edge curves
  (1D Newton on (r_s - r(t)) . r' = 0, t in [-1, 1]); the closest one gives an *edge* point, or a
  *vertex* point when it lies at an end of the edge. Such a point counts only when the slave lies in
  the wedge of that edge or vertex (the distance does not decrease into any facet around it, the
  first-order condition of a constrained minimum), not over a facet. Boundary edges and vertices of
  an open surface never give contact (the point is off the surface). The gap is the distance with the sign of the
  averaged outward normal there (both facets' normals at the edge point; all facets' normals at the
  vertex); ``normal`` is then the unit vector from the edge/vertex point to the slave (times that
  sign), the direction of the distance, and ``xi`` the point on ``facet``'s boundary.

Everything is bounded: hops, visited facets (64), recorded edges (32) and Newton iterations. The
outputs never hold NaN; a slave without contact point has facet -1, xi 0, g = +inf, normal 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np
from numba import njit, prange

from .projection import planar_start, project_inline
from .search import _box_dist2, candidates, counting_order
from .surface import (
    EDGE_DIR,
    EDGE_START,
    MeshSurface,
    edge_closest_point,
    facet_boxes,
    facet_frame,
    facet_frame_inline,
    facet_sizes,
    gather_facet,
)

NO_CONTACT = 0
FACET = 1
EDGE = 2
VERTEX = 3

_MAX_VISITED = 64
_MAX_EDGES = 32
_ES = EDGE_START
_ED = EDGE_DIR


@njit(cache=True, error_model="numpy")
def _kkt_ok(d, t, sgn, tol):
    """The distance does not decrease into the facet along the inward tangent sgn * t:
    (r_s - c) . (sgn t) <= tol |t|."""
    return sgn * (d[0] * t[0] + d[1] * t[1] + d[2] * t[2]) <= tol * np.sqrt(t[0] ** 2 + t[1] ** 2 + t[2] ** 2)


@njit(cache=True, error_model="numpy", inline="always")
def _walk(f, xi, xs, x, faces, nbr_facet, nbr_edge, gmax, tol_in, tol_first, tol_bnd, min_cos, max_hops, use_dir, ndir,
          xyz, rho, t1, t2, nrm, pc, pG, vis, nvis, edges, nedge):  # fmt: skip
    """Project on f, hand over across edges; returns (accepted facet or -1, g, nvis, nedge). f accepts a point up to
    tol_first outside it, and up to tol_bnd outside it across edges of the surface's boundary (no facet beyond); the
    facets handed over to up to tol_in.

    Records every edge a projection left through in ``edges`` (for the blind-spot rule). Arrays come one by one,
    not in tuples: unpacking a tuple of arrays costs reference counts in this hottest loop.
    """
    for hop in range(max_hops + 1):
        for k in range(nvis):
            if vis[k] == f:
                return -1, 0.0, nvis, nedge
        if nvis < vis.shape[0]:
            vis[nvis] = f
            nvis += 1
        gather_facet(x, faces, f, xyz)
        status, g, _nit = project_inline(xyz, xs, xi, pc, pG, 30, 1e-12)
        if status == 2 or not (np.isfinite(xi[0]) and np.isfinite(xi[1]) and np.isfinite(g)):
            return -1, 0.0, nvis, nedge
        o1 = abs(xi[0]) - 1.0
        o2 = abs(xi[1]) - 1.0
        tol = tol_first if hop == 0 else tol_in
        ea = 1 if xi[0] > 0.0 else 3  # edges 1 / 3 lie at xi1 = +1 / -1, edges 2 / 0 at xi2 = +1 / -1
        eb = 2 if xi[1] > 0.0 else 0
        inside = o1 <= tol and o2 <= tol
        if not inside and hop == 0 and tol_bnd > tol:  # (beyond the boundary by less than tol_bnd: kept)
            inside = (o1 <= tol or (o1 <= tol_bnd and nbr_facet[f, ea] < 0)) and \
                (o2 <= tol or (o2 <= tol_bnd and nbr_facet[f, eb] < 0))
        if inside:
            if status != 0 or not (g > -gmax[f]):
                return -1, 0.0, nvis, nedge
            if use_dir:
                facet_frame_inline(xyz, xi[0], xi[1], rho, t1, t2, nrm)
                if nrm[0] * ndir[0] + nrm[1] * ndir[1] + nrm[2] * ndir[2] < min_cos:
                    return -1, 0.0, nvis, nedge
            return f, g, nvis, nedge
        for e, o in ((ea, o1), (eb, o2)):
            if o > tol and nedge < edges.shape[0]:
                dup = False
                for k in range(nedge):
                    dup = dup or (edges[k, 0] == f and edges[k, 1] == e)
                if not dup:
                    edges[nedge, 0] = f
                    edges[nedge, 1] = e
                    nedge += 1
        e = ea if o1 >= o2 else eb
        nb = nbr_facet[f, e]
        if nb < 0 or hop == max_hops:
            return -1, 0.0, nvis, nedge
        # same point of the shared edge on the neighbour (edges of consistently oriented facets run
        # in opposite directions)
        c1 = min(max(xi[0], -1.0), 1.0)
        c2 = min(max(xi[1], -1.0), 1.0)
        t = (c1 - _ES[e, 0]) * _ED[e, 0] + (c2 - _ES[e, 1]) * _ED[e, 1] - 1.0
        ne = nbr_edge[f, e]
        if faces[nb, ne] == faces[f, (e + 1) % 4]:
            t = -t
        xi[0] = _ES[ne, 0] + (t + 1.0) * _ED[ne, 0]
        xi[1] = _ES[ne, 1] + (t + 1.0) * _ED[ne, 1]
        f = nb
    return -1, 0.0, nvis, nedge


@njit(cache=True, error_model="numpy")
def _blind_spot(xs, x, topo, prm, edges, nedge, scr, c, xi_out, n_out):
    """Closest interior edge or vertex among the recorded exit edges; returns (kind, facet, g).

    An edge point c (or vertex v) counts only where it is a constrained local minimum of the distance
    on every facet around it (first-order condition: (r_s - c) . m <= 0 for each inward tangent m),
    i.e. the slave lies in the wedge of that edge or vertex, not over a facet of it.
    """
    faces, nbr_facet, nbr_edge, on_bnd, n2f_ptr, n2f_fac = topo
    gmax, tol_in = prm[0], prm[1]
    xyz, rho, t1, t2, nrm = scr
    nsum = np.empty(3)
    d = np.empty(3)
    best_d2 = np.inf
    best_kind = NO_CONTACT
    best_sign = 1.0
    bf = -1
    for k in range(nedge):
        f = edges[k, 0]
        e = edges[k, 1]
        nb = nbr_facet[f, e]
        if nb < 0:
            continue
        gather_facet(x, faces, f, xyz)
        t, d2 = edge_closest_point(xyz, e, xs, c)
        if not (d2 < best_d2):
            continue
        dist = np.sqrt(d2)
        for p in range(3):
            d[p] = xs[p] - c[p]
            nsum[p] = 0.0
        ok = True
        kind = EDGE
        if abs(t) >= 1.0 - 1e-12:
            kind = VERTEX
            v = faces[f, e] if t < 0.0 else faces[f, (e + 1) % 4]
            if on_bnd[v]:
                continue
            for m in range(n2f_ptr[v], n2f_ptr[v + 1]):
                fv = n2f_fac[m]
                for a in range(4):
                    if faces[fv, a] == v:
                        gather_facet(x, faces, fv, xyz)
                        facet_frame(xyz, _ES[a, 0], _ES[a, 1], rho, t1, t2, nrm)
                        ok = ok and _kkt_ok(d, t1, -_ES[a, 0], tol_in * dist)
                        ok = ok and _kkt_ok(d, t2, -_ES[a, 1], tol_in * dist)
                        for p in range(3):
                            nsum[p] += nrm[p]
        else:
            ne = nbr_edge[f, e]
            tn = -t if faces[nb, ne] == faces[f, (e + 1) % 4] else t
            for side in range(2):
                ff, ee, tt = (f, e, t) if side == 0 else (nb, ne, tn)
                gather_facet(x, faces, ff, xyz)
                xi1 = _ES[ee, 0] + (tt + 1.0) * _ED[ee, 0]
                xi2 = _ES[ee, 1] + (tt + 1.0) * _ED[ee, 1]
                facet_frame(xyz, xi1, xi2, rho, t1, t2, nrm)
                # edges 1, 3 fix xi1 = +1, -1 (inward -xi1 rho_1); edges 0, 2 fix xi2 = -1, +1
                if ee % 2 == 1:
                    ok = ok and _kkt_ok(d, t1, -xi1, tol_in * dist)
                else:
                    ok = ok and _kkt_ok(d, t2, -xi2, tol_in * dist)
                for p in range(3):
                    nsum[p] += nrm[p]
        if not ok:
            continue
        ln = np.sqrt(nsum[0] ** 2 + nsum[1] ** 2 + nsum[2] ** 2)
        dn = 0.0
        for p in range(3):
            nsum[p] = nsum[p] / ln if ln > 0.0 else 0.0
            dn += d[p] * nsum[p]
        sign = 1.0 if dn >= 0.0 else -1.0
        if not (sign * dist > -gmax[f]):
            continue
        best_d2 = d2
        best_kind = kind
        best_sign = sign
        bf = f
        xi_out[0] = _ES[e, 0] + (t + 1.0) * _ED[e, 0]
        xi_out[1] = _ES[e, 1] + (t + 1.0) * _ED[e, 1]
        scale = max(abs(xs[0]), abs(xs[1]), abs(xs[2]), abs(c[0]), abs(c[1]), abs(c[2]))
        for p in range(3):
            n_out[p] = sign * d[p] / dist if dist > 1e-14 * scale and dist > 0.0 else nsum[p]
    if bf < 0:
        return NO_CONTACT, -1, 0.0
    return best_kind, bf, best_sign * np.sqrt(best_d2)


@njit(cache=True, error_model="numpy")
def _hull_dist2(xyz, xs, cp):
    """Lower bound of the squared distance from xs to the facet xyz: the distance to the box, in the facet's
    corner frame, of its control net (the nodes of a quad4; the Bernstein net of a quad9), which holds the
    facet. ``cp`` is (9, 3) scratch."""
    nen = xyz.shape[0]
    for p in range(3):
        for a in range(4):
            cp[a, p] = xyz[a, p]
        if nen == 9:
            for a in range(4):
                cp[4 + a, p] = 2.0 * xyz[4 + a, p] - 0.5 * (xyz[a, p] + xyz[(a + 1) % 4, p])
            cp[8, p] = (4.0 * xyz[8, p] - (xyz[4, p] + xyz[5, p] + xyz[6, p] + xyz[7, p])
                        + 0.25 * (xyz[0, p] + xyz[1, p] + xyz[2, p] + xyz[3, p]))
    t10 = xyz[1, 0] + xyz[2, 0] - xyz[0, 0] - xyz[3, 0]
    t11 = xyz[1, 1] + xyz[2, 1] - xyz[0, 1] - xyz[3, 1]
    t12 = xyz[1, 2] + xyz[2, 2] - xyz[0, 2] - xyz[3, 2]
    t20 = xyz[2, 0] + xyz[3, 0] - xyz[0, 0] - xyz[1, 0]
    t21 = xyz[2, 1] + xyz[3, 1] - xyz[0, 1] - xyz[1, 1]
    t22 = xyz[2, 2] + xyz[3, 2] - xyz[0, 2] - xyz[1, 2]
    n0 = t11 * t22 - t12 * t21
    n1 = t12 * t20 - t10 * t22
    n2 = t10 * t21 - t11 * t20
    ln = np.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
    l1 = np.sqrt(t10 * t10 + t11 * t11 + t12 * t12)
    if not (ln > 0.0 and l1 > 0.0):
        return 0.0
    n0 /= ln
    n1 /= ln
    n2 /= ln
    t10 /= l1
    t11 /= l1
    t12 /= l1
    # t2 := n x t1 (t1 is normal to n by construction)
    t20 = n1 * t12 - n2 * t11
    t21 = n2 * t10 - n0 * t12
    t22 = n0 * t11 - n1 * t10
    d2 = 0.0
    for ax in range(3):
        if ax == 0:
            e0, e1, e2 = t10, t11, t12
        elif ax == 1:
            e0, e1, e2 = t20, t21, t22
        else:
            e0, e1, e2 = n0, n1, n2
        lo = np.inf
        hi = -np.inf
        for a in range(nen):
            v = cp[a, 0] * e0 + cp[a, 1] * e1 + cp[a, 2] * e2
            lo = min(lo, v)
            hi = max(hi, v)
        v = xs[0] * e0 + xs[1] * e1 + xs[2] * e2
        if v < lo:
            d2 += (lo - v) ** 2
        elif v > hi:
            d2 += (v - hi) ** 2
    return d2


@njit(cache=True, error_model="numpy", inline="always")
def _project_one(xs, x, faces, nbr_facet, nbr_edge, lo, hi, cand_fac, c0, c1, pf, gmax, fprm, max_hops, xyz, rho,
                 t1, t2, nrm, xi, pxi, ndir, cp, pc, pG, vis, edges, xi_out, n_out):  # fmt: skip
    """Contact point of one slave on its candidates cand_fac[c0:c1]; returns (kind, facet, g, nedge) and writes
    xi_out (2,), n_out (3,). kind -1: no facet accepts the point, the caller tries the blind spot (``edges``).

    xi holds the previous contact point on pf on entry (when pf >= 0); fprm = (tol_inside, hysteresis, min_cos,
    tol_keep, tol_boundary): the previous facet accepts a projection up to tol_keep outside it, and up to
    tol_boundary across the surface's boundary.
    At most 30 arguments: beyond that Python passes them as a tuple, which numba cannot inline.
    """
    tol_in, hyst, min_cos, tol_keep, tol_bnd = fprm
    nvis = 0
    nedge = 0
    best_f = -1
    best_g = 0.0
    prev_g = 0.0
    prev_ok = False
    use_dir = False
    if pf >= 0:
        xi[0] = xi[0] if np.isfinite(xi[0]) else 0.0
        xi[1] = xi[1] if np.isfinite(xi[1]) else 0.0
        gather_facet(x, faces, pf, xyz)
        facet_frame_inline(xyz, min(max(xi[0], -1.0), 1.0), min(max(xi[1], -1.0), 1.0), rho, t1, t2, ndir)
        use_dir = min_cos > -1.0
    # the previous facet first (from its previous xi), then the candidates; one call site of the walk (it is
    # compiled in place)
    for m in range(c0 - 1 if pf >= 0 else c0, c1):
        if m < c0:
            f0 = pf
        else:
            f0 = cand_fac[m]
            # boxes bound the facets: one farther than the best |g| cannot do better
            if best_f >= 0 and _box_dist2(xs[0], xs[1], xs[2], lo, hi, f0) > best_g * best_g:
                break
            seen = False  # already projected on (a walk's hand-over, or the previous facet)
            for k in range(nvis):
                if vis[k] == f0:
                    seen = True
                    break
            if seen:
                continue
            if best_f >= 0:  # a tighter bound: the facet's own oriented box
                gather_facet(x, faces, f0, xyz)
                if _hull_dist2(xyz, xs, cp) > best_g * best_g:
                    continue
            planar_start(x, faces, f0, xs, xi)
        tol = tol_keep if m < c0 else tol_in
        tb = max(tol_bnd, tol) if m < c0 else tol_in
        f, g, nvis, nedge = _walk(f0, xi, xs, x, faces, nbr_facet, nbr_edge, gmax, tol_in, tol, tb, min_cos, max_hops,
                                  use_dir, ndir, xyz, rho, t1, t2, nrm, pc, pG, vis, nvis, edges, nedge)  # fmt: skip
        if f >= 0 and (best_f < 0 or abs(g) < abs(best_g)):
            best_f, best_g = f, g
            xi_out[0] = xi[0]
            xi_out[1] = xi[1]
        if m < c0 and f >= 0 and f == pf:
            prev_ok, prev_g = True, g
            pxi[0] = xi[0]
            pxi[1] = xi[1]
    if prev_ok and not (abs(best_g) < (1.0 - hyst) * abs(prev_g)):
        best_f, best_g = pf, prev_g
        xi_out[0] = pxi[0]
        xi_out[1] = pxi[1]
    if best_f >= 0:
        gather_facet(x, faces, best_f, xyz)
        facet_frame_inline(xyz, xi_out[0], xi_out[1], rho, t1, t2, n_out)
        return FACET, best_f, best_g, nedge
    return -1, -1, 0.0, nedge


@njit(cache=True, error_model="numpy", parallel=True)
def project_slaves_kernel(xs, x, topo, lo, hi, cand_ptr, cand_fac, prev_facet, prev_xi, prm, nchunk, out_facet, out_xi,
                          out_g, out_kind, out_n):  # fmt: skip
    """Contact point of every slave (see the module docstring); writes the out arrays.

    The per-slave arrays (xs, the candidate CSR, prev_facet, prev_xi and the outputs) are in visiting order,
    permuted by the caller (``visit_order``, ``_gather_in_order``): sequential memory traffic in the kernel whatever
    the slave numbering.

    Args:
        xs: (ns, 3) slaves. x: (n, 3) nodes. topo: (faces, nbr_facet, nbr_edge, node_on_boundary,
            node_ptr, node_facets) of the surface. lo, hi: (nf, 3) facet boxes. cand_ptr, cand_fac:
            candidate CSR. prev_facet (ns,), prev_xi (ns, 2): last converged contact point, facet -1 for none.
        prm: (gmax (nf,), tol_inside, hysteresis, min_cos, max_hops, tol_keep, tol_boundary).
        nchunk: slaves are processed in nchunk parallel chunks (scratch allocated per chunk).
    """
    ns = xs.shape[0]
    faces, nbr_facet, nbr_edge = topo[0], topo[1], topo[2]
    gmax, tol_in, hyst, min_cos, max_hops, tol_keep, tol_bnd = prm
    fprm = (tol_in, hyst, min_cos, tol_keep, tol_bnd)
    nen = faces.shape[1]
    for ch in prange(nchunk):
        xyz = np.empty((nen, 3))
        rho = np.empty(3)
        t1 = np.empty(3)
        t2 = np.empty(3)
        nrm = np.empty(3)
        xi = np.empty(2)
        pxi = np.empty(2)
        ndir = np.zeros(3)
        c = np.empty(3)
        cp = np.empty((9, 3))
        pc = np.empty((3, 3, 3))
        pG = np.empty((6, 3))
        vis = np.empty(_MAX_VISITED, dtype=np.int64)
        edges = np.empty((_MAX_EDGES, 2), dtype=np.int64)
        xsv = np.empty(3)
        xo = np.empty(2)
        no = np.empty(3)
        for q in range(ch * ns // nchunk, (ch + 1) * ns // nchunk):
            xsv[0] = xs[q, 0]
            xsv[1] = xs[q, 1]
            xsv[2] = xs[q, 2]
            xi[0] = prev_xi[q, 0]
            xi[1] = prev_xi[q, 1]
            kind, f, g, nedge = _project_one(xsv, x, faces, nbr_facet, nbr_edge, lo, hi, cand_fac, cand_ptr[q],
                                             cand_ptr[q + 1], prev_facet[q], gmax, fprm, max_hops, xyz, rho, t1, t2,
                                             nrm, xi, pxi, ndir, cp, pc, pG, vis, edges, xo, no)  # fmt: skip
            if kind < 0:
                kind, f, g = _blind_spot(xsv, x, topo, prm, edges, nedge, (xyz, rho, t1, t2, nrm), c, xo, no)
            out_kind[q] = kind
            out_facet[q] = f
            if kind == NO_CONTACT:
                out_g[q] = np.inf
                for p in range(2):
                    out_xi[q, p] = 0.0
                for p in range(3):
                    out_n[q, p] = 0.0
            else:
                out_g[q] = g
                out_xi[q, 0] = xo[0]
                out_xi[q, 1] = xo[1]
                for p in range(3):
                    out_n[q, p] = no[p]


@njit(cache=True, error_model="numpy")
def _gather_in_order(order, xs, pf, pxi, ptr, fac):
    """The slaves' coordinates, previous contact points and candidate lists in the visiting order ``order``, in one
    pass over the slaves (a randomly numbered slave set costs one memory miss per slave and array)."""
    ns = order.shape[0]
    xs_o = np.empty((ns, 3))
    pf_o = np.empty(ns, dtype=np.int64)
    pxi_o = np.empty((ns, 2))
    ptr_o = np.empty(ns + 1, dtype=np.int64)
    ptr_o[0] = 0
    for q in range(ns):
        s = order[q]
        xs_o[q, 0] = xs[s, 0]
        xs_o[q, 1] = xs[s, 1]
        xs_o[q, 2] = xs[s, 2]
        pf_o[q] = pf[s]
        pxi_o[q, 0] = pxi[s, 0]
        pxi_o[q, 1] = pxi[s, 1]
        ptr_o[q + 1] = ptr_o[q] + ptr[s + 1] - ptr[s]
    fac_o = np.empty(ptr_o[ns], dtype=np.int64)
    for q in range(ns):
        m = ptr_o[q]
        for k in range(ptr[order[q]], ptr[order[q] + 1]):
            fac_o[m] = fac[k]
            m += 1
    return xs_o, pf_o, pxi_o, ptr_o, fac_o


@njit(cache=True, error_model="numpy")
def _scatter_from_order(order, facet, xi, g, kind, normal, out_facet, out_xi, out_g, out_kind, out_normal):
    """The results in visiting order back to the slaves' numbering, one pass."""
    for q in range(order.shape[0]):
        s = order[q]
        out_facet[s] = facet[q]
        out_xi[s, 0] = xi[q, 0]
        out_xi[s, 1] = xi[q, 1]
        out_g[s] = g[q]
        out_kind[s] = kind[q]
        out_normal[s, 0] = normal[q, 0]
        out_normal[s, 1] = normal[q, 1]
        out_normal[s, 2] = normal[q, 2]


@njit(cache=True, error_model="numpy")
def visit_order(prev_facet, cand_ptr, cand_fac, nf):
    """Slaves grouped by their previous (else first candidate) facet, a counting sort in O(ns + nf): neighbouring
    slaves then share facet data in cache whatever the slave numbering."""
    ns = prev_facet.shape[0]
    key = np.empty(ns, dtype=np.int64)
    for s in range(ns):
        k = prev_facet[s]
        if k < 0:
            k = cand_fac[cand_ptr[s]] if cand_ptr[s + 1] > cand_ptr[s] else nf
        key[s] = k
    return counting_order(key, nf)


@dataclass
class ProjectionResult:
    """Per-slave contact points.

    Attributes:
        facet: (ns,) int64 facet of the contact point, -1 without one.
        xi: (ns, 2) its element coordinates on ``facet`` (on the facet boundary for edge/vertex points).
        g: (ns,) signed normal gap (negative: penetration), +inf without contact point.
        kind: (ns,) int8: 0 no contact point, 1 facet interior, 2 edge, 3 vertex.
        normal: (ns, 3) unit normal at the contact point (see the module docstring for edges/vertices).
    """

    facet: np.ndarray
    xi: np.ndarray
    g: np.ndarray
    kind: np.ndarray
    normal: np.ndarray


def project_slaves(
    x_nodes: np.ndarray,
    surface: MeshSurface,
    slave_xyz: np.ndarray,
    cand_ptr: np.ndarray,
    cand_facets: np.ndarray,
    prev_facet: np.ndarray | None = None,
    prev_xi: np.ndarray | None = None,
    gmax: float | np.ndarray | None = None,
    *,
    tol_inside: float = 1e-7,
    hysteresis: float = 1e-3,
    min_cos: float = -0.5,
    max_hops: int = 4,
    boxes: tuple[np.ndarray, np.ndarray] | None = None,
    tol_keep: float | None = None,
    tol_boundary: float | None = None,
) -> ProjectionResult:
    """Contact point of each slave on the whole master surface.

    Args:
        x_nodes: (n, 3) current node positions.
        surface: master surface.
        slave_xyz: (ns, 3) slave positions.
        cand_ptr, cand_facets: candidate CSR from :func:`covcontact.contact.search.candidates`.
        prev_facet: (ns,) last converged facet per slave, -1 for none (warm start and hysteresis).
        prev_xi: (ns, 2) last converged xi on ``prev_facet``.
        gmax: largest accepted penetration depth: a scalar, (nf,) per facet, or None for half the
            facet size (longer diagonal).
        tol_inside: a projection inside [-1 - tol, 1 + tol]^2 lies on the facet.
        hysteresis: relative |g| improvement needed to leave the previous facet.
        min_cos: with a previous facet, facets whose normal makes a cosine below this with the
            previous normal are rejected (thin-body far face); -1 switches the guard off.
        max_hops: largest number of hand-overs across edges per walk.
        tol_keep: the previous facet accepts a projection up to this much outside it (element coordinates; default
            ``tol_inside``): a slave that sits on an edge keeps its facet while Newton moves it across by less.
        tol_boundary: the previous facet accepts a projection up to this much outside it across an edge of the
            surface's boundary (default ``tol_keep``): a slave resting on the master's free edge stays in contact
            while Newton moves it across by less (else it drops out and comes back, and Newton cycles).
        boxes: facet boxes (lo, hi) if already computed for these positions.
    """
    x = np.ascontiguousarray(x_nodes, dtype=np.float64)
    xs = np.ascontiguousarray(slave_xyz, dtype=np.float64).reshape(-1, 3)
    ns, nf = xs.shape[0], surface.n_facets
    if cand_ptr.shape[0] != ns + 1:
        raise ValueError("cand_ptr must have ns + 1 entries")
    pf = np.full(ns, -1, np.int64) if prev_facet is None else np.ascontiguousarray(prev_facet, np.int64)
    pxi = np.zeros((ns, 2)) if prev_xi is None else np.ascontiguousarray(prev_xi, np.float64).reshape(ns, 2)
    if pf.shape != (ns,) or (ns and (pf.max() >= nf or pf.min() < -1)):
        raise ValueError("prev_facet must be (ns,) with values in [-1, n_facets)")
    if gmax is None:
        gm = 0.5 * facet_sizes(x, surface.faces)
    else:
        # (a copy: a broadcast view of one facet is contiguous but read-only, a kernel signature of its own that
        # numba would compile again, 30 s)
        gm = np.array(np.broadcast_to(np.asarray(gmax, np.float64), (nf,)))
    lo, hi = facet_boxes(x, surface.faces) if boxes is None else boxes
    out = ProjectionResult(
        facet=np.empty(ns, np.int64),
        xi=np.empty((ns, 2)),
        g=np.empty(ns),
        kind=np.empty(ns, np.int8),
        normal=np.empty((ns, 3)),
    )
    if ns == 0:
        return out
    nchunk = min(ns, 16 * numba.get_num_threads())
    topo = (
        surface.faces,
        surface.nbr_facet,
        surface.nbr_edge,
        surface.node_on_boundary,
        surface.node_ptr,
        surface.node_facets,
    )
    keep = float(tol_inside if tol_keep is None else tol_keep)
    prm = (gm, float(tol_inside), float(hysteresis), float(min_cos), int(max_hops), keep,
           keep if tol_boundary is None else float(tol_boundary))
    cp = np.ascontiguousarray(cand_ptr, np.int64)
    cf = np.ascontiguousarray(cand_facets, np.int64)
    lo, hi = np.ascontiguousarray(lo), np.ascontiguousarray(hi)
    order = visit_order(pf, cp, cf, nf)
    o = ProjectionResult(facet=np.empty(ns, np.int64), xi=np.empty((ns, 2)), g=np.empty(ns),
                         kind=np.empty(ns, np.int8), normal=np.empty((ns, 3)))  # fmt: skip
    xs_o, pf_o, pxi_o, cp, cf = _gather_in_order(order, xs, pf, pxi, cp, cf)
    project_slaves_kernel(xs_o, x, topo, lo, hi, cp, cf, pf_o, pxi_o, prm, nchunk, o.facet, o.xi, o.g, o.kind, o.normal)
    _scatter_from_order(order, o.facet, o.xi, o.g, o.kind, o.normal, out.facet, out.xi, out.g, out.kind, out.normal)
    return out


def closest_points(
    x_nodes: np.ndarray, surface: MeshSurface, slave_xyz: np.ndarray, margin: float, **kw
) -> ProjectionResult:
    """Search and projection in one call (``kw`` go to :func:`project_slaves`)."""
    ptr, fac = candidates(x_nodes, surface, slave_xyz, margin)
    return project_slaves(x_nodes, surface, slave_xyz, ptr, fac, **kw)
