"""Rigid analytic master surfaces: plane, cylinder, sphere (docs/theory.md sections 3-5).

Each surface is placed by an origin and a right-handed orthonormal frame (rows e1, e2, e3), moved by
a ``RigidMotion`` with load factor lam. Parameterisations (sigma = +1 for ``outside=True``, the body
being the solid inside the surface; sigma = -1 for a hollow one touched from inside):

- plane:    rho = o + xi1 e1 + xi2 e2, n = e3, h = 0.
- cylinder: rho = o + R e_r(phi) + sigma s e3, xi = (phi, s), n = sigma e_r,
            a = diag(R^2, 1), h_11 = -sigma R.
- sphere:   rho = o + R e_r(theta, phi), xi = (theta, sigma phi) in one of three charts whose polar
            axis is the frame axis most nearly perpendicular to the point (so sin theta >= sqrt(2/3),
            far from the poles); n = sigma e_r, a = diag(R^2, R^2 sin^2), h = -sigma a / R.

A rigid master has no dofs: the element acts on the slave node only (3 x 3). With the effective gap
g_e = g + lam_k / eps (lam_k <= 0 the Uzawa multiplier, 0 for pure penalty; active when g_e <= 0):
residual eps g_e n, tangent parts main eps H n(x)n, curvature -eps H g_e h^ij rho_i(x)rho_j,
rotational zero, and exact eps H (n(x)n + g_e/g (a^ij - c^ij) rho_i(x)rho_j), the exact Hessian of
eps/2 <g_e>^2 = 1/(2 eps) <lam_k + eps g>^2 (c_ij = a_ij - g h_ij with the geometric g).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numba import njit, prange

from covcontact.contact.element import (
    CASE_A,
    CASE_C,
    CASE_EXACT,
    PART_NAMES,
    ContactResult,
    _mat2_prod3,
    check_inputs,
    check_multiplier,
)
from covcontact.contact.laws import c_inverse, effective_gap, is_active, linear_equivalent
from covcontact.contact.profile import PROFILE_COLS, profile_closest, profile_point
from covcontact.motion import RigidMotion, frame_from_axis, unit_vector

PLANE = 0
CYLINDER = 1
SPHERE = 2
EXTRUDED = 3
REVOLVED = 4
SHARP_CORNER = 3  # the chart reported at the sharp corner of a profile (a vertex: cases a, c use exact)
NO_PROFILE = np.zeros((0, PROFILE_COLS))

_CHUNK = 32


@njit(cache=True, inline="always")
def _axial(d0, d1, d2, frame):
    """Cylindrical coordinates (z, r, phi) of the offset d from the origin about the frame's third axis."""
    z = d0 * frame[2, 0] + d1 * frame[2, 1] + d2 * frame[2, 2]
    x1 = d0 * frame[0, 0] + d1 * frame[0, 1] + d2 * frame[0, 2]
    x2 = d0 * frame[1, 0] + d1 * frame[1, 1] + d2 * frame[1, 2]
    r = np.sqrt(x1 * x1 + x2 * x2)
    return z, r, (np.arctan2(x2, x1) if r > 0.0 else 0.0)


