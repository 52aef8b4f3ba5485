"""Segment-to-surface contact on nodal weighted gaps (``gap = "nodal"``, docs/theory.md section 16).

The Gauss points of the slave facets measure the gap as in ordinary segment-to-surface contact, but the normal law
acts on one weighted gap per slave node, g~_a = sum_g c_ag g_g with c_ag = w_ag / A_a, A_a = sum_g w_ag, over the
points g of the facets around node a that have a contact point. The weights w_ag = psi_a(xi_g) w_g J_g take the dual
shape functions of the mortar methods, biorthogonal to the N_b under each facet's rule, so that A_a is the node's
tributary area and against a flat master g~_a is the node's own gap; where a facet has no dual basis (tri6 and quad8
corners, one point per facet) psi_a is a positive partition of unity instead (N_a on linear facets,
N_a^2 / sum_b N_b^2 on quadratic ones). The energy is
W = sum_a Phi_a(g~_a) with the pair's law per node (penalty eps_N A_a, smoothed or not): one constraint per slave node,
as node-to-surface has, where the points alone over-constrain conforming faces (their active set cycles on flat
contact). With the node's force F_a = -Phi_a' >= 0 and stiffness S_a = Phi_a'':

- residual: R = -sum_g p_g grad g_g, the point force p_g = sum_a c_ag F_a (the nodal pressures interpolated);
- tangent: K = sum_a S_a grad g~_a (x) grad g~_a + sum_g (-p_g) Hess g_g, grad g~_a = sum_g c_ag grad g_g.

The second sum is each point's rotational, curvature and second-order parts at the force p_g, from the same kernels
as a point of its own (their terms are linear in the law's force and slope: a law of slope E and unit force gives
grad g_g and them per unit force plus E grad g_g (x) grad g_g, which is removed); the first couples every point of a
node's facets, one block per active node over the nodes of those facets and of their points' masters.
"""

from __future__ import annotations

import numpy as np

from .driver import FACET, VERTEX
from .edge import edge_vertex_batch
from .kernels import contact_batch
from .laws import is_active, linear_equivalents


def node_weights(points, ids: np.ndarray, area: np.ndarray, facet: np.ndarray | None = None):
    """(conn (m, nen) facet nodes, N (m, nen) shape values, w (m, nen) the weights w_ag) of slave points ``ids``
    (``facet``: each point's slave facet, for the dual weights)."""
    j = np.asarray(ids, dtype=np.int64) - points.offset
    nen = int(points.nen[j[0]])
    N = points.N[j, :nen]
    conn = points.conn[j, :nen]
    if facet is not None and nen in (3, 4, 9):
        psi = dual_shapes(N, area, facet)
        if psi is not None:
            return conn, N, psi * area[:, None]
    phi = N if nen in (3, 4) else N * N / (N * N).sum(axis=1, keepdims=True)
    return conn, N, phi * area[:, None]


def dual_shapes(N: np.ndarray, w: np.ndarray, facet: np.ndarray) -> np.ndarray | None:
    """The dual shape functions of each slave facet at its points, psi_a = sum_c (D M^-1)_ac N_c with
    M_ab = sum_g N_a N_b w_g and D_ab = delta_ab sum_g N_a w_g over the facet's points, so that
    sum_g psi_a N_b w_g = delta_ab D_a (biorthogonal under the facet's rule). None where a facet's M is singular (one
    point per facet) or a D_a is not positive."""
    nf = int(facet.max()) + 1
    nen = N.shape[1]
    M = np.zeros((nf, nen, nen))
    np.add.at(M, facet, w[:, None, None] * N[:, :, None] * N[:, None, :])
    D = np.zeros((nf, nen))
    np.add.at(D, facet, w[:, None] * N)
    if np.any(D <= 0.0):
        return None
    try:
        A = D[:, :, None] * np.linalg.inv(M)
    except np.linalg.LinAlgError:
        return None
    if not np.all(np.isfinite(A)) or np.linalg.cond(M).max() > 1e12:
        return None
    return np.einsum("gac,gc->ga", A[facet], N)


def _static(p, points):
    """The pass's weights and slave nodes (fixed by the reference configuration), worked out at its first evaluation."""
    cached = getattr(p, "_nodal_static", None)
    if cached is None:
        conn, N, w = node_weights(points, p.slaves, p.area, p.slave_facet)
        nodes, inv = np.unique(conn, return_inverse=True)
        cached = (conn, N, w, nodes, inv.reshape(conn.shape))
        p._nodal_static = cached
    return cached


