"""Covariant Coulomb friction in the plane: a slave node sliding along a master curve made of the linear or
quadratic edges of a planar body (docs/theory.md section 28, "Friction").

One convective coordinate xi along the segment x(xi) = N_b(xi) x_b, base vector rho = x,xi, metric a = rho . rho.
With the committed stick point xi_n of the slave on its segment and the committed covariant traction T_n:

    t'   = T_n rho(xi_n) / a(xi_n)               the old traction carried with the master (current configuration)
    T^tr = t' . rho - eps_T a (xi - xi_n)        the trial covariant traction
    ||T|| = |T| / sqrt(a),  kappa = mu p         (p = eps <-g_e> the normal pressure)
    stick: ||T^tr|| < kappa (1 - 1e-10), T = T^tr;   slip: T = kappa sqrt(a) sign(T^tr)   (on the cone: slip)

and the residual is the variational one of the 3D element (section 7) with one index,

    R = eps g_e A^T n - T xi' + tau^2 / (2 eps_T) D(a),   tau = T / a,   xi' = (A^T rho - g A,xi^T n) / c,  c = a - g h,

whose friction part is -A^T (T / a) rho to leading order (the slave feels the traction t = tau rho against its slip).
It is computed by the 3D kernel's generic routine (:func:`.friction_kernels.friction_generic`) on the curve's
extrusion along z, x(xi, zeta) = N_b(xi) x_b + zeta e_z: rho_2 = e_z, a_12 = 0, a_22 = 1, h_12 = h_22 = 0, no
derivative of rho_2 by the nodes. In-plane motion keeps zeta = 0 and T_2 = 0 (t' and the slip lie in the plane), so
the extruded element restricted to the in-plane dofs is exactly the one-coordinate element above, and the in-plane
block of its exact tangent (non-symmetric in slip) is this element's exact tangent; its z rows and columns (the
extrusion's own stick spring along z) are dropped, as the contact in the plane never sees z.

History per slave (HIST_SIZE = 14 floats, the 3D layout): [0] xi_n, [2:5] rho_n = x(xi_n), [5:8] rho(xi_n) in the
configuration of the last commit, [11] T_n, [13] the flag (1 valid); [1], [8:11], [12] zero. Every evaluation writes
the history to commit (xi, x(xi), rho(xi), T) into ``hist_out``; the committed one is only read.

Across segments (the slave's segment of the evaluation differs from that of its committed history) the history is
moved as the 3D code moves it across facets (:func:`transfer_history`): the old stick point rho_n is projected onto
the new segment in the configuration of the last commit (the segment's polynomial carried on past its ends, while
the projection converges within TRANSFER_BAND of the segment where the continuation stays regular), and the old
traction vector t_n = T_n rho_n / a_n is expressed there, T' = t_n . rho'(xi_n'); farther out the stick point is the
new segment's own closest point rho_a and the spring's stretch between the two goes into the traction,
t_a = t_n - eps_T (rho_a - rho_n). A slave new to contact sticks from where the step found it
(:func:`start_history`): its projection on its segment in the committed configuration, zero traction.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .element import CASE_EXACT
from .friction_kernels import (
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
    friction_generic,
    new_friction_work,
)
from .laws import is_active
from .planar_kernels import project_on_segment, segment_core, segment_point, segment_shapes

#: how far beyond its ends (in xi) a history point may lie on the segment's continuation
TRANSFER_BAND = 0.5
#: ... where the continuation's metric a must be at least this share of the segment centre's, rho on its side
_TRANSFER_METRIC = 0.05

__all__ = ["HIST_SIZE", "NEW", "OPEN", "SLIP", "STICK", "TRANSFER_BAND", "make_history", "segment_friction",
           "segment_friction_core", "start_history", "transfer_history", "vertex_friction", "vertex_history"]


@njit(cache=True)
def segment_friction_core(xseg, xs, xi, eps_n, eps_t, mu, lam_k, hist, R, K, hist_out):
    """Residual R (3 (nen + 1)) and exact tangent K (normal + friction; added into the zeroed outputs) of slave xs on
    segment xseg (nen, 3) at its projection xi, with the committed history ``hist`` (moved onto this segment);
    ``hist_out`` receives the history to commit. Returns (g, state): OPEN, STICK, SLIP (also mu = 0) or NEW (no
    history: frictionless)."""
    nen = xseg.shape[0]
    nb = nen + 1
    m = 3 * nb
    dummy = np.zeros((1, 1, 1))
    g = segment_core(xseg, xs, xi, eps_n, lam_k, np.int64(CASE_EXACT), np.bool_(False), R, K, dummy)
    N = np.empty(3)
    dN = np.empty(3)
    ddN = np.empty(3)
    segment_shapes(nen, xi, N, dN, ddN)
    x = np.zeros(3)
    rho1 = np.zeros((2, 3))
    rho2 = np.zeros((2, 2, 3))
    rho3 = np.zeros((2, 2, 2, 3))
    for b in range(nen):
        for p in range(2):
            x[p] += N[b] * xseg[b, p]
            rho1[0, p] += dN[b] * xseg[b, p]
            rho2[0, 0, p] += ddN[b] * xseg[b, p]
    rho1[1, 2] = 1.0
    for k in range(HIST_SIZE):
        hist_out[k] = 0.0
    hist_out[H_XI] = xi
    for p in range(3):
        hist_out[H_RHO + p] = x[p]
        hist_out[H_RHO_COV + p] = rho1[0, p]
    hist_out[H_FLAG] = 1.0
    if not is_active(g, lam_k, eps_n):
        return g, OPEN
    if mu == 0.0:
        return g, SLIP
    if hist[H_FLAG] == 0.0:
        return g, NEW
    a = rho1[0, 0] * rho1[0, 0] + rho1[0, 1] * rho1[0, 1]
    la = np.sqrt(a)
    # the old traction carried with the master: t' = T_n rho(xi_n) / a(xi_n), and d t' / d x_b
    No = np.empty(3)
    dNo = np.empty(3)
    ddNo = np.empty(3)
    segment_shapes(nen, hist[H_XI], No, dNo, ddNo)
    ro = np.zeros(3)
    for b in range(nen):
        for p in range(2):
            ro[p] += dNo[b] * xseg[b, p]
    ao = ro[0] * ro[0] + ro[1] * ro[1]
    if ao == 0.0:
        return g, NEW
    lo = np.sqrt(ao)
    tvec = np.zeros(3)
    for p in range(2):
        tvec[p] = hist[H_T] * ro[p] / ao
    # d t'_o / d x_bp = T_n N_b,xi(xi_n) / a_o (n_o n_p - t_o t_p), t = rho_o / |rho_o|, n = (t_y, -t_x)
    dtdx = np.zeros((3, m))
    to = (ro[0] / lo, ro[1] / lo)
    no = (to[1], -to[0])
    for b in range(nen):
        s = hist[H_T] * dNo[b] / ao
        for o in range(2):
            for p in range(2):
                dtdx[o, 3 * b + p] = s * (no[o] * no[p] - to[o] * to[p])
    # the extruded chart: blocks' shape factors (slave last), zeta = 0
    ar = np.zeros(nb)
    d1 = np.zeros((2, nb))
    d2 = np.zeros((2, 2, nb))
    for b in range(nen):
        ar[b] = -N[b]
        d1[0, b] = dN[b]
        d2[0, 0, b] = ddN[b]
    ar[nen] = 1.0
    r = np.zeros(3)
    r[0] = xs[0] - x[0]
    r[1] = xs[1] - x[1]
    nrm = np.zeros(3)
    nrm[0] = rho1[0, 1] / la
    nrm[1] = -rho1[0, 0] / la
    a_cov = np.zeros((2, 2))
    a_con = np.zeros((2, 2))
    a_cov[0, 0] = a
    a_cov[1, 1] = 1.0
    a_con[0, 0] = 1.0 / a
    a_con[1, 1] = 1.0
    dxi = np.zeros(2)
    dxi[0] = xi - hist[H_XI]
    T = np.zeros(2)
    Rf = np.zeros(m)
    Kf = np.zeros((m, m))
    state = friction_generic(nb, ar, d1, d2, r, nrm, g, rho1, rho2, rho3, a_cov, a_con, dxi, tvec, dtdx,
                             eps_n, eps_t, mu, Rf, Kf, T, new_friction_work(), lam_k)
    for s in range(m):
        if s % 3 == 2:
            continue
        R[s] += Rf[s]
        for q in range(m):
            if q % 3 != 2:
                K[s, q] += Kf[s, q]
    hist_out[H_T] = T[0]
    return g, state


def segment_friction(xseg, xs, xi, eps_n, eps_t, mu, hist, lam_k=0.0):
    """:func:`segment_friction_core` with its own outputs: (R, K, hist_out, g, state)."""
    xseg = np.ascontiguousarray(xseg, dtype=np.float64)
    nd = 3 * (xseg.shape[0] + 1)
    R, K, ho = np.zeros(nd), np.zeros((nd, nd)), np.zeros(HIST_SIZE)
    g, st = segment_friction_core(xseg, np.ascontiguousarray(xs, dtype=np.float64), float(xi), float(eps_n),
                                  float(eps_t), float(mu), float(lam_k), np.ascontiguousarray(hist, dtype=np.float64),
                                  R, K, ho)
    return R, K, ho, float(g), int(st)


def vertex_friction(xv, xs, du, t_n, sign: float, eps_n: float, eps_t: float, mu: float, lam_k: float = 0.0):
    """Coulomb friction of slave xs against the vertex xv between two segments (docs/theory.md section 28, "Friction
    at a vertex"): the normal n = (x_s - x_v) / g, g = sign |x_s - x_v|, the tangent tau = (-n_y, n_x); the trial
    tangential force T^tr = tau . (t_n - eps_T du) with ``du`` the slave's displacement relative to the vertex node
    since the last commit and ``t_n`` the committed traction vector; stick: T = T^tr below the cone mu N (N = -eps
    g_e), slip: T = mu N sign(T^tr). The friction part of the residual, R_v = T tau, R_s = -T tau, and its exact
    tangent, on (vertex, slave) as (6,) and (6, 6) (in-plane entries). Returns (R, K, T, tau, state); the normal part
    is :func:`.planar_kernels.vertex_core`'s."""
    R = np.zeros(6)
    K = np.zeros((6, 6))
    d = np.asarray(xs[:2], dtype=float) - np.asarray(xv[:2], dtype=float)
    dist = float(np.hypot(d[0], d[1]))
    if dist == 0.0:
        return R, K, 0.0, np.zeros(2), NEW
    g = sign * dist
    ge = g + lam_k / eps_n
    if not is_active(g, lam_k, eps_n):
        return R, K, 0.0, np.zeros(2), OPEN
    n = d / g
    tau = np.array([-n[1], n[0]])
    w = np.asarray(t_n[:2], dtype=float) - eps_t * np.asarray(du[:2], dtype=float)
    T_tr = float(tau @ w)
    N = -eps_n * ge
    if abs(T_tr) < mu * N * (1.0 - 1e-10):
        T, state = T_tr, STICK
        dT = -sign * float(n @ w) / dist * tau - eps_t * tau      # d T / d(x_s - x_v)
    else:
        sg = 1.0 if T_tr >= 0.0 else -1.0
        T, state = mu * N * sg, SLIP
        dT = -mu * eps_n * sg * n
    Kss = -np.outer(tau, dT) + T * sign / dist * np.outer(n, tau)  # d R_s / d(x_s - x_v), d tau = -sign n tau^T / |d|
    R[3:5] = -T * tau
    R[0:2] = T * tau
    K[3:5, 3:5] = Kss
    K[0:2, 0:2] = Kss
    K[3:5, 0:2] = -Kss
    K[0:2, 3:5] = -Kss
    return R, K, T, tau, state


def vertex_history(xseg, xi: float, traction: np.ndarray) -> np.ndarray:
    """The history to commit of a slave at a vertex: a history on the vertex's segment ``xseg`` at its end ``xi``
    (+-1) holding the traction vector ``traction`` (its component along the segment, covariantly), so that it moves
    on to either segment as a segment's history does."""
    rho, rc = _frame(xseg, xi)
    return make_history(xi, float(rc[:2] @ np.asarray(traction[:2], dtype=float)), rho, rc)


def traction_vector(history) -> np.ndarray:
    """The committed traction vector t_n = T_n rho_n / a_n of a history (zero without one)."""
    hist = np.asarray(history, dtype=np.float64)
    if hist[H_FLAG] == 0.0:
        return np.zeros(3)
    rc = hist[H_RHO_COV:H_RHO_COV + 3]
    return hist[H_T] * rc / float(rc @ rc)


# -- history: make, start, move across segments -----------------------------------------------------------------
def make_history(xi_n: float, traction: float = 0.0, rho_n=(0.0, 0.0, 0.0), rho_cov_n=(1.0, 0.0, 0.0)) -> np.ndarray:
    """A valid planar history: stick point xi_n, covariant traction T_n, the point x(xi_n) and rho(xi_n)."""
    h = np.zeros(HIST_SIZE)
    h[H_XI] = float(xi_n)
    h[H_RHO:H_RHO + 3] = rho_n
    h[H_RHO_COV:H_RHO_COV + 3] = rho_cov_n
    h[H_T] = float(traction)
    h[H_FLAG] = 1.0
    return h


def _frame(xseg, xi):
    x, r, _ = segment_point(xseg, float(xi))
    return np.array([x[0], x[1], 0.0]), np.array([r[0], r[1], 0.0])


def _regular_at(xseg, xi) -> bool:
    """Whether the segment's continuation is regular at xi: within TRANSFER_BAND of the segment, its metric at least
    _TRANSFER_METRIC of the centre's and rho on the centre's side."""
    if not (np.isfinite(xi) and abs(xi) <= 1.0 + TRANSFER_BAND):
        return False
    r0 = _frame(xseg, 0.0)[1]
    r1 = _frame(xseg, xi)[1]
    return bool(r1 @ r1 >= _TRANSFER_METRIC * (r0 @ r0) and r1 @ r0 > 0.0)


def _closest_on_segment(xseg, point) -> float:
    """xi in [-1, 1] of the point of the segment itself closest to ``point``."""
    best, best_d2 = None, np.inf
    xi, _, ok = project_on_segment(xseg, point, 0.0)
    if ok and abs(xi) <= 1.0:
        best, best_d2 = float(xi), float(np.sum((_frame(xseg, xi)[0][:2] - point[:2]) ** 2))
    for end in (-1.0, 1.0):
        d2 = float(np.sum((_frame(xseg, end)[0][:2] - point[:2]) ** 2))
        if d2 < best_d2:
            best, best_d2 = end, d2
    return best


def _anchored(xseg, point, t_vec, eps_t: float, xi0: float) -> np.ndarray:
    """The history on segment ``xseg`` of a tangential spring anchored at ``point`` holding the traction vector
    ``t_vec``: the anchor is the projection of ``point`` on the segment or its regular continuation near it; farther
    away the segment's own closest point rho_a, with the traction t_vec - eps_t (rho_a - point)."""
    xseg = np.ascontiguousarray(xseg, dtype=np.float64)
    point = np.ascontiguousarray(point, dtype=np.float64)
    xi, _, ok = project_on_segment(xseg, point, float(xi0))
    if not (ok and _regular_at(xseg, xi)):
        xi = _closest_on_segment(xseg, point)
    rho, rc = _frame(xseg, xi)
    if rc @ rc == 0.0:
        raise ValueError("degenerate master segment (zero length element at the point)")
    return make_history(xi, float(rc @ (t_vec - eps_t * (rho - point))), rho, rc)


def transfer_history(history, xseg, xi0: float = 0.0, eps_t: float = 0.0) -> np.ndarray:
    """Move a planar history to another segment ``xseg`` (its nodes in the configuration of the last commit): the old
    stick point rho_n anchored on the new segment (:func:`_anchored`) with the old traction vector
    t_n = T_n rho_n / a_n. ValueError where the new segment is degenerate."""
    hist = np.asarray(history, dtype=np.float64)
    if hist[H_FLAG] == 0.0:
        return hist.copy()
    return _anchored(xseg, hist[H_RHO:H_RHO + 3], traction_vector(hist), float(eps_t), xi0)


def start_history(xseg, xs, xi0: float, eps_t: float = 0.0) -> np.ndarray:
    """The history of a slave new to contact: its projection on segment ``xseg`` (committed configuration, the slave
    at ``xs`` there) as the stick point, zero traction; none (frictionless start, NEW) where the segment is
    degenerate."""
    if not (np.all(np.isfinite(xseg)) and np.all(np.isfinite(xs)) and np.isfinite(xi0)):
        return np.zeros(HIST_SIZE)
    try:
        return _anchored(xseg, xs, np.zeros(3), float(eps_t), float(xi0))
    except (ValueError, np.linalg.LinAlgError):
        return np.zeros(HIST_SIZE)
