"""Tangent-continuous 2D tool profiles of straight segments and circular arcs (docs/theory.md section 5).

A profile is given as a polyline ``points`` (p, q) in its own plane (p to the right, q up, as drawn) with a
fillet radius per interior corner. Each corner with a radius r > 0 becomes an arc of radius r tangent to
both legs; a sharp corner (0) becomes an arc of radius ``SHARP`` times the profile's length, so that the
normal field is continuous everywhere (a sharp convex corner acts as the vertex it is, with its exact
stiffness). The first and the last segment extend without end. The contact side is on the left when one
walks along the points (the tool's material on the right); arc length s along the profile is the first
surface coordinate.

Compiled form: one row of ``PROFILE_COLS`` floats per segment,
    [0] type (LINE, ARC)  [1] s0 (arc length at the segment's start)  [2] L (length)
    [3:5] start point (line) or centre (arc)  [5:7] unit direction (line)
    [7] radius, [8] start angle, [9] turn sign (+1 counter-clockwise), [5] 1 for a sharp corner (arc)
    [10], [11] range of the local parameter t = s - s0 ([0, L]; -inf / +inf at the open ends)
"""

from __future__ import annotations

import numpy as np
from numba import njit

LINE = 0.0
ARC = 1.0
PROFILE_COLS = 12
SHARP = 1.0e-9  # radius of a sharp corner, relative to the profile's length
JOIN_TOL = 1.0e-9  # relative: two consecutive points closer than this are one point


def build_profile(points, fillets=None, axis_ends=False) -> np.ndarray:
    """Segment table (nseg, PROFILE_COLS) of the profile through ``points`` (m, 2) with ``fillets`` (m - 2,).

    axis_ends: the profile is revolved about p = 0; an end on the axis does not extend beyond it.

    ValueError naming ``points`` or ``fillets`` when fewer than 2 points are given, two consecutive points
    coincide, the profile turns back on itself, or a fillet does not fit between its neighbours.
    """
    P = np.asarray(points, dtype=np.float64)
    if P.ndim != 2 or P.shape[1] != 2 or len(P) < 2 or not np.all(np.isfinite(P)):
        raise ValueError(f"points: expected at least 2 finite (p, q) pairs, got {np.asarray(points).tolist()!r}")
    m = len(P)
    r = np.zeros(m - 2) if fillets is None else np.asarray(fillets, dtype=np.float64).ravel()
    if r.shape != (m - 2,) or not np.all(np.isfinite(r)) or np.any(r < 0.0):
        raise ValueError(f"fillets: expected {m - 2} radii >= 0 (one per interior corner, 0 for a sharp one), "
                         f"got {np.asarray(fillets).tolist()!r}")
    legs = np.diff(P, axis=0)
    lens = np.linalg.norm(legs, axis=1)
    total = float(lens.sum())
    if np.any(lens <= JOIN_TOL * max(total, 1e-300)):
        k = int(np.argmin(lens))
        raise ValueError(f"points: points {k + 1} and {k + 2} coincide")
    d = legs / lens[:, None]
    sharp = r == 0.0
    r = np.where(sharp, SHARP * total, r)
    # tangent length of each corner's arc
    tl = np.zeros(m)
    turn = np.zeros(m)
    for k in range(1, m - 1):
        a, b = d[k - 1], d[k]
        cross = a[0] * b[1] - a[1] * b[0]
        ang = float(np.arctan2(cross, float(a @ b)))
        if abs(ang) > np.pi - 1e-6:
            raise ValueError(f"points: the profile turns back on itself at point {k + 1}")
        turn[k] = ang
        tl[k] = r[k - 1] * np.tan(0.5 * abs(ang))
    for k in range(m - 1):
        if tl[k] + tl[k + 1] > lens[k] * (1.0 + 1e-12):
            raise ValueError(f"fillets: the fillets at the ends of segment {k + 1} (points {k + 1}-{k + 2}, "
                             f"length {lens[k]:g}) need {tl[k] + tl[k + 1]:g} of it; reduce the radii")
    rows = []
    s = 0.0
    for k in range(m - 1):
        a = P[k] + d[k] * tl[k]
        b = P[k + 1] - d[k] * tl[k + 1]
        L = float(np.linalg.norm(b - a))
        row = np.zeros(PROFILE_COLS)
        row[:3] = (LINE, s, L)
        row[3:5] = a
        row[5:7] = d[k]
        open_start = k == 0 and not (axis_ends and P[0, 0] == 0.0)
        open_end = k == m - 2 and not (axis_ends and P[-1, 0] == 0.0)
        row[10:12] = (-np.inf if open_start else 0.0, np.inf if open_end else L)
        if L > JOIN_TOL * total or open_start or open_end:  # a leg the fillets use up leaves no line
            rows.append(row)
        s += L
        if k < m - 2 and turn[k + 1] != 0.0:
            rad = r[k]
            sg = 1.0 if turn[k + 1] > 0.0 else -1.0
            left = np.array([-d[k][1], d[k][0]])
            c = b + sg * rad * left
            arc = np.zeros(PROFILE_COLS)
            La = rad * abs(turn[k + 1])
            arc[:3] = (ARC, s, La)
            arc[3:5] = c
            arc[5] = 1.0 if sharp[k] else 0.0
            arc[7] = rad
            arc[8] = np.arctan2(b[1] - c[1], b[0] - c[0])
            arc[9] = sg
            arc[10:12] = (0.0, La)
            rows.append(arc)
            s += La
    return np.ascontiguousarray(np.vstack(rows))