@njit(cache=True)
def analytic_geometry(kind, origin, frame, radius, sigma, prof, xs, xi, rho, rho_cov, a_cov, a_con, n, h_cov):
    """Closed-form projection of ``xs`` and the surface quantities there; returns (g, chart).

    prof: the segment table of a profile (``profile.build_profile``; empty for the other kinds)."""
    d0 = xs[0] - origin[0]
    d1 = xs[1] - origin[1]
    d2 = xs[2] - origin[2]
    for i in range(2):
        for j in range(2):
            h_cov[i, j] = 0.0
            a_cov[i, j] = 0.0
    chart = 0
    if kind == PLANE:
        xi[0] = d0 * frame[0, 0] + d1 * frame[0, 1] + d2 * frame[0, 2]
        xi[1] = d0 * frame[1, 0] + d1 * frame[1, 1] + d2 * frame[1, 2]
        g = d0 * frame[2, 0] + d1 * frame[2, 1] + d2 * frame[2, 2]
        for p in range(3):
            rho[p] = origin[p] + xi[0] * frame[0, p] + xi[1] * frame[1, p]
            rho_cov[0, p] = frame[0, p]
            rho_cov[1, p] = frame[1, p]
            n[p] = frame[2, p]
        a_cov[0, 0] = 1.0
        a_cov[1, 1] = 1.0
    elif kind == CYLINDER:
        z, r, phi = _axial(d0, d1, d2, frame)
        cp = np.cos(phi)
        sp = np.sin(phi)
        xi[0] = phi
        xi[1] = sigma * z
        g = sigma * (r - radius)
        for p in range(3):
            er = cp * frame[0, p] + sp * frame[1, p]
            ephi = -sp * frame[0, p] + cp * frame[1, p]
            rho[p] = origin[p] + radius * er + z * frame[2, p]
            rho_cov[0, p] = radius * ephi
            rho_cov[1, p] = sigma * frame[2, p]
            n[p] = sigma * er
        a_cov[0, 0] = radius * radius
        a_cov[1, 1] = 1.0
        h_cov[0, 0] = -sigma * radius
    elif kind == EXTRUDED:
        pp = d0 * frame[0, 0] + d1 * frame[0, 1] + d2 * frame[0, 2]
        qq = d0 * frame[1, 0] + d1 * frame[1, 1] + d2 * frame[1, 2]
        z = d0 * frame[2, 0] + d1 * frame[2, 1] + d2 * frame[2, 2]
        k, t, _ = profile_closest(prof, pp, qq)
        cx, cy, tx, ty, c2x, c2y, _, _ = profile_point(prof, k, t)
        xi[0] = prof[k, 1] + t
        xi[1] = -z
        g = -(pp - cx) * ty + (qq - cy) * tx
        for p in range(3):
            rho[p] = origin[p] + cx * frame[0, p] + cy * frame[1, p] + z * frame[2, p]
            rho_cov[0, p] = tx * frame[0, p] + ty * frame[1, p]
            rho_cov[1, p] = -frame[2, p]
            n[p] = -ty * frame[0, p] + tx * frame[1, p]
        a_cov[0, 0] = 1.0
        a_cov[1, 1] = 1.0
        h_cov[0, 0] = -c2x * ty + c2y * tx
        if prof[k, 0] == 1.0 and prof[k, 5] == 1.0:
            chart = SHARP_CORNER
    elif kind == REVOLVED:
        z, r, phi = _axial(d0, d1, d2, frame)
        cp = np.cos(phi)
        sp = np.sin(phi)
        k, t, _ = profile_closest(prof, r, z)
        cr, cz, tr, tz, c2r, c2z, _, _ = profile_point(prof, k, t)
        xi[0] = prof[k, 1] + t
        xi[1] = phi
        g = -(r - cr) * tz + (z - cz) * tr
        h_cov[0, 0] = -c2r * tz + c2z * tr
        pole = abs(cr) <= 1e-9 * (prof[prof.shape[0] - 1, 1] + prof[prof.shape[0] - 1, 2])
        for p in range(3):
            er = cp * frame[0, p] + sp * frame[1, p]
            ephi = -sp * frame[0, p] + cp * frame[1, p]
            rho[p] = origin[p] + cr * er + cz * frame[2, p]
            rho_cov[0, p] = tr * er + tz * frame[2, p]
            rho_cov[1, p] = ephi if pole else cr * ephi
            n[p] = -tz * er + tr * frame[2, p]
        a_cov[0, 0] = 1.0
        if prof[k, 0] == 1.0 and prof[k, 5] == 1.0:
            chart = SHARP_CORNER
        if pole:  # on the axis the surface is umbilic: unit e_phi, the meridian's curvature
            a_cov[1, 1] = 1.0
            h_cov[1, 1] = h_cov[0, 0]
            chart = 1
        else:
            a_cov[1, 1] = cr * cr
            h_cov[1, 1] = cr * tz
    else:
        r = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if r > 0.0:
            w0 = d0 / r
            w1 = d1 / r
            w2 = d2 / r
        else:
            w0 = frame[0, 0]
            w1 = frame[0, 1]
            w2 = frame[0, 2]
        # polar axis: the frame axis most nearly perpendicular to the point's direction
        best = 2.0
        for k in range(3):
            c = abs(w0 * frame[k, 0] + w1 * frame[k, 1] + w2 * frame[k, 2])
            if c < best:
                best = c
                chart = k
        kq1 = (chart + 1) % 3
        kq2 = (chart + 2) % 3
        up = w0 * frame[chart, 0] + w1 * frame[chart, 1] + w2 * frame[chart, 2]
        u1 = w0 * frame[kq1, 0] + w1 * frame[kq1, 1] + w2 * frame[kq1, 2]
        u2 = w0 * frame[kq2, 0] + w1 * frame[kq2, 1] + w2 * frame[kq2, 2]
        st = np.sqrt(u1 * u1 + u2 * u2)
        theta = np.arctan2(st, up)
        phi = np.arctan2(u2, u1)
        st = np.sin(theta)
        ct = np.cos(theta)
        cp = np.cos(phi)
        sp = np.sin(phi)
        xi[0] = theta
        xi[1] = sigma * phi
        g = sigma * (r - radius)
        for p in range(3):
            q1 = frame[kq1, p]
            q2 = frame[kq2, p]
            pp = frame[chart, p]
            er = st * cp * q1 + st * sp * q2 + ct * pp
            eth = ct * cp * q1 + ct * sp * q2 - st * pp
            eph = -sp * q1 + cp * q2
            rho[p] = origin[p] + radius * er
            rho_cov[0, p] = radius * eth
            rho_cov[1, p] = sigma * radius * st * eph
            n[p] = sigma * er
        a_cov[0, 0] = radius * radius
        a_cov[1, 1] = radius * radius * st * st
        h_cov[0, 0] = -sigma * radius
        h_cov[1, 1] = -sigma * radius * st * st
    det = a_cov[0, 0] * a_cov[1, 1] - a_cov[0, 1] * a_cov[1, 0]
    a_con[0, 0] = a_cov[1, 1] / det
    a_con[1, 1] = a_cov[0, 0] / det
    a_con[0, 1] = -a_cov[0, 1] / det
    a_con[1, 0] = -a_cov[1, 0] / det
    return g, chart


