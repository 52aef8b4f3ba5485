"""Covariant Coulomb friction element: Python layer and the rigid analytic-surface twin.

The compiled facet element and the mathematics are in ``friction_kernels`` (docs/theory.md section 7).

History of one slave node, HIST_SIZE = 14 floats, written by every evaluation into ``hist_out`` (the
values to commit when the step converges; the caller keeps the committed copy and the facet id):

    [0:2]  xi_n        projection of the last converged step (slip dxi = xi - xi_n on the same facet)
    [2:5]  rho_n       contact point rho(xi_n)            (analytic surfaces: in the body frame)
    [5:11] rho_cov_n   rho_1, rho_2 at xi_n               (analytic surfaces: in the body frame)
    [11:13] T_n        covariant tangential traction T_i (zero while open)
    [13]   flag        1.0 valid, 0.0 none (the element is then frictionless: state NEW)

The facet element uses xi_n and T_n only; rho_n and rho_cov_n serve ``transfer_history`` when a slave
node moves to another facet. Analytic surfaces use rho_n and rho_cov_n (body frame) and T_n, so their
history is chart-free and moves with the surface.
States: OPEN 0, STICK 1, SLIP 2 (also mu = 0), NEW 3.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numba import njit, prange

from covcontact.contact.analytic import CYLINDER, EXTRUDED, PLANE, REVOLVED, analytic_core, new_analytic_work
from covcontact.contact.element import (
    CASE_EXACT,
    INSIDE_TOL,
    ContactResult,
    _as_points,
    check_inputs,
    contact_element,
)
from covcontact.contact.friction_kernels import (
    H_FLAG,
    H_RHO,
    H_RHO_COV,
    H_T,
    H_XI,
    HIST_SIZE,
    NEW,
    OPEN,
    SLIP,
    STICK,
    friction_batch,
    friction_element,
    friction_generic,
    inv2,
    new_friction_work,
)
from covcontact.contact.geometry import facet_geometry
from covcontact.contact.laws import is_active, linear_equivalent
from covcontact.contact.profile import profile_closest, profile_derivative
from covcontact.contact.projection import CONVERGED, DEGENERATE, project_on_facet
from covcontact.contact.surface import edge_closest_point
from covcontact.fem.shapes import NODES

__all__ = [
    "HIST_SIZE",
    "NEW",
    "OPEN",
    "SLIP",
    "STATES",
    "STICK",
    "FrictionResult",
    "analytic_friction_batch",
    "analytic_friction_core",
    "friction_batch",
    "friction_element",
    "make_history",
    "new_history",
    "node_to_surface_friction",
    "surface_friction",
    "transfer_history",
]

STATES = {OPEN: "open", STICK: "stick", SLIP: "slip", NEW: "new"}

_CHUNK = 16


# ------------------------------------------------------------------- rigid analytic surfaces (compiled)


@njit(cache=True)
def _surface_deriv(kind, origin, frame, radius, sigma, prof, chart, xi, na, nb_, out):
    """d^(na + nb_) rho / d xi1^na d xi2^nb_ of an analytic surface in ``chart`` (3,) into out."""
    for p in range(3):
        out[p] = 0.0
    hp = 0.5 * np.pi
    if kind == EXTRUDED:
        if nb_ == 0:
            cx, cy = profile_derivative(prof, xi[0], na)
            for p in range(3):
                out[p] = cx * frame[0, p] + cy * frame[1, p]
                if na == 0:
                    out[p] += origin[p] - xi[1] * frame[2, p]
        elif nb_ == 1 and na == 0:
            for p in range(3):
                out[p] = -frame[2, p]
    elif kind == REVOLVED:
        cr, cz = profile_derivative(prof, xi[0], na)
        c = np.cos(xi[1] + nb_ * hp)
        s = np.sin(xi[1] + nb_ * hp)
        for p in range(3):
            out[p] = cr * (c * frame[0, p] + s * frame[1, p])
            if nb_ == 0:
                out[p] += cz * frame[2, p]
                if na == 0:
                    out[p] += origin[p]
    elif kind == PLANE:
        for p in range(3):
            if na == 0 and nb_ == 0:
                out[p] = origin[p] + xi[0] * frame[0, p] + xi[1] * frame[1, p]
            elif na + nb_ == 1:
                out[p] = frame[0, p] if na == 1 else frame[1, p]
    elif kind == CYLINDER:
        c = np.cos(xi[0] + na * hp)
        s = np.sin(xi[0] + na * hp)
        for p in range(3):
            if nb_ == 0:
                out[p] = radius * (c * frame[0, p] + s * frame[1, p])
                if na == 0:
                    out[p] += origin[p] + sigma * xi[1] * frame[2, p]
            elif nb_ == 1 and na == 0:
                out[p] = sigma * frame[2, p]
    else:
        k1 = (chart + 1) % 3
        k2 = (chart + 2) % 3
        ph = sigma * xi[1]
        st = np.sin(xi[0] + na * hp)
        ct = np.cos(xi[0] + na * hp)
        cp = np.cos(ph + nb_ * hp)
        sp = np.sin(ph + nb_ * hp)
        f = radius * sigma**nb_
        for p in range(3):
            out[p] = f * (st * cp * frame[k1, p] + st * sp * frame[k2, p])
            if nb_ == 0:
                out[p] += f * ct * frame[chart, p]
            if na == 0 and nb_ == 0:
                out[p] += origin[p]


@njit(cache=True)
def surface_derivs(kind, origin, frame, radius, sigma, prof, chart, xi, rho, rho1, rho2, rho3):
    """rho and its derivatives by xi up to third order, (3,), (2, 3), (2, 2, 3), (2, 2, 2, 3)."""
    _surface_deriv(kind, origin, frame, radius, sigma, prof, chart, xi, np.int64(0), np.int64(0), rho)
    for i in range(2):
        _surface_deriv(kind, origin, frame, radius, sigma, prof, chart, xi, 1 - i, i, rho1[i])
        for j in range(2):
            _surface_deriv(kind, origin, frame, radius, sigma, prof, chart, xi, 2 - i - j, i + j, rho2[i, j])
            for k in range(2):
                nb_ = i + j + k
                _surface_deriv(kind, origin, frame, radius, sigma, prof, chart, xi, 3 - nb_, nb_,
                               rho3[i, j, k])


@njit(cache=True)
def surface_coords(kind, origin, frame, radius, sigma, prof, chart, point, xi_ref, xi_out):
    """Coordinates in ``chart`` of a point on the surface, angles unwrapped to within pi of xi_ref."""
    d = (point[0] - origin[0], point[1] - origin[1], point[2] - origin[2])
    if kind == EXTRUDED:
        pp = d[0] * frame[0, 0] + d[1] * frame[0, 1] + d[2] * frame[0, 2]
        qq = d[0] * frame[1, 0] + d[1] * frame[1, 1] + d[2] * frame[1, 2]
        k, t, _ = profile_closest(prof, pp, qq)
        xi_out[0] = prof[k, 1] + t
        xi_out[1] = -(d[0] * frame[2, 0] + d[1] * frame[2, 1] + d[2] * frame[2, 2])
        return
    if kind == REVOLVED:
        x1 = d[0] * frame[0, 0] + d[1] * frame[0, 1] + d[2] * frame[0, 2]
        x2 = d[0] * frame[1, 0] + d[1] * frame[1, 1] + d[2] * frame[1, 2]
        z = d[0] * frame[2, 0] + d[1] * frame[2, 1] + d[2] * frame[2, 2]
        k, t, _ = profile_closest(prof, np.sqrt(x1 * x1 + x2 * x2), z)
        phi = np.arctan2(x2, x1)
        tp = 2.0 * np.pi
        xi_out[0] = prof[k, 1] + t
        xi_out[1] = phi + tp * np.round((xi_ref[1] - phi) / tp)
        return
    if kind == PLANE:
        xi_out[0] = d[0] * frame[0, 0] + d[1] * frame[0, 1] + d[2] * frame[0, 2]
        xi_out[1] = d[0] * frame[1, 0] + d[1] * frame[1, 1] + d[2] * frame[1, 2]
        return
    tp = 2.0 * np.pi
    if kind == CYLINDER:
        x1 = d[0] * frame[0, 0] + d[1] * frame[0, 1] + d[2] * frame[0, 2]
        x2 = d[0] * frame[1, 0] + d[1] * frame[1, 1] + d[2] * frame[1, 2]
        z = d[0] * frame[2, 0] + d[1] * frame[2, 1] + d[2] * frame[2, 2]
        phi = np.arctan2(x2, x1)
        xi_out[0] = phi + tp * np.round((xi_ref[0] - phi) / tp)
        xi_out[1] = sigma * z
        return
    k1 = (chart + 1) % 3
    k2 = (chart + 2) % 3
    up = d[0] * frame[chart, 0] + d[1] * frame[chart, 1] + d[2] * frame[chart, 2]
    u1 = d[0] * frame[k1, 0] + d[1] * frame[k1, 1] + d[2] * frame[k1, 2]
    u2 = d[0] * frame[k2, 0] + d[1] * frame[k2, 1] + d[2] * frame[k2, 2]
    phi = np.arctan2(u2, u1)
    ref = sigma * xi_ref[1]
    xi_out[0] = np.arctan2(np.sqrt(u1 * u1 + u2 * u2), up)
    xi_out[1] = sigma * (phi + tp * np.round((ref - phi) / tp))


@njit(cache=True)
def new_analytic_friction_work():
    """Scratch of ``analytic_friction_core``."""
    geo = (
        np.empty(3), np.empty((2, 3)), np.empty((2, 2, 3)), np.empty((2, 2, 2, 3)),  # 0-3
        np.empty((2, 2)), np.empty((2, 2)), np.empty((2, 2)), np.empty((2, 2)),  # 4-7 a, a^-1, a_n, a_n^-1
        np.ones(1), np.zeros((2, 1)), np.zeros((2, 2, 1)),  # 8-10 ar, d1, d2
        np.empty(3), np.empty(3), np.zeros((3, 3)), np.empty(2), np.empty(2), np.empty(2),  # 11-16
        np.empty(3), np.empty((1, 1, 1)),  # 17 point, 18 dummy
    )
    return new_analytic_work(), new_friction_work(), geo


@njit(cache=True)
def analytic_friction_core(kind, origin, frame, radius, sigma, prof, xs, eps_n, eps_t, mu, hist, xi,
                           R_out, K_out, hist_out, work, lam_k=0.0, band=0.0):
    """Friction element of one slave node against a rigid analytic surface (3 x 3, slave dofs).

    origin, frame: current placement (frame rows e1, e2, e3). xi: (2,) out, projection. History
    points and base vectors are kept in the surface's body frame (objective; chart independent).
    Returns (g, state).
    """
    aw, fw, geo = work
    rho, rho1, rho2, rho3, a_cov, a_con, a_n, a_ni, ar, d1, d2, r, tvec, dtdx, xin, dxi, T, pt, dummy = geo
    # np.int64 / np.bool_ constants are run-time values to numba: one compiled callee for every caller
    exact, no = np.int64(CASE_EXACT), np.bool_(False)
    g, chart = analytic_core(kind, origin, frame, radius, sigma, prof, xs, eps_n, exact, no, xi, R_out,
                             K_out, dummy, aw, lam_k, band)
    nrm = aw[4]
    if kind == REVOLVED and chart == 1:
        # on the axis of a revolved profile the angle is no coordinate: the node takes the normal force only
        # (in an axisymmetric model its tangential force is zero by symmetry) and keeps no history
        for k in range(HIST_SIZE):
            hist_out[k] = 0.0
        return g, (SLIP if is_active(g, lam_k, eps_n, band) else OPEN)
    surface_derivs(kind, origin, frame, radius, sigma, prof, chart, xi, rho, rho1, rho2, rho3)
    for i in range(2):
        for j in range(2):
            a_cov[i, j] = rho1[i, 0] * rho1[j, 0] + rho1[i, 1] * rho1[j, 1] + rho1[i, 2] * rho1[j, 2]
    inv2(a_cov, a_con)
    for k in range(HIST_SIZE):
        hist_out[k] = 0.0
    hist_out[H_XI] = xi[0]
    hist_out[H_XI + 1] = xi[1]
    for e in range(3):
        s0 = 0.0
        s1 = 0.0
        s2 = 0.0
        for p in range(3):
            s0 += frame[e, p] * (rho[p] - origin[p])
            s1 += frame[e, p] * rho1[0, p]
            s2 += frame[e, p] * rho1[1, p]
        hist_out[H_RHO + e] = s0
        hist_out[H_RHO_COV + e] = s1
        hist_out[H_RHO_COV + 3 + e] = s2
    hist_out[H_FLAG] = 1.0
    if not is_active(g, lam_k, eps_n, band):
        return g, OPEN
    eps_n, lam_k = linear_equivalent(g, lam_k, eps_n, band)  # the smoothed law's traction and slope here
    if mu == 0.0:
        return g, SLIP
    if hist[H_FLAG] == 0.0:
        return g, NEW
    # old point and traction, body frame -> current placement
    for i in range(2):
        for j in range(2):
            s = 0.0
            for e in range(3):
                s += hist[H_RHO_COV + 3 * i + e] * hist[H_RHO_COV + 3 * j + e]
            a_n[i, j] = s
    inv2(a_n, a_ni)
    Tu0 = a_ni[0, 0] * hist[H_T] + a_ni[0, 1] * hist[H_T + 1]
    Tu1 = a_ni[1, 0] * hist[H_T] + a_ni[1, 1] * hist[H_T + 1]
    for p in range(3):
        pt[p] = origin[p]
        tvec[p] = 0.0
        for e in range(3):
            pt[p] += frame[e, p] * hist[H_RHO + e]
            tvec[p] += frame[e, p] * (Tu0 * hist[H_RHO_COV + e] + Tu1 * hist[H_RHO_COV + 3 + e])
        r[p] = xs[p] - rho[p]
    surface_coords(kind, origin, frame, radius, sigma, prof, chart, pt, xi, xin)
    dxi[0] = xi[0] - xin[0]
    dxi[1] = xi[1] - xin[1]
    one = np.int64(1)
    state = friction_generic(one, ar, d1, d2, r, nrm, g, rho1, rho2, rho3, a_cov, a_con, dxi, tvec, dtdx,
                             eps_n, eps_t, mu, R_out, K_out, T, fw, lam_k)
    hist_out[H_T] = T[0]
    hist_out[H_T + 1] = T[1]
    return g, state


@njit(cache=True, parallel=True)
def analytic_friction_batch(kind, origin, frame, radius, sigma, prof, xs, eps_n, eps_t, mu, hist, R_out, K_out,
                            hist_out, g_out, xi_out, state_out, lam_k, band=0.0):
    """``analytic_friction_core`` for ns slave points (ns, 3), parallel; per-slave eps_n, eps_t, mu, hist and
    lam_k (Uzawa multipliers, zeros for the penalty).

    Out: R_out (ns, 3), K_out (ns, 3, 3), hist_out (ns, HIST_SIZE), g_out (ns,), xi_out (ns, 2),
    state_out (ns,) int64.
    """
    ns = xs.shape[0]
    nchunk = (ns + _CHUNK - 1) // _CHUNK
    for c in prange(nchunk):
        work = new_analytic_friction_work()
        lo = c * _CHUNK
        hi = min(ns, lo + _CHUNK)
        for s in range(lo, hi):
            g, st = analytic_friction_core(kind, origin, frame, radius, sigma, prof, xs[s], eps_n[s], eps_t[s],
                                           mu[s], hist[s], xi_out[s], R_out[s], K_out[s], hist_out[s], work,
                                           lam_k[s], band)
            g_out[s] = g
            state_out[s] = st


# ------------------------------------------------------------------------------------------ Python layer


@dataclass
class FrictionResult(ContactResult):
    """``ContactResult`` of the frictional element (parts: "normal", "friction"), plus:

    Attributes:
        state: OPEN, STICK, SLIP or NEW (see ``STATES``).
        traction: (2,) covariant tangential traction T_i (after the return mapping).
        traction_vector: (3,) a^ij T_j rho_i, the tangential traction on the slave.
        history: (HIST_SIZE,) history to commit when the step converges.
    """

    state: int = OPEN
    traction: np.ndarray = field(default_factory=lambda: np.zeros(2))
    traction_vector: np.ndarray = field(default_factory=lambda: np.zeros(3))
    history: np.ndarray = field(default_factory=lambda: np.zeros(HIST_SIZE))


def new_history() -> np.ndarray:
    """An empty history (flag 0)."""
    return np.zeros(HIST_SIZE)


def make_history(xi_n, traction=(0.0, 0.0), rho_n=(0.0, 0.0, 0.0), rho_cov_n=None) -> np.ndarray:
    """A valid history from its parts (rho_cov_n (2, 3) defaults to the unit axes e1, e2)."""
    xi = _as_points(xi_n, lambda s: s == (2,), "xi_n (expected (2,))")
    rho = _as_points(rho_n, lambda s: s == (3,), "rho_n (expected (3,))")
    rc = np.eye(3)[:2] if rho_cov_n is None else rho_cov_n
    rc = _as_points(rc, lambda s: s == (2, 3), "rho_cov_n (expected (2, 3))")
    return _history(xi, _as_points(traction, lambda s: s == (2,), "traction (expected (2,))"), rho, rc)


def _history(xi, t, rho, rc) -> np.ndarray:
    """The history of arrays of the right shapes (xi (2,), t (2,), rho (3,), rc (2, 3)), only their finiteness
    checked: the inner loops of the friction history (every new contact point at every residual of a step) call it,
    ``make_history`` after checking each part."""
    h = np.zeros(HIST_SIZE)
    h[H_XI:H_XI + 2] = xi
    h[H_RHO:H_RHO + 3] = rho
    h[H_RHO_COV:H_RHO_COV + 6] = rc.ravel()
    h[H_T:H_T + 2] = t
    h[H_FLAG] = 1.0
    if not np.isfinite(h).all():
        raise ValueError("friction history contains non-finite values")
    return h


def _check_friction(eps_t, mu, history):
    et = float(eps_t)
    if not np.isfinite(et) or et <= 0.0:
        raise ValueError(f"eps_t must be a positive finite number, got {eps_t!r}")
    m = float(mu)
    if not np.isfinite(m) or m < 0.0:
        raise ValueError(f"mu must be a finite number >= 0, got {mu!r}")
    hist = new_history() if history is None else _as_points(
        history, lambda s: s == (HIST_SIZE,), f"history (expected ({HIST_SIZE},))").copy()
    return et, m, hist


def _traction_vector(T, rho_cov):
    a = rho_cov @ rho_cov.T
    return np.linalg.solve(a, T) @ rho_cov


def node_to_surface_friction(
    master_xyz, slave_xyz, eps_n, eps_t, mu, history=None, xi0=None
) -> FrictionResult:
    """Frictional contact of one slave node against one quad4/quad9 master facet.

    Args:
        master_xyz: (n, 3) current facet nodes, n = 4 or 9, VTK order, outward normal.
        slave_xyz: (3,) current slave position.
        eps_n, eps_t: normal and tangential penalties (> 0). mu: Coulomb coefficient (>= 0).
        history: (HIST_SIZE,) committed history on this facet, or None (no history: state NEW).
        xi0: (2,) projection start; default the nearest facet node (use xi_n when sliding).

    Returns:
        FrictionResult: residual (3(n+1),) and exact tangent (master nodes first, slave last).
    """
    xyz = _as_points(master_xyz, lambda s: s in ((4, 3), (9, 3)), "master_xyz (expected (4, 3) or (9, 3))")
    xs, eps, _, xi = check_inputs(slave_xyz, eps_n, "exact", xi0)
    et, m, hist = _check_friction(eps_t, mu, history)
    nen = xyz.shape[0]
    if xi is None:
        k = int(np.argmin(np.sum((xyz - xs) ** 2, axis=1)))
        xi = NODES["quad4" if nen == 4 else "quad9"][k].astype(np.float64).copy()
    status, _ = project_on_facet(xyz, xs, xi)
    if status == DEGENERATE:
        raise ValueError("degenerate master facet (zero area element at the projection)")
    size = 3 * (nen + 1)
    R, K, ho = np.zeros(size), np.zeros((size, size)), np.zeros(HIST_SIZE)
    g, state = friction_element(xyz, xs, xi, eps, et, m, hist, R, K, ho)
    RN, KN = np.zeros(size), np.zeros((size, size))
    contact_element(xyz, xs, xi, eps, CASE_EXACT, False, RN, KN, np.zeros((1, 1, 1)))
    _, rc, nrm, _ = _facet_frame(xyz, xi)
    T = ho[H_T:H_T + 2].copy()
    return FrictionResult(
        gap=float(g), xi=xi, normal=nrm, inside=bool(np.all(np.abs(xi) <= 1.0 + INSIDE_TOL)), residual=R,
        tangent=K, parts={"normal": KN, "friction": K - KN}, status=int(status), state=int(state), traction=T,
        traction_vector=_traction_vector(T, rc), history=ho)


def surface_friction(surface, slave_xyz, eps_n, eps_t, mu, history=None, lam: float = 1.0,
                     band: float = 0.0) -> FrictionResult:
    """Frictional contact of one slave node against a rigid ``Plane``, ``Cylinder``, ``Sphere`` or ``Profile``.

    Arguments as ``node_to_surface_friction``; ``lam`` places the surface (its ``RigidMotion``); ``band`` the
    width of the normal law's smoothing (0: none). Residual (3,) and tangent (3, 3) act on the slave dofs only.
    """
    xs, eps, _, _ = check_inputs(slave_xyz, eps_n, "exact", None)
    et, m, hist = _check_friction(eps_t, mu, history)
    origin, frame = surface.placement(lam)
    xi, R, K, ho = np.zeros(2), np.zeros(3), np.zeros((3, 3)), np.zeros(HIST_SIZE)
    g, state = analytic_friction_core(surface.kind, origin, frame, float(surface.radius),
                                      float(surface.sigma), surface.prof, xs, eps, et, m, hist, xi, R, K, ho,
                                      new_analytic_friction_work(), 0.0, float(band))
    normal = surface.contact(xs, eps, "exact", lam, band=band)
    pr = surface.project(xs, lam)
    T = ho[H_T:H_T + 2].copy()
    return FrictionResult(
        gap=float(g), xi=xi, normal=pr.normal, inside=True, residual=R, tangent=K,
        parts={"normal": normal.tangent, "friction": K - normal.tangent}, state=int(state), traction=T,
        traction_vector=_traction_vector(T, pr.rho_cov), history=ho)


#: how far beyond its edges (element coordinates) a history point may lie on the facet's continuation: the
#: continuation is the facet's polynomial carried on past its edges, which folds (rho_1 x rho_2 = 0) at a distance that
#: depends on the facet's shape; the quadrilaterals of a tri3 or tri6 patch (docs/theory.md section 19) fold at their
#: outer corner xi = (2, 2), one facet size away
TRANSFER_BAND = 0.5
#: ... and there the area element must be at least this share of the facet centre's, with the same orientation
_TRANSFER_AREA = 0.05


def _facet_frame(xyz, xi):
    """(rho, rho_cov, n, area element) of facet ``xyz`` at ``xi``; ValueError where the facet is degenerate there."""
    nen = xyz.shape[0]
    rho, rc, n = np.zeros(3), np.zeros((2, 3)), np.zeros(3)
    area = facet_geometry(xyz, xi[0], xi[1], np.empty(nen), np.empty((nen, 2)), np.empty((nen, 2, 2)), rho, rc,
                          np.empty((2, 2)), np.empty((2, 2)), n, np.empty((2, 2)))
    if area == 0.0:
        raise ValueError("degenerate master facet (zero area element at the point)")
    return rho, rc, n, area


def _regular_at(xyz, xi) -> bool:
    """Whether the facet's continuation is regular at ``xi``: within TRANSFER_BAND of the facet, its area element at
    least _TRANSFER_AREA of the centre's and its normal on the centre's side."""
    if not (math.isfinite(xi[0]) and math.isfinite(xi[1]) and max(abs(xi[0]), abs(xi[1])) <= 1.0 + TRANSFER_BAND):
        return False
    try:
        _, _, n0, a0 = _facet_frame(xyz, np.zeros(2))
        _, _, n1, a1 = _facet_frame(xyz, xi)
    except ValueError:
        return False
    return bool(a1 >= _TRANSFER_AREA * a0 and n1 @ n0 > 0.0)


def _closest_on_facet(xyz, point, xi0) -> np.ndarray:
    """The element coordinates (in [-1, 1]^2) of the point of the facet itself (not its continuation) closest to
    ``point``: a projection that converges inside, else the closest of its edge curves' points."""
    best, best_d2 = None, np.inf
    for start in (xi0, np.zeros(2)):
        xi = np.array(start, dtype=np.float64)
        status, _ = project_on_facet(xyz, point, xi)
        if status == CONVERGED and np.max(np.abs(xi)) <= 1.0 + INSIDE_TOL:
            xi = np.clip(xi, -1.0, 1.0)
            rho = _facet_frame(xyz, xi)[0]
            best, best_d2 = xi, float(np.sum((point - rho) ** 2))
            break
    corners = NODES["quad4"].astype(np.float64)
    c = np.empty(3)
    for e in range(4):
        t, d2 = edge_closest_point(xyz, e, point, c)
        if d2 < best_d2:
            best_d2 = d2
            best = 0.5 * (1.0 - t) * corners[e] + 0.5 * (1.0 + t) * corners[(e + 1) % 4]
    return best