def nodal_forces(p, points, g: np.ndarray, ok: np.ndarray):
    """The nodal law of pass ``p`` at the points' gaps ``g`` (``ok``: the points with a contact point).

    Returns (conn, N, c, inv, S, pg): each point's facet nodes and shape values, c (m, nen) the coefficients c_ag
    (zero where the point has no contact point), each (point, node)'s index among the slave nodes, per node the
    stiffness S_a (zero where inactive), and the point forces p_g = sum_a c_ag F_a."""
    conn, N, w, nodes, inv = _static(p, points)
    w = np.where(ok[:, None], w, 0.0)
    A = np.bincount(inv.ravel(), w.ravel(), minlength=len(nodes))
    gz = np.where(ok, g, 0.0)
    has = A > 0.0
    A_safe = np.where(has, A, 1.0)
    gt = np.bincount(inv.ravel(), (w * gz[:, None]).ravel(), minlength=len(nodes)) / A_safe
    eps_a = np.bincount(inv.ravel(), (w * (p.eps / p.area)[:, None]).ravel(), minlength=len(nodes))
    F = np.zeros(len(nodes))
    S = np.zeros(len(nodes))
    act = np.flatnonzero(has & is_active(np.where(has, gt, np.inf), np.zeros(len(nodes)), np.where(has, eps_a, 1.0),
                                         p.band))
    if act.size:
        e_s, l_s = linear_equivalents(gt[act], np.zeros(act.size), eps_a[act], p.band)
        F[act] = -(l_s + e_s * gt[act])
        S[act] = e_s
    c = w / A_safe[inv]
    pg = (c * F[inv]).sum(axis=1)
    return conn, N, c, inv, S, pg


def _unit(g: np.ndarray, area: np.ndarray):
    """A law of unit force at gap g for the point kernels, whose results are linear in the force: slope
    E = 1 / (|g| + sqrt(area)) and multiplier lam = -1 - E g (<= 0, active: lam + E g = -1). The residual is then
    -grad g, the tangent E grad g (x) grad g - Hess g."""
    E = 1.0 / (np.abs(g) + np.sqrt(area))
    return E, -1.0 - E * g


#: entries of a node's gradient below this fraction of its largest are round-off of cancelling terms (main_blocks)
ROUND_OFF = 1e-12


def main_blocks(inv, c, S, conn, N, pts, ids, grads):
    """The blocks S_a grad g~_a (x) grad g~_a of the active nodes: ``pts`` the points with a force, ``ids`` (k, q) the
    ids their gradient ``grads`` (k, 3 q) acts on (the point's own id last), each expanded onto its facet's nodes."""
    if not len(pts):
        return []
    q = ids.shape[1]
    nen = conn.shape[1]
    k, b = np.nonzero((S[inv[pts]] > 0.0) & (c[pts] != 0.0))  # (point, node of its facet) with an active node
    if not k.size:
        return []
    g = pts[k]
    cab = c[g, b]
    a = inv[g, b]
    master = grads[k, :3 * (q - 1)].reshape(len(k), q - 1, 3) * cab[:, None, None]  # (m, q - 1, 3)
    slave = (cab[:, None, None] * N[g][:, :, None]) * grads[k, None, 3 * (q - 1):]   # (m, nen, 3)
    a_all = np.concatenate([np.repeat(a, q - 1), np.repeat(a, nen)])
    id_all = np.concatenate([ids[k, :q - 1].ravel(), conn[g].ravel()])
    v_all = np.concatenate([master.reshape(-1, 3), slave.reshape(-1, 3)])
    order = np.lexsort((id_all, a_all))
    a_all, id_all, v_all = a_all[order], id_all[order], v_all[order]
    key = np.flatnonzero(np.r_[True, (np.diff(a_all) != 0) | (np.diff(id_all) != 0)])
    a_u, id_u = a_all[key], id_all[key]
    v_u = np.add.reduceat(v_all, key, axis=0)
    # entries that cancel to round-off dropped: the dual weights make a node's slave entries delta_ab (against a flat
    # master grad g~_a is the node's own normal alone, the others sum to 1e-16 of it)
    size = np.abs(v_u).max(axis=1)
    first = np.flatnonzero(np.r_[True, np.diff(a_u) != 0])
    peak = np.maximum.reduceat(size, first)[np.cumsum(np.r_[True, np.diff(a_u) != 0]) - 1]
    keep = size > ROUND_OFF * peak
    a_u, id_u, v_u = a_u[keep], id_u[keep], v_u[keep]
    starts = np.flatnonzero(np.r_[True, np.diff(a_u) != 0])
    sizes = np.diff(np.r_[starts, len(a_u)])
    out = []
    for n in np.unique(sizes):  # the nodes whose blocks have n entries, at once
        first = starts[sizes == n]
        idx = first[:, None] + np.arange(n)
        V = v_u[idx].reshape(len(first), 3 * n)
        K = S[a_u[first]][:, None, None] * V[:, :, None] * V[:, None, :]
        out.append((id_u[idx], np.zeros((len(first), 3 * n)), K))
    return out