@njit(cache=True)
def new_analytic_work():
    """Scratch arrays of one analytic evaluation."""
    return (
        np.empty(3),
        np.empty((2, 3)),
        np.empty((2, 2)),
        np.empty((2, 2)),
        np.empty(3),
        np.empty((2, 2)),
        np.empty((2, 2)),
        np.empty((2, 2)),
        np.empty((2, 2)),
        np.empty((2, 2)),
    )


@njit(cache=True)
def _add_rr(coef, rho_cov, scale, K):
    for p in range(3):
        for q in range(3):
            s = 0.0
            for i in range(2):
                for j in range(2):
                    s += coef[i, j] * rho_cov[i, p] * rho_cov[j, q]
            K[p, q] += scale * s


@njit(cache=True)
def analytic_core(
    kind, origin, frame, radius, sigma, prof, xs, eps_n, case, want_parts, xi, R_out, K_out, P_out, work, lam_k=0.0,
    band=0.0,
):
    """Project ``xs`` and evaluate the 3 x 3 rigid-master contact element; returns (g, chart).

    xi: (2,) out. R_out (3,), K_out (3, 3), P_out (4, 3, 3) out (P_out untouched unless want_parts);
    order of parts as ``PART_NAMES``. ``work[4]`` holds the normal on return. lam_k: Uzawa multiplier
    (<= 0, fixed during Newton; 0 = penalty); band: width of the smoothing of the normal law (0: none).
    g is the geometric gap; outputs are zero when the slave is not active.
    """
    rho, rho_cov, a_cov, a_con, n, h_cov, h_con, c_con, D1, D2 = work
    g, chart = analytic_geometry(
        kind, origin, frame, radius, sigma, prof, xs, xi, rho, rho_cov, a_cov, a_con, n, h_cov
    )
    for p in range(3):
        R_out[p] = 0.0
        for q in range(3):
            K_out[p, q] = 0.0
            if want_parts:
                for k in range(4):
                    P_out[k, p, q] = 0.0
    if not is_active(g, lam_k, eps_n, band):
        return g, chart
    eps_n, lam_k = linear_equivalent(g, lam_k, eps_n, band)  # the smoothed law (band > 0) at this g
    ge = effective_gap(g, lam_k, eps_n)  # lam_N = eps_n ge
    for p in range(3):
        R_out[p] = eps_n * ge * n[p]
    _mat2_prod3(a_con, h_cov, a_con, h_con, 1.0)
    c_inverse(a_cov, a_con, h_cov, g, c_con)  # a^ij on the focal point/axis (no exact Hessian)
    _mat2_prod3(a_con, h_cov, c_con, D1, ge)  # ge/g (c^ij - a^ij)
    _mat2_prod3(a_con, h_cov, D1, D2, -g)  # ge/g (a^ij - c^ij + g h^ij)
    for p in range(3):
        for q in range(3):
            K_out[p, q] = eps_n * n[p] * n[q]
    if case == CASE_EXACT or (chart == SHARP_CORNER and (case == CASE_A or case == CASE_C)):
        for i in range(2):
            for j in range(2):
                D1[i, j] = -D1[i, j]
        _add_rr(D1, rho_cov, eps_n, K_out)
        for i in range(2):
            for j in range(2):
                D1[i, j] = -D1[i, j]
    elif case == CASE_A or case == CASE_C:
        _add_rr(h_con, rho_cov, -eps_n * ge, K_out)
    if want_parts:
        for p in range(3):
            for q in range(3):
                P_out[0, p, q] = eps_n * n[p] * n[q]
        if chart == SHARP_CORNER:  # a vertex: its whole second-order stiffness is the "curvature" part
            _add_rr(D1, rho_cov, -eps_n, P_out[2])
        else:
            _add_rr(h_con, rho_cov, -eps_n * ge, P_out[2])
            _add_rr(D2, rho_cov, eps_n, P_out[3])
    return g, chart