@njit(cache=True)
def profile_point(prof, k, t):
    """Segment k at local t: point, tangent, second and third derivative by arc length (8 scalars)."""
    if prof[k, 0] == LINE:
        return (prof[k, 3] + t * prof[k, 5], prof[k, 4] + t * prof[k, 6], prof[k, 5], prof[k, 6],
                0.0, 0.0, 0.0, 0.0)
    R = prof[k, 7]
    sg = prof[k, 9]
    phi = prof[k, 8] + sg * t / R
    c = np.cos(phi)
    s = np.sin(phi)
    return (prof[k, 3] + R * c, prof[k, 4] + R * s, -sg * s, sg * c, -c / R, -s / R, sg * s / (R * R),
            -sg * c / (R * R))


@njit(cache=True)
def profile_derivative(prof, s, na):
    """d^na C / ds^na (2 scalars) at arc length s, na = 0..3."""
    k, t = profile_segment(prof, s)
    v = profile_point(prof, k, t)
    return v[2 * na], v[2 * na + 1]


@njit(cache=True)
def profile_closest(prof, p, q):
    """Closest point of (p, q) on the profile: returns (segment k, local t, squared distance)."""
    best = np.inf
    kb = 0
    tb = 0.0
    for k in range(prof.shape[0]):
        if prof[k, 0] == LINE:
            t = (p - prof[k, 3]) * prof[k, 5] + (q - prof[k, 4]) * prof[k, 6]
        else:
            R = prof[k, 7]
            sg = prof[k, 9]
            ang = np.arctan2(q - prof[k, 4], p - prof[k, 3])
            # angle from the start in the turning direction, in (-pi, pi] around the arc's middle
            mid = 0.5 * prof[k, 2] / R
            da = sg * (ang - prof[k, 8]) - mid
            da = da - 2.0 * np.pi * np.round(da / (2.0 * np.pi))
            t = (da + mid) * R
        t = min(max(t, prof[k, 10]), prof[k, 11])
        if prof[k, 0] == LINE:
            x = prof[k, 3] + t * prof[k, 5]
            y = prof[k, 4] + t * prof[k, 6]
        else:
            phi = prof[k, 8] + prof[k, 9] * t / prof[k, 7]
            x = prof[k, 3] + prof[k, 7] * np.cos(phi)
            y = prof[k, 4] + prof[k, 7] * np.sin(phi)
        d2 = (p - x) * (p - x) + (q - y) * (q - y)
        if d2 < best:
            best = d2
            kb = k
            tb = t
    return kb, tb, best


@njit(cache=True)
def profile_segment(prof, s):
    """The segment holding arc length s and the local parameter there (ends extend the end segments)."""
    n = prof.shape[0]
    for k in range(n - 1):
        if s < prof[k + 1, 1]:
            return k, s - prof[k, 1]
    return n - 1, s - prof[n - 1, 1]
