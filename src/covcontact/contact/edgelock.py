"""Slaves held on a master edge in a valley (docs/theory.md section 4, "Edge locks").

Where two master facets meet at a valley (each facet's outward normal leans towards the other one, as when a
slave node pushes a master edge down), a penetrating slave near the edge is pushed towards the edge from both
sides: by the normal of facet A on A's side, by that of facet B on B's side. Its equilibrium lies in the thin
wedge below the edge, of width about |g| times the kink angle, where the closest point of the surface is the
edge itself and the force turns continuously from one normal to the other (the edge point of
:mod:`.driver`). A Newton correction computed on one facet's side jumps over that wedge to the other side and
back; the iteration cycles between two states with the same residual.

The lock: a penetrating slave of a frictionless pass whose contact facet changed between two Newton
iterates to the neighbour across a valley edge and then back again (or to a facet that shares only a corner with the previous
one, at a pit), with both contact points within ``BAND`` (element coordinates) of that edge or corner, is
held there: its contact point is the closest point of that edge curve (or the corner node), its gap the
distance with the sign of the averaged normal, and its element the edge or vertex element of :mod:`.edge`
(exact tangent). Newton then converges into the wedge. At a converged state every lock is
checked against the free projection (:func:`inconsistent`, facet bounds without tolerance); where they differ (the slave came to rest on a
facet, not in the wedge) the lock is released for the rest of the step and Newton goes on from there. So a
converged state with locks is also a solution of the free contact problem.

A lock is kept from step to step (a slave in a valley stays there); released and pending ones are free
again at the start of the next step.
"""

from __future__ import annotations

import numpy as np

from ..fem.shapes import shape_functions
from .driver import EDGE, FACET, VERTEX
from .surface import EDGE_DIR, EDGE_START, edge_closest_point, facet_frame

#: largest distance (element coordinates) of both contact points from the shared edge for a lock
BAND = 0.02
#: relative difference of the gap vectors g n below which a locked contact point and the free projection agree
AGREE = 1e-7

FREE = -1
RELEASED = -2
#: PENDING - f: the slave crossed a valley edge or corner, leaving facet f, at the last iterate
PENDING = -3


def _edge_xi(e: int, t: float) -> np.ndarray:
    return np.array([EDGE_START[e, 0] + (t + 1.0) * EDGE_DIR[e, 0], EDGE_START[e, 1] + (t + 1.0) * EDGE_DIR[e, 1]])


def _across(surface, f: int, e: int, t: float) -> tuple[int, int, float]:
    """The neighbour of facet f across its local edge e, that edge's number on the neighbour and the parameter
    there of the point t of edge e (the edges of consistently oriented facets run in opposite directions); the
    neighbour is -1 at a boundary edge."""
    nb = int(surface.nbr_facet[f, e])
    if nb < 0:
        return nb, -1, t
    ne = int(surface.nbr_edge[f, e])
    return nb, ne, -t if surface.faces[nb, ne] == surface.faces[f, (e + 1) % 4] else t


def _off_edge(xi: np.ndarray, e: int) -> float:
    """Distance in element coordinates of xi from the line of local edge e (xi1 = +-1 for e = 1, 3; xi2 = -+1 for
    e = 0, 2)."""
    return abs(xi[0] - (1.0 if e == 1 else -1.0)) if e % 2 == 1 else abs(xi[1] - (1.0 if e == 2 else -1.0))


def _normal(xyz: np.ndarray, xi: np.ndarray) -> np.ndarray:
    rho, t1, t2, n = np.empty(3), np.empty(3), np.empty(3), np.empty(3)
    facet_frame(xyz, float(xi[0]), float(xi[1]), rho, t1, t2, n)
    return n


def _centre(xyz: np.ndarray, cell: str) -> np.ndarray:
    N = shape_functions(cell, np.zeros((1, 2)))[0][0]
    return N @ xyz


def _corner_normals(surface, x: np.ndarray, v: int) -> np.ndarray:
    """Sum of the unit normals at node v of the facets around it."""
    nsum = np.zeros(3)
    faces = surface.faces
    for m in range(surface.node_ptr[v], surface.node_ptr[v + 1]):
        f = int(surface.node_facets[m])
        a = int(np.flatnonzero(faces[f, :4] == v)[0])
        nsum += _normal(np.ascontiguousarray(x[faces[f]]), EDGE_START[a])
    return nsum