def _anchored(xyz, point, t_vec, eps_t, xi0) -> np.ndarray:
    """The history on facet ``xyz`` (its configuration of the history) of a tangential spring anchored at ``point``
    that holds the traction vector ``t_vec``.

    The anchor is the projection of ``point`` on the facet, where that lies on the facet or on its regular
    continuation near it (``_regular_at``). Farther away (a slave that crossed more than the facet next to its old one
    in a step; near a fold of the continuation the frame is singular, beyond it the projection meaningless) the
    anchor is the facet's own closest point rho_a and the spring's stretch between the two points goes into the
    traction: t_a = t_vec - eps_t (rho_a - point), which gives the same trial traction t - eps_T (rho - anchor) at
    every contact point on a plane (to first order on a curved facet)."""
    xi = np.array(xi0, dtype=np.float64)
    status, _ = project_on_facet(xyz, point, xi)
    if status == DEGENERATE or not (status == CONVERGED and _regular_at(xyz, xi)):
        xi = _closest_on_facet(xyz, point, np.clip(np.nan_to_num(np.asarray(xi0, dtype=np.float64)), -1.0, 1.0))
    rho, rc, _, _ = _facet_frame(xyz, xi)
    return _history(xi, rc @ (t_vec - eps_t * (rho - point)), rho, rc)