@njit(cache=True, parallel=True)
def analytic_batch(
    kind,
    origin,
    frame,
    radius,
    sigma,
    prof,
    xs,
    eps,
    case,
    R_out,
    K_out,
    g_out,
    xi_out,
    n_out,
    chart_out,
    lam_k=None,
    band=0.0,
):
    """Many slave points (ns, 3) against one analytic surface, parallel over slaves.

    eps: (ns,) penalties (already weighted). Outputs: R_out (ns, 3), K_out (ns, 3, 3), g_out (ns,),
    xi_out (ns, 2), n_out (ns, 3), chart_out (ns,) int64. lam_k: (ns,) Uzawa multipliers (<= 0),
    None (default): pure penalty.
    """
    ns = xs.shape[0]
    nchunk = (ns + _CHUNK - 1) // _CHUNK
    dummy = np.empty((1, 1, 1))
    for c in prange(nchunk):
        work = new_analytic_work()  # scratch per chunk of slaves, not per slave
        lo = c * _CHUNK
        hi = min(ns, lo + _CHUNK)
        for s in range(lo, hi):
            lk = 0.0
            if lam_k is not None:
                lk = lam_k[s]
            g, chart = analytic_core(
                kind,
                origin,
                frame,
                radius,
                sigma,
                prof,
                xs[s],
                eps[s],
                case,
                False,
                xi_out[s],
                R_out[s],
                K_out[s],
                dummy,
                work,
                lk,
                band,
            )
            g_out[s] = g
            chart_out[s] = chart
            n_out[s, 0] = work[4][0]
            n_out[s, 1] = work[4][1]
            n_out[s, 2] = work[4][2]