def mesh_pass(mgr, p, xe, res, case, t, want_K, want_parts, ev) -> None:
    """A nodal-gap pass against a meshed master (the projection ``res`` of every point done)."""
    ok = res.kind != 0
    conn, N, c, inv, S, pg = nodal_forces(p, mgr.points, res.g, ok)
    pts = np.flatnonzero(ok & ((S[inv] > 0.0) & (c != 0.0)).any(axis=1))  # the points of the active nodes
    if not pts.size:
        return
    nen = p.surface.nen
    nd = 3 * (nen + 1)
    E, lam = _unit(res.g[pts], p.area[pts])
    ids = np.hstack([p.surface.faces[res.facet[pts]], p.slaves[pts][:, None]])
    R = np.zeros((pts.size, nd))
    K = np.zeros((pts.size, nd, nd))
    P = np.zeros((pts.size, 4, nd, nd)) if want_parts else np.zeros((1, 4, 1, 1))
    g = np.zeros(pts.size)
    facet = res.kind[pts] == FACET
    fi = np.flatnonzero(facet)
    if fi.size:
        Rf = np.zeros((fi.size, nd))
        Kf = np.zeros((fi.size, nd, nd))
        Pf = np.zeros((fi.size, 4, nd, nd)) if want_parts else P
        gf = np.zeros(fi.size)
        contact_batch(xe, np.ascontiguousarray(ids[fi, :nen]), np.ascontiguousarray(ids[fi, nen]),
                      np.ascontiguousarray(res.xi[pts[fi]]), np.ascontiguousarray(E[fi]), case, want_parts, Rf, Kf,
                      Pf, gf, np.ascontiguousarray(lam[fi]))
        R[fi], K[fi], g[fi] = Rf, Kf, gf
        if want_parts:
            P[fi] = Pf
    ej = np.flatnonzero(~facet)  # edge and vertex points (their kernel has no parts: all in the main one)
    if ej.size:
        R[ej], K[ej], g[ej] = edge_vertex_batch(xe, ids[ej], res.xi[pts[ej]], res.g[pts[ej]],
                                                res.kind[pts[ej]] == VERTEX, E[ej], lam[ej])
    grads = -R
    f = pg[pts]
    K = f[:, None, None] * (K - E[:, None, None] * grads[:, :, None] * grads[:, None, :])
    R = f[:, None] * R
    if want_parts:
        P *= f[:, None, None, None]
    t.gap[pts] = g
    t.force[pts] = -R[:, -3:]
    mgr._add(ev.blocks, ids, R, K if want_K else None, xe)
    if want_parts:
        zero = np.zeros_like(R)
        for j in range(1, 4):
            ev.parts[j].add(ids[fi], zero[fi], P[fi, j])
        ev.parts[0].add(ids[~facet], zero[~facet], K[~facet])
    for conn_b, Rb, Kb in main_blocks(inv, c, S, conn, N, pts, ids, grads):
        mgr._add(ev.blocks, conn_b, Rb, Kb if want_K else None, xe)
        if want_parts:
            ev.parts[0].add(conn_b, Rb, Kb)


#: the force of the one evaluation of an analytic pass's points (a law of unit slope per sqrt(area) and this
#: multiplier: every point within 1e6 sqrt(area) of the surface is active with a positive force)
_FAR = 1.0e6


def analytic_pass(mgr, p, xe, lam, case_name: str, t, want_K, want_parts, ev) -> None:
    """A nodal-gap pass against an analytic rigid surface (fixed or moved, not a force-controlled tool). One evaluation
    of every point gives its gap and, at the force f0 = _FAR - E g of a law every nearby point is active under, its
    gradient and its other parts per unit force (all linear in the force)."""
    xs = np.ascontiguousarray(xe[p.slaves])
    E_all = 1.0 / np.sqrt(p.area)

    def evaluate(name):
        return p.analytic.evaluate(xs, E_all, parts=name, lam=lam, multiplier=-_FAR)

    out = evaluate(case_name)
    g = out.gap
    t.gap, t.xi = g, out.xi
    ok = np.isfinite(g)
    conn, N, c, inv, S, pg = nodal_forces(p, mgr.points, g, ok)
    t.force = np.zeros((p.ns, 3))
    f0 = _FAR - E_all * np.where(ok, g, 0.0)
    pts = np.flatnonzero(ok & (f0 > 0.0) & ((S[inv] > 0.0) & (c != 0.0)).any(axis=1))  # the points of the active nodes
    if not pts.size:
        return
    E, scale = E_all[pts], pg[pts] / f0[pts]
    grads = -out.residual[pts] / f0[pts][:, None]
    R = -pg[pts][:, None] * grads
    K = scale[:, None, None] * (out.tangent[pts] - E[:, None, None] * grads[:, :, None] * grads[:, None, :])
    ids = p.slaves[pts][:, None]
    t.force[pts] = -R
    ev.blocks.add(ids, R, K if want_K else None)
    if want_parts:
        d, cc, ex = (scale[:, None, None] * evaluate(name).tangent[pts] for name in ("d", "c", "exact"))
        zero = np.zeros_like(R)
        ev.parts[2].add(ids, zero, cc - d)
        ev.parts[3].add(ids, zero, ex - cc)
    for conn_b, Rb, Kb in main_blocks(inv, c, S, conn, N, pts, ids, grads):
        ev.blocks.add(conn_b, Rb, Kb if want_K else None)
        if want_parts:
            ev.parts[0].add(conn_b, Rb, Kb)