def transfer_history(history, master_xyz, xi0=None, eps_t: float = 0.0) -> np.ndarray:
    """Move a facet history to another facet (a slave node changed facets).

    ``master_xyz`` are the new facet's nodes in the configuration of the history (the last converged
    step). The old contact point rho_n is projected onto the new facet, and the old traction vector
    t_n = T_k a_(n)^kl rho_l^(n) is re-expressed there: T'_i = t_n . rho'_i (tangential part).

    Where rho_n lies farther from the new facet than its regular continuation reaches (``TRANSFER_BAND`` beyond its
    edges), the history is anchored at the new facet's closest point rho_a instead, with the traction
    t_n - ``eps_t`` (rho_a - rho_n): ``eps_t`` is the slave's tangential penalty (0 drops the slip between the two
    points). ValueError where the new facet is degenerate.
    """
    hist = _check_friction(1.0, 0.0, history)[2]
    if hist[H_FLAG] == 0.0:
        return hist
    xyz = np.ascontiguousarray(_as_points(master_xyz, lambda s: s in ((4, 3), (9, 3)),
                                          "master_xyz (expected (4, 3) or (9, 3))"))
    rho_n = hist[H_RHO:H_RHO + 3].copy()
    rc_n = hist[H_RHO_COV:H_RHO_COV + 6].reshape(2, 3)
    t_n = _traction_vector(hist[H_T:H_T + 2], rc_n)
    if xi0 is None:
        k = int(np.argmin(np.sum((xyz - rho_n) ** 2, axis=1)))
        xi = NODES["quad4" if xyz.shape[0] == 4 else "quad9"][k].astype(np.float64).copy()
    else:
        xi = _as_points(xi0, lambda s: s == (2,), "xi0 (expected (2,))").copy()
    return _anchored(xyz, rho_n, t_n, float(eps_t), xi)


def start_history(master_xyz, slave_xyz, xi0, eps_t: float = 0.0) -> np.ndarray:
    """The history of a slave new to contact: its projection on the facet ``master_xyz`` (in the configuration where
    the step started, with the slave at ``slave_xyz`` there) as the stick point, zero traction (anchored on the
    facet as ``transfer_history`` does where that projection lies beyond the facet's regular continuation); no
    history (a frictionless start, state NEW) where the facet is degenerate there."""
    xyz = np.ascontiguousarray(master_xyz, dtype=np.float64)
    xs = np.ascontiguousarray(slave_xyz, dtype=np.float64)
    xi = np.array(xi0, dtype=np.float64)
    if not (np.all(np.isfinite(xi)) and np.all(np.isfinite(xs)) and np.all(np.isfinite(xyz))):
        return new_history()
    try:
        return _anchored(xyz, xs, np.zeros(3), float(eps_t), xi)
    except (ValueError, np.linalg.LinAlgError):
        return new_history()