@dataclass
class AnalyticProjection:
    """Closest point on an analytic surface and its covariant quantities."""

    gap: float
    xi: np.ndarray
    chart: int
    rho: np.ndarray
    rho_cov: np.ndarray
    a_cov: np.ndarray
    h_cov: np.ndarray
    normal: np.ndarray


@dataclass
class AnalyticBatch:
    """Results of ``evaluate`` for ns slave points."""

    gap: np.ndarray
    xi: np.ndarray
    chart: np.ndarray
    normal: np.ndarray
    residual: np.ndarray
    tangent: np.ndarray


class _Analytic:
    kind = PLANE
    radius = 0.0
    sigma = 1.0
    prof = NO_PROFILE
    motion: RigidMotion
    _origin: np.ndarray
    _frame: np.ndarray

    def _place(self, kind, origin, origin_name, axis=None, axis_name="", radius=None, outside=True):
        """Validate and store kind, radius and sigma (if ``radius`` is given), origin and frame.

        The frame is built around the unit ``axis`` (the identity without one).
        """
        self.kind = kind
        if radius is not None:
            if not (np.isfinite(radius) and radius > 0.0):
                raise ValueError(f"radius must be positive, got {radius!r}")
            self.sigma = 1.0 if outside else -1.0
        self._origin = np.asarray(origin, dtype=np.float64).copy()
        if self._origin.shape != (3,) or not np.all(np.isfinite(self._origin)):
            raise ValueError(f"{origin_name} must be 3 finite numbers, got {origin!r}")
        self._frame = np.eye(3) if axis is None else frame_from_axis(unit_vector(axis, axis_name))

    def placement(self, lam: float = 1.0):
        """Current origin (3,) and frame (3, 3) (rows e1, e2, e3) at load factor ``lam``."""
        origin = np.ascontiguousarray(self.motion.apply(self._origin, lam))
        frame = np.ascontiguousarray(self.motion.rotate(self._frame, lam))
        return origin, frame

    def project(self, slave_xyz, lam: float = 1.0) -> AnalyticProjection:
        """Closed-form closest point of ``slave_xyz`` (3,)."""
        xs, _, _, _ = check_inputs(slave_xyz, 1.0, "a", None)
        origin, frame = self.placement(lam)
        xi, rho, rc, a, ac, n, h = (
            np.zeros(2),
            np.zeros(3),
            np.zeros((2, 3)),
            np.zeros((2, 2)),
            np.zeros((2, 2)),
            np.zeros(3),
            np.zeros((2, 2)),
        )
        g, chart = analytic_geometry(
            self.kind, origin, frame, float(self.radius), float(self.sigma), self.prof, xs, xi, rho, rc, a, ac,
            n, h
        )
        return AnalyticProjection(float(g), xi, int(chart), rho, rc, a, h, n)

    def contact(
        self, slave_xyz, eps_n, parts: str = "a", lam: float = 1.0, multiplier: float = 0.0, band: float = 0.0
    ) -> ContactResult:
        """Contact element of one slave node (3 x 3, slave dofs only); see ``ContactResult``.

        lam is the load factor of the motion; multiplier the Uzawa multiplier lam_k <= 0 (0: penalty); band the
        width of the normal law's smoothing (0: none).
        """
        xs, eps, case, _ = check_inputs(slave_xyz, eps_n, parts, None)
        lam_k = check_multiplier(multiplier)
        origin, frame = self.placement(lam)
        work = new_analytic_work()
        xi, R, K, P = np.zeros(2), np.zeros(3), np.zeros((3, 3)), np.zeros((4, 3, 3))
        g, _ = analytic_core(
            self.kind,
            origin,
            frame,
            float(self.radius),
            float(self.sigma),
            self.prof,
            xs,
            eps,
            case,
            True,
            xi,
            R,
            K,
            P,
            work,
            lam_k,
            float(band),
        )
        return ContactResult(
            gap=float(g),
            xi=xi,
            normal=work[4].copy(),
            inside=True,
            residual=R,
            tangent=K,
            parts={name: P[k] for k, name in enumerate(PART_NAMES)},
        )

    def evaluate(self, slave_xyz, eps, parts: str = "a", lam: float = 1.0, multiplier=None,
                 band: float = 0.0) -> AnalyticBatch:
        """Compiled batch over slave points (ns, 3) with penalties ``eps`` (scalar or (ns,)).

        lam: load factor of the motion. multiplier: Uzawa multipliers lam_k <= 0 (scalar or (ns,));
        None: pure penalty.
        """
        xs = np.ascontiguousarray(np.asarray(slave_xyz, dtype=np.float64))
        if xs.ndim != 2 or xs.shape[1] != 3:
            raise ValueError(f"slave_xyz must have shape (ns, 3), got {xs.shape}")
        ns = xs.shape[0]
        e = np.ascontiguousarray(np.broadcast_to(np.asarray(eps, dtype=np.float64), (ns,)))
        _, _, case, _ = check_inputs(np.zeros(3), 1.0, parts, None)
        if not (np.all(np.isfinite(xs)) and np.all(np.isfinite(e)) and np.all(e > 0.0)):
            raise ValueError("slave_xyz must be finite and eps positive")
        lk = None
        if multiplier is not None:
            lk = np.ascontiguousarray(np.broadcast_to(np.asarray(multiplier, dtype=np.float64), (ns,)))
            if not (np.all(np.isfinite(lk)) and np.all(lk <= 0.0)):
                raise ValueError("multiplier must be finite and <= 0")
        origin, frame = self.placement(lam)
        out = AnalyticBatch(
            np.zeros(ns),
            np.zeros((ns, 2)),
            np.zeros(ns, dtype=np.int64),
            np.zeros((ns, 3)),
            np.zeros((ns, 3)),
            np.zeros((ns, 3, 3)),
        )
        if ns:
            analytic_batch(
                self.kind,
                origin,
                frame,
                float(self.radius),
                float(self.sigma),
                self.prof,
                xs,
                e,
                case,
                out.residual,
                out.tangent,
                out.gap,
                out.xi,
                out.normal,
                out.chart,
                lk,
                float(band),
            )
        return out


