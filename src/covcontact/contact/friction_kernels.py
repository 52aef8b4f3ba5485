"""Compiled covariant Coulomb friction element (docs/theory.md section 7; Konyukhov & Schweizerhof 2005).

One slave node against one quad4/quad9 master facet (dofs: master nodes, then the slave) or an analytic
rigid surface (slave dofs only). Internal-force convention, penalty regularisation in both directions.

Kinematics (same facet): dxi = xi - xi_n. Trial traction (covariant components), with the old traction
convected with the master, t' = T^(n)_k a^kl(xi_n) rho_l(xi_n) (current configuration at the old point):

    T^tr_i = t' . rho_i - eps_T a_ij dxi^j,     ||T|| = sqrt(T_i a^ij T_j),     kappa = mu eps_N |g|
    stick: ||T^tr|| < kappa (1 - 1e-10), T = T^tr;   slip: T = kappa T^tr / ||T^tr||   (on the cone: slip)

This is the stored form T_k^(n) a_(n)^kl (rho_l^(n) . rho_i) of docs/theory.md section 7 with the old base
vectors taken at the same material point of the master now instead of stored: equal for a master at rest,
and objective (a rigid motion of the pair leaves T unchanged), which the stored form is not (|T^tr| drops
by 4 % for a 0.3 rad rotation about an in-plane axis). Rigid analytic surfaces: t' is the old traction
carried with the body.

Residual (variational; for T^(n) = 0 in stick it is exactly the gradient of 1/2 eps_T a_ij dxi^i dxi^j):

    R = eps_N g A^T n  -  T_k xi'^k  +  1/(2 eps_T) tau^i tau^j D(a_ij),     tau^i = a^ij T_j

with D the total derivative d/dx and xi'^k = D xi^k = c^kl (A^T rho_l - g A_,l^T n) from the projection
(implicit function theorem), c_ij = a_ij - g h_ij.
To leading order the friction part is -A^T (a^ij T_j rho_i): the slave feels t = a^ij T_j rho_i, and the
stick stiffness is +eps_T a^ij A^T (rho_i (x) rho_j) A; the extra terms are O(g) and O(dxi) (2-4 % at
g = -0.03, |dxi| = 0.06) and make the stick tangent (T^(n) = 0) exactly symmetric.

Tangent: exact. Written on z = (xi^1, xi^2, x): with G(z) = -T_k xi^k - ||T||^2 / (2 eps_T) at frozen T,
R_T = P^T grad G with P = [xi'; I] and F_i(z) = (x_s - rho) . rho_i, so
K_T = P^T (hess G + mu^i hess F_i) P + (dR_T / dT) (dT / dx),  mu^i = c^ik dG/dxi^k.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from covcontact.contact.element import CASE_EXACT, element_core, new_work
from covcontact.contact.geometry import facet_geometry
from covcontact.contact.laws import c_inverse, is_active, normal_pressure
from covcontact.fem.shapes import IDX, lagrange1d

#: element states
OPEN = 0
STICK = 1
SLIP = 2
NEW = 3  # in contact without friction history (flag 0): frictionless in this evaluation
#: relative band of the slip test: a trial traction within it of the Coulomb limit slips
CONE_TOL = 1e-10

#: history layout (floats per slave node)
H_XI = 0  # xi_n (2)
H_RHO = 2  # rho_n (3): old contact point (analytic: in the surface's body frame)
H_RHO_COV = 5  # rho_1^(n), rho_2^(n) (6) (analytic: body frame)
H_T = 11  # T^(n)_1, T^(n)_2 (covariant)
H_FLAG = 13  # 1.0: valid history, 0.0: none
HIST_SIZE = 14

_MMAX = 30  # 3 (9 + 1)
_DMAX = 32
_CHUNK = 16
_IDX9 = IDX["quad9"]


@njit(cache=True)
def new_friction_work():
    """Scratch arrays of the friction part (sized for quad9)."""
    M = _MMAX
    D = _DMAX
    return (
        np.empty((D, 3)),  # 0 grad r
        np.empty((2, D, 3)),  # 1 grad rho_i
        np.empty((3, D)),  # 2 grad a_00, a_01, a_11
        np.empty((2, D)),  # 3 grad T^tr_i
        np.empty((2, M)),  # 4 xi'
        np.empty((2, M)),  # 5 D T^tr
        np.empty((2, M)),  # 6 D T
        np.empty((3, M)),  # 7 D a
        np.empty((2, D)),  # 8 v_i = tau^j grad a_ij
        np.empty((2, M)),  # 9 D v_i
        np.empty((D, 3)),  # 10 grad w
        np.empty((D, 3)),  # 11 grad u
        np.empty((D, D)),  # 12 H
        np.empty((D, M)),  # 13 H P
        np.empty((2, 2)),  # 14 c^ij
        np.empty(M),  # 15 D g
        np.empty(3),  # 16 w = mu^i rho_i
        np.empty(3),  # 17 u = tau^i rho_i
    )


@njit(cache=True)
def inv2(A, out):
    """Inverse of a 2 x 2 matrix into out (not in place)."""
    det = A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]
    out[0, 0] = A[1, 1] / det
    out[1, 1] = A[0, 0] / det
    out[0, 1] = -A[0, 1] / det
    out[1, 0] = -A[1, 0] / det


@njit(cache=True)
def _reduce(f, xp, m, out):
    """out = P^T f: the total derivative d/dx of a function with z-gradient f."""
    for s in range(m):
        out[s] = f[2 + s] + xp[0, s] * f[0] + xp[1, s] * f[1]


@njit(cache=True)
def friction_generic(nb, ar, d1, d2, r, nrm, g, rho1, rho2, rho3, a_cov, a_con, dxi, tvec, dtdx,
                     eps_n, eps_t, mu, R_out, K_out, T_out, fw, lam_k=0.0):
    """Add the friction residual and exact tangent to R_out, K_out; return STICK or SLIP.

    Dofs: nb blocks of 3, m = 3 nb. Per block b: d r / d x_b = ar[b] I, d rho_i / d x_b = d1[i, b] I,
    d rho_ij / d x_b = d2[i, j, b] I. r = x_s - rho = g n; rho1, rho2, rho3: derivatives of rho by xi
    up to third order; dxi = xi - xi_n; tvec: transported old traction t' (3,) with d t'/dx = dtdx (3, m).
    T_out (2,) receives the covariant traction T_i. Requires g <= 0, eps_t > 0.
    """
    gr, grho, ga, gT, xp, DTtr, DT, Da, v, Dv, gw, gu, H, HP, cc, Dg, w, u = fw
    m = 3 * nb
    d = m + 2
    # c_ij = a_ij - r . rho_ij and its inverse (a^ij on the focal surface)
    for i in range(2):  # g h_ij = r . rho_ij, held in cc until c_inverse overwrites it
        for j in range(2):
            cc[i, j] = r[0] * rho2[i, j, 0] + r[1] * rho2[i, j, 1] + r[2] * rho2[i, j, 2]
    c_inverse(a_cov, a_con, cc, 1.0, cc)
    # z-gradients of r and rho_i
    for z in range(d):
        for q in range(3):
            gr[z, q] = 0.0
            grho[0, z, q] = 0.0
            grho[1, z, q] = 0.0
    for k in range(2):
        for q in range(3):
            gr[k, q] = -rho1[k, q]
            grho[0, k, q] = rho2[0, k, q]
            grho[1, k, q] = rho2[1, k, q]
    for b in range(nb):
        for p in range(3):
            z = 2 + 3 * b + p
            gr[z, p] = ar[b]
            grho[0, z, p] = d1[0, b]
            grho[1, z, p] = d1[1, b]
    # xi' = c^-1 F_,x with F_i,x = ar_b rho_i + d1_ib r
    for b in range(nb):
        for p in range(3):
            s = 3 * b + p
            f0 = ar[b] * rho1[0, p] + d1[0, b] * r[p]
            f1 = ar[b] * rho1[1, p] + d1[1, b] * r[p]
            xp[0, s] = cc[0, 0] * f0 + cc[0, 1] * f1
            xp[1, s] = cc[1, 0] * f0 + cc[1, 1] * f1
            Dg[s] = ar[b] * nrm[p]
    # grad a_ij (ij = 00, 01, 11)
    for ij in range(3):
        i = 0 if ij < 2 else 1
        j = 0 if ij == 0 else 1
        for z in range(d):
            s = 0.0
            for q in range(3):
                s += grho[i, z, q] * rho1[j, q] + rho1[i, q] * grho[j, z, q]
            ga[ij, z] = s
        _reduce(ga[ij], xp, m, Da[ij])
    # trial traction and its gradient
    Ttr0 = 0.0
    Ttr1 = 0.0
    for q in range(3):
        Ttr0 += tvec[q] * rho1[0, q]
        Ttr1 += tvec[q] * rho1[1, q]
    Ttr0 -= eps_t * (a_cov[0, 0] * dxi[0] + a_cov[0, 1] * dxi[1])
    Ttr1 -= eps_t * (a_cov[1, 0] * dxi[0] + a_cov[1, 1] * dxi[1])
    for i in range(2):
        for z in range(d):
            s = 0.0
            for q in range(3):
                s += tvec[q] * grho[i, z, q]
            s -= eps_t * (ga[i, z] * dxi[0] + ga[i + 1, z] * dxi[1])
            if z >= 2:
                for o in range(3):
                    s += dtdx[o, z - 2] * rho1[i, o]
            gT[i, z] = s
        gT[i, 0] -= eps_t * a_cov[i, 0]
        gT[i, 1] -= eps_t * a_cov[i, 1]
        _reduce(gT[i], xp, m, DTtr[i])
    # return mapping
    ta0 = a_con[0, 0] * Ttr0 + a_con[0, 1] * Ttr1
    ta1 = a_con[1, 0] * Ttr0 + a_con[1, 1] * Ttr1
    nu = np.sqrt(max(Ttr0 * ta0 + Ttr1 * ta1, 0.0))
    kappa = -mu * normal_pressure(g, lam_k, eps_n)  # Coulomb limit from the normal pressure
    # a trial traction on the cone to round-off (a slave that slid in the last step, not moved yet) slips: the
    # bare test nu <= kappa decides it by round-off, and with it the tangent, so the path would depend on the
    # order of sums (serial against distributed runs)
    if nu == 0.0 or nu < kappa * (1.0 - CONE_TOL):
        state = STICK
        T0 = Ttr0
        T1 = Ttr1
        for s in range(m):
            DT[0, s] = DTtr[0, s]
            DT[1, s] = DTtr[1, s]
    else:
        state = SLIP
        T0 = kappa * Ttr0 / nu
        T1 = kappa * Ttr1 / nu
        for s in range(m):
            dnu = (ta0 * DTtr[0, s] + ta1 * DTtr[1, s]
                   - 0.5 * (ta0 * ta0 * Da[0, s] + 2.0 * ta0 * ta1 * Da[1, s] + ta1 * ta1 * Da[2, s])) / nu
            dk = -mu * eps_n * Dg[s]
            DT[0, s] = dk * Ttr0 / nu + (kappa * DTtr[0, s] - T0 * dnu) / nu
            DT[1, s] = dk * Ttr1 / nu + (kappa * DTtr[1, s] - T1 * dnu) / nu
    T_out[0] = T0
    T_out[1] = T1
    tau0 = a_con[0, 0] * T0 + a_con[0, 1] * T1
    tau1 = a_con[1, 0] * T0 + a_con[1, 1] * T1
    # v_i = tau^j grad a_ij
    for z in range(d):
        v[0, z] = tau0 * ga[0, z] + tau1 * ga[1, z]
        v[1, z] = tau0 * ga[1, z] + tau1 * ga[2, z]
    _reduce(v[0], xp, m, Dv[0])
    _reduce(v[1], xp, m, Dv[1])
    h = 0.5 / eps_t
    for s in range(m):
        R_out[s] += -T0 * xp[0, s] - T1 * xp[1, s] + h * (tau0 * Dv[0, s] + tau1 * Dv[1, s])
    # multipliers mu^i = c^ik dG/dxi^k, dG/dxi^k = -T_k + h tau^i v_i[k]
    G0 = -T0 + h * (tau0 * v[0, 0] + tau1 * v[1, 0])
    G1 = -T1 + h * (tau0 * v[0, 1] + tau1 * v[1, 1])
    m0 = cc[0, 0] * G0 + cc[0, 1] * G1
    m1 = cc[1, 0] * G0 + cc[1, 1] * G1
    for q in range(3):
        w[q] = m0 * rho1[0, q] + m1 * rho1[1, q]
        u[q] = tau0 * rho1[0, q] + tau1 * rho1[1, q]
    for z in range(d):
        for q in range(3):
            gw[z, q] = m0 * grho[0, z, q] + m1 * grho[1, z, q]
            gu[z, q] = tau0 * grho[0, z, q] + tau1 * grho[1, z, q]
    # H = mu^i hess F_i + hess G (first-derivative products)
    ie = 1.0 / eps_t
    for z in range(d):
        for y in range(d):
            s = 0.0
            for q in range(3):
                s += gr[z, q] * gw[y, q] + gw[z, q] * gr[y, q] + ie * gu[z, q] * gu[y, q]
            s -= ie * (a_con[0, 0] * v[0, z] * v[0, y] + a_con[0, 1] * (v[0, z] * v[1, y] + v[1, z] * v[0, y])
                       + a_con[1, 1] * v[1, z] * v[1, y])
            H[z, y] = s
    # second-derivative terms: r . hess w + w . hess r + (1/eps_t) u . hess u (xi-xi and xi-x blocks)
    tt = (m0, m1)
    ta = (tau0, tau1)
    for k in range(2):
        for l in range(2):
            s = 0.0
            for i in range(2):
                for q in range(3):
                    s += (tt[i] * r[q] + ie * ta[i] * u[q]) * rho3[i, k, l, q]
            for q in range(3):
                s -= w[q] * rho2[k, l, q]
            H[k, l] += s
        for b in range(nb):
            cr = m0 * d2[0, k, b] + m1 * d2[1, k, b]
            cu = ie * (tau0 * d2[0, k, b] + tau1 * d2[1, k, b])
            for p in range(3):
                val = cr * r[p] - d1[k, b] * w[p] + cu * u[p]
                z = 2 + 3 * b + p
                H[k, z] += val
                H[z, k] += val
    # K += P^T H P + B DT,  B[:, k] = -xi'^k + (1/eps_t) a^ki D v_i
    for z in range(d):
        for t in range(m):
            HP[z, t] = H[z, 2 + t] + H[z, 0] * xp[0, t] + H[z, 1] * xp[1, t]
    for s in range(m):
        b0 = -xp[0, s] + ie * (a_con[0, 0] * Dv[0, s] + a_con[0, 1] * Dv[1, s])
        b1 = -xp[1, s] + ie * (a_con[1, 0] * Dv[0, s] + a_con[1, 1] * Dv[1, s])
        for t in range(m):
            K_out[s, t] += (HP[2 + s, t] + xp[0, s] * HP[0, t] + xp[1, s] * HP[1, t]
                            + b0 * DT[0, t] + b1 * DT[1, t])
    return state


@njit(cache=True)
def third_derivs(nen, xi1, xi2, d3N):
    """Third derivatives N_a,ijk (nen, 2, 2, 2) of quad4 (all zero) / quad9 shape functions."""
    for a in range(nen):
        for i in range(2):
            for j in range(2):
                for k in range(2):
                    d3N[a, i, j, k] = 0.0
        if nen == 9:
            _, da, dda = lagrange1d(2, _IDX9[a, 0], xi1)
            _, db, ddb = lagrange1d(2, _IDX9[a, 1], xi2)
            v112 = dda * db
            v122 = da * ddb
            d3N[a, 0, 0, 1] = v112
            d3N[a, 0, 1, 0] = v112
            d3N[a, 1, 0, 0] = v112
            d3N[a, 0, 1, 1] = v122
            d3N[a, 1, 0, 1] = v122
            d3N[a, 1, 1, 0] = v122


@njit(cache=True)
def new_facet_work():
    """Scratch of ``friction_core``: (element work, friction work, facet arrays)."""
    nb = 10
    geo = (
        np.empty(9), np.empty((9, 2)), np.empty((9, 2, 2)), np.empty((9, 2, 2, 2)),  # 0-3 N, dN, ddN, d3N
        np.empty(3), np.empty((2, 3)), np.empty((2, 2)), np.empty((2, 2)), np.empty(3), np.empty((2, 2)),
        np.empty((2, 2, 3)), np.empty((2, 2, 2, 3)),  # 10, 11 rho2, rho3
        np.empty(9), np.empty((9, 2)), np.empty((9, 2, 2)),  # 12-14 N, dN, ddN at xi_n
        np.empty(3), np.empty((2, 3)), np.empty((2, 2)), np.empty((2, 2)), np.empty(3), np.empty((2, 2)),
        np.empty(nb), np.empty((2, nb)), np.empty((2, 2, nb)),  # 21-23 ar, d1, d2
        np.empty(3), np.empty(3), np.empty((3, 3 * nb)), np.empty(2), np.empty(2), np.empty((1, 1, 1)),
    )
    return new_work(), new_friction_work(), geo


@njit(cache=True)
def friction_core(xyz, xs, xi1, xi2, eps_n, eps_t, mu, hist, R_out, K_out, hist_out, work, lam_k=0.0):
    """Residual and exact tangent (normal + friction) of one slave node against one facet.

    Args:
        xyz: (n, 3) facet nodes (n = 4, 9). xs: (3,) slave. xi1, xi2: converged projection.
        eps_n, eps_t: penalties (already weighted). mu: friction coefficient.
        hist: (HIST_SIZE,) history of the last converged step on this facet.
        R_out: (3(n+1),) out. K_out: (3(n+1), 3(n+1)) out. hist_out: (HIST_SIZE,) out, the history
            to commit when the step converges.
        work: tuple from ``new_facet_work``.

    Returns:
        (g, state); g = +inf at a degenerate facet point (outputs zero, hist_out = hist).
    """
    ew, fw, geo = work
    N, dN, ddN, d3N, rho, rho1, a_cov, a_con, nrm, h_cov, rho2, rho3 = geo[:12]
    No, dNo, ddNo, rhoo, rho1o, ao, aoi, nrmo, ho = geo[12:21]
    ar, d1, d2, r, tvec, dtdx, dxi, T, dummy = geo[21:]
    nen = xyz.shape[0]
    nb = nen + 1
    # np.int64 / np.bool_ constants are run-time values to numba: one compiled element_core for all callers
    exact, no = np.int64(CASE_EXACT), np.bool_(False)
    g = element_core(xyz, xs, xi1, xi2, eps_n, exact, no, R_out, K_out, dummy, ew, lam_k)
    for k in range(HIST_SIZE):
        hist_out[k] = hist[k]
    if g == np.inf:
        return g, OPEN
    facet_geometry(xyz, xi1, xi2, N[:nen], dN[:nen], ddN[:nen], rho, rho1, a_cov, a_con, nrm, h_cov)
    third_derivs(nen, xi1, xi2, d3N)
    for p in range(3):
        r[p] = xs[p] - rho[p]
        for i in range(2):
            for j in range(2):
                s = 0.0
                for k in range(2):
                    s3 = 0.0
                    for a in range(nen):
                        s3 += d3N[a, i, j, k] * xyz[a, p]
                    rho3[i, j, k, p] = s3
                for a in range(nen):
                    s += ddN[a, i, j] * xyz[a, p]
                rho2[i, j, p] = s
    hist_out[H_XI] = xi1
    hist_out[H_XI + 1] = xi2
    for p in range(3):
        hist_out[H_RHO + p] = rho[p]
        hist_out[H_RHO_COV + p] = rho1[0, p]
        hist_out[H_RHO_COV + 3 + p] = rho1[1, p]
    hist_out[H_T] = 0.0
    hist_out[H_T + 1] = 0.0
    hist_out[H_FLAG] = 1.0
    if not is_active(g, lam_k, eps_n):
        return g, OPEN
    if mu == 0.0:
        return g, SLIP
    if hist[H_FLAG] == 0.0:
        return g, NEW
    # old traction convected with the master: t' = T_k a^kl rho_l at xi_n (current configuration); a degenerate frame
    # there (a fold of the facet's continuation: transfer_history keeps xi_n off them) leaves the element new
    if facet_geometry(xyz, hist[H_XI], hist[H_XI + 1], No[:nen], dNo[:nen], ddNo[:nen], rhoo, rho1o,
                      ao, aoi, nrmo, ho) == 0.0:
        return g, NEW
    Tu0 = aoi[0, 0] * hist[H_T] + aoi[0, 1] * hist[H_T + 1]
    Tu1 = aoi[1, 0] * hist[H_T] + aoi[1, 1] * hist[H_T + 1]
    for p in range(3):
        tvec[p] = Tu0 * rho1o[0, p] + Tu1 * rho1o[1, p]
    # d t'_o / d x_bp = s_b no_o no_p - q_b,o t'_p, s_b = T^l N_b,l(xi_n), q_b = rho^i N_b,i(xi_n)
    for b in range(nb):
        if b < nen:
            s_b = Tu0 * dNo[b, 0] + Tu1 * dNo[b, 1]
            w0 = aoi[0, 0] * dNo[b, 0] + aoi[0, 1] * dNo[b, 1]
            w1 = aoi[1, 0] * dNo[b, 0] + aoi[1, 1] * dNo[b, 1]
        else:
            s_b = 0.0
            w0 = 0.0
            w1 = 0.0
        for o in range(3):
            q_o = w0 * rho1o[0, o] + w1 * rho1o[1, o]
            for p in range(3):
                dtdx[o, 3 * b + p] = s_b * nrmo[o] * nrmo[p] - q_o * tvec[p]
    for b in range(nb):
        if b < nen:
            ar[b] = -N[b]
            for i in range(2):
                d1[i, b] = dN[b, i]
                for j in range(2):
                    d2[i, j, b] = ddN[b, i, j]
        else:
            ar[b] = 1.0
            for i in range(2):
                d1[i, b] = 0.0
                for j in range(2):
                    d2[i, j, b] = 0.0
    dxi[0] = xi1 - hist[H_XI]
    dxi[1] = xi2 - hist[H_XI + 1]
    state = friction_generic(nb, ar, d1, d2, r, nrm, g, rho1, rho2, rho3, a_cov, a_con, dxi, tvec,
                             dtdx, eps_n, eps_t, mu, R_out, K_out, T, fw, lam_k)
    hist_out[H_T] = T[0]
    hist_out[H_T + 1] = T[1]
    return g, state


@njit(cache=True)
def friction_element(xyz, xs, xi, eps_n, eps_t, mu, hist, R_out, K_out, hist_out, lam_k=0.0):
    """Single-pair entry point of ``friction_core`` (own scratch); xi: (2,). Returns (g, state)."""
    return friction_core(xyz, xs, xi[0], xi[1], eps_n, eps_t, mu, hist, R_out, K_out, hist_out,
                         new_facet_work(), lam_k)


@njit(cache=True, parallel=True)
def friction_batch(x_nodes, facet_conn, slave_ids, xi, eps_n, eps_t, mu, hist, R_out, K_out, hist_out,
                   g_out, state_out, lam_k):
    """``friction_core`` over npair slave-facet pairs of one facet type, parallel over pairs.

    Args: x_nodes (nnode, 3); facet_conn (npair, n) int64; slave_ids (npair,) int64; xi (npair, 2)
    converged projections; eps_n, eps_t, mu, lam_k (npair,) (lam_k: Uzawa multipliers, zeros for the
    penalty); hist (npair, HIST_SIZE). Out: R_out (npair, m),
    K_out (npair, m, m), hist_out (npair, HIST_SIZE), g_out (npair,), state_out (npair,) int64.
    """
    npair, nen = facet_conn.shape
    nchunk = (npair + _CHUNK - 1) // _CHUNK
    for c in prange(nchunk):
        work = new_facet_work()
        xyz = np.empty((nen, 3))
        xs = np.empty(3)
        lo = c * _CHUNK
        hi = min(npair, lo + _CHUNK)
        for k in range(lo, hi):
            for a in range(nen):
                for p in range(3):
                    xyz[a, p] = x_nodes[facet_conn[k, a], p]
            for p in range(3):
                xs[p] = x_nodes[slave_ids[k], p]
            g, st = friction_core(xyz, xs, xi[k, 0], xi[k, 1], eps_n[k], eps_t[k], mu[k], hist[k], R_out[k],
                                  K_out[k], hist_out[k], work, lam_k[k])
            g_out[k] = g
            state_out[k] = st