def edge_point(surface, x: np.ndarray, code: int, xs: np.ndarray) -> tuple[int, np.ndarray, float, np.ndarray, int]:
    """Contact point of slave position xs held by lock ``code`` (8 facet + e on local edge e, 8 facet + 4 + a
    on corner a): (facet, xi on its boundary, signed gap, unit normal, kind 2 edge / 3 vertex). The sign is that
    of the averaged normal of the facets at the point."""
    f, k = divmod(int(code), 8)
    faces = surface.faces
    xyz = np.ascontiguousarray(x[faces[f]])
    xs = np.ascontiguousarray(xs, dtype=np.float64)
    if k >= 4:
        a = k - 4
        c = xyz[a].copy()
        xi = EDGE_START[a].copy()
        nsum = _corner_normals(surface, x, int(faces[f, a]))
        t = 1.0
    else:
        e = k
        c = np.empty(3)
        t, _ = edge_closest_point(xyz, e, xs, c)
        xi = _edge_xi(e, t)
        nsum = _normal(xyz, xi)
        nb, ne, tn = _across(surface, f, e, t)
        if nb >= 0:
            nsum = nsum + _normal(np.ascontiguousarray(x[faces[nb]]), _edge_xi(ne, tn))
    d = xs - c
    dist = float(np.linalg.norm(d))
    sign = 1.0 if float(d @ nsum) >= 0.0 else -1.0
    n = sign * d / dist if dist > 0.0 else nsum / max(float(np.linalg.norm(nsum)), 1e-300)
    kind = VERTEX if abs(t) >= 1.0 - 1e-12 else EDGE
    return f, xi, sign * dist, n, kind


def _valley(xa, xb, na, nb, c, cell) -> bool:
    """Each facet rises above the other one's tangent plane at the common point c."""
    return float((_centre(xb, cell) - c) @ na) > 0.0 and float((_centre(xa, cell) - c) @ nb) > 0.0


def new_locks(surface, x: np.ndarray, xs: np.ndarray, lock: np.ndarray, facet: np.ndarray, xi: np.ndarray,
              gap: np.ndarray, kind: np.ndarray, prev_facet: np.ndarray, prev_xi: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray]:
    """New lock values (slave indices and values) of the free or pending, penetrating slaves on a facet that
    shares a valley edge or corner with the facet they had at the previous iterate, both contact points
    within BAND of it: a lock where the slave crossed back to the facet it left at its last crossing (the
    cycle), else a pending mark (a slave that crosses once and stays on its new facet is never held)."""
    cand = np.flatnonzero(((lock == FREE) | (lock <= PENDING)) & (kind == FACET) & (prev_facet >= 0) & (facet >= 0)
                          & (facet != prev_facet) & (gap < 0.0))
    idx, codes = [], []

    def cross(s, code):
        idx.append(s)  # locked when the slave comes back to the facet it left at its last crossing
        codes.append(code if lock[s] == PENDING - int(facet[s]) else PENDING - int(prev_facet[s]))

    faces = surface.faces
    cell = surface.cell_type
    for s in cand:
        fa, fb = int(prev_facet[s]), int(facet[s])
        xa = np.ascontiguousarray(x[faces[fa]])
        xb = np.ascontiguousarray(x[faces[fb]])
        hit = np.flatnonzero(surface.nbr_facet[fa] == fb)
        if hit.size == 1:  # across an edge
            e = int(hit[0])
            c = np.empty(3)
            t, _ = edge_closest_point(xa, e, np.ascontiguousarray(xs[s], dtype=np.float64), c)
            _, eb, tb = _across(surface, fa, e, t)
            if _off_edge(prev_xi[s], e) > BAND or _off_edge(xi[s], eb) > BAND:
                continue
            if _valley(xa, xb, _normal(xa, _edge_xi(e, t)), _normal(xb, _edge_xi(eb, tb)), c, cell):
                cross(s, 8 * fa + e)
            continue
        common = np.intersect1d(faces[fa, :4], faces[fb, :4])
        if common.size != 1:
            continue
        a = int(np.flatnonzero(faces[fa, :4] == common[0])[0])  # across a corner
        b = int(np.flatnonzero(faces[fb, :4] == common[0])[0])
        if np.abs(prev_xi[s] - EDGE_START[a]).max() > BAND or np.abs(xi[s] - EDGE_START[b]).max() > BAND:
            continue
        if _valley(xa, xb, _normal(xa, EDGE_START[a]), _normal(xb, EDGE_START[b]), xa[a], cell):
            cross(s, 8 * fa + 4 + a)
    return np.asarray(idx, dtype=np.int64), np.asarray(codes, dtype=np.int64)


def inconsistent(lock: np.ndarray, gap: np.ndarray, normal: np.ndarray, free_kind: np.ndarray,
                 free_gap: np.ndarray, free_normal: np.ndarray) -> np.ndarray:
    """Locked slaves whose free projection at the same positions (with no tolerance on the facet bounds) is a
    facet point whose gap vector g n differs from the locked one by more than AGREE |g|: the slave rests on a
    facet, not in the wedge of its edge."""
    diff = np.linalg.norm(free_gap[:, None] * free_normal - gap[:, None] * normal, axis=1) if len(gap) else gap
    return np.flatnonzero((lock >= 0) & (free_kind == FACET) & ~(diff <= AGREE * np.abs(gap)))