@dataclass
class Plane(_Analytic):
    """Rigid plane through ``point`` with outward unit normal ``normal``."""

    point: tuple | np.ndarray = (0.0, 0.0, 0.0)
    normal: tuple | np.ndarray = (0.0, 0.0, 1.0)
    motion: RigidMotion = field(default_factory=RigidMotion)

    def __post_init__(self):
        self._place(PLANE, self.point, "point", self.normal, "normal")


@dataclass
class Cylinder(_Analytic):
    """Rigid circular cylinder: axis through ``center`` along ``axis``, ``radius``.

    outside=True: solid cylinder touched from outside (n points away from the axis);
    outside=False: hollow, touched from inside (n points to the axis).
    """

    center: tuple | np.ndarray = (0.0, 0.0, 0.0)
    axis: tuple | np.ndarray = (0.0, 0.0, 1.0)
    radius: float = 1.0
    outside: bool = True
    motion: RigidMotion = field(default_factory=RigidMotion)

    def __post_init__(self):
        self._place(CYLINDER, self.center, "center", self.axis, "axis", self.radius, self.outside)


@dataclass
class Sphere(_Analytic):
    """Rigid sphere of ``radius`` about ``center``; ``outside`` as for ``Cylinder``."""

    center: tuple | np.ndarray = (0.0, 0.0, 0.0)
    radius: float = 1.0
    outside: bool = True
    motion: RigidMotion = field(default_factory=RigidMotion)

    def __post_init__(self):
        self._place(SPHERE, self.center, "center", radius=self.radius, outside=self.outside)
