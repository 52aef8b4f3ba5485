"""Compiled J2 return mapping in the logarithmic strain space: constants, hardening, ``j2_response``.

The formulation, the params and history layouts: :mod:`covcontact.materials.plasticity` and docs/theory.md,
section 12.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .logstrain import _dd1, _dd2, _eigh3

#: kind code of the J2 material (SVK = 0, NEO_HOOKE = 1 in covcontact.materials.hyperelastic)
J2 = 2
#: history length per material point
NHIST = 15
#: params length of the fixed part (every law); the table law appends its points after it (P_TAB_N)
NPARAMS = 36

# history indices
H_EP = 0
H_ALPHA = 6
H_BETA = 7
H_WP = 13
H_FLAG = 14

# params indices
P_E, P_NU, P_LAMBDA, P_MU, P_BULK = 0, 1, 2, 3, 4
P_LAW, P_SY0, P_H = 5, 6, 7
P_SWIFT_K, P_SWIFT_EPS0, P_SWIFT_N = 8, 9, 10
P_VOCE_SINF, P_VOCE_DELTA = 11, 12
P_HKIN = 13
P_HILL = 14
P_HILL_COEF = 15
P_Q3 = 21
P_P = 30
# table law only: params[P_TAB_N] = n points, then strains params[P_TAB:P_TAB + n], stresses after them
P_TAB_N = NPARAMS
P_TAB = NPARAMS + 1

LAW_LINEAR, LAW_SWIFT, LAW_VOCE, LAW_TABLE = 0, 1, 2, 3

#: return mapping: relative residual tolerance and iteration limit
RM_TOL = 1e-13
RM_MAXIT = 60


@njit(cache=True)
def _table(params, alpha):
    """Piecewise-linear sigma_y(alpha) through the table's points and the slope of the segment that holds
    alpha (the right one at a point); constant, slope 0, from the last point on."""
    n = int(params[P_TAB_N])
    s0 = P_TAB + n
    last = n - 1
    if n == 1 or alpha >= params[P_TAB + last]:
        return params[s0 + last], 0.0
    # bisection for the segment lo: strain[lo] <= alpha < strain[lo + 1] (the first one below strain 0)
    lo = 0
    hi = last
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if params[P_TAB + mid] <= alpha:
            lo = mid
        else:
            hi = mid
    ea = params[P_TAB + lo]
    sa = params[s0 + lo]
    H = (params[s0 + lo + 1] - sa) / (params[P_TAB + lo + 1] - ea)
    return sa + H * (alpha - ea), H


@njit(cache=True, inline="always")
def _hardening(params, alpha):
    """sigma_y(alpha) and its slope h = d sigma_y / d alpha."""
    law = params[P_LAW]
    if law == LAW_LINEAR:
        H = params[P_H]
        return params[P_SY0] + H * alpha, H
    if law == LAW_SWIFT:
        x = params[P_SWIFT_EPS0] + alpha
        n = params[P_SWIFT_N]
        sy = params[P_SWIFT_K] * x ** n
        return sy, n * sy / x
    if law == LAW_TABLE:
        return _table(params, alpha)
    sy0 = params[P_SY0]
    ds = params[P_VOCE_SINF] - sy0
    delta = params[P_VOCE_DELTA]
    H = params[P_H]
    ex = math.exp(-delta * alpha)
    return sy0 + ds * (1.0 - ex) + H * alpha, ds * delta * ex + H


@njit(cache=True)
def j2_response(params, F, hist_n, hist, S, D):
    """``j2_response_h`` with H = F - I formed from F."""
    H = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            H[i, j] = F[i, j] - (1.0 if i == j else 0.0)
    return j2_response_h(params, F, H, hist_n, hist, S, D)


@njit(cache=True)
def j2_response_h(params, F, H, hist_n, hist, S, D):
    """Second Piola-Kirchhoff stress S (6,), algorithmic tangent D = dS/dE (6, 6) and trial history hist
    (NHIST,) at the deformation gradient F (3, 3) from the committed history hist_n (read only).

    Returns 0 ok, 1 det F <= 0 (S = D = 0, hist = hist_n), 2 return mapping did not converge (S, D and
    hist of the last iterate).
    """
    for k in range(NHIST):
        hist[k] = hist_n[k]
    detF = (F[0, 0] * (F[1, 1] * F[2, 2] - F[1, 2] * F[2, 1])
            - F[0, 1] * (F[1, 0] * F[2, 2] - F[1, 2] * F[2, 0])
            + F[0, 2] * (F[1, 0] * F[2, 1] - F[1, 1] * F[2, 0]))
    lam = params[P_LAMBDA]
    mu = params[P_MU]
    m2 = 2.0 * mu
    bulk = params[P_BULK]
    hkin = params[P_HKIN]
    sq2 = 1.4142135623730951
    isq2 = 0.7071067811865476

    # Green-Lagrange strain from the displacement gradient H (F = I + H; formed from the displacements, H keeps
    # every digit of a small strain) and its spectral decomposition
    h00 = H[0, 0]
    h11 = H[1, 1]
    h22 = H[2, 2]
    h01 = H[0, 1]
    h02 = H[0, 2]
    h10 = H[1, 0]
    h12 = H[1, 2]
    h20 = H[2, 0]
    h21 = H[2, 1]
    g00 = h00 + 0.5 * (h00 * h00 + h10 * h10 + h20 * h20)
    g11 = h11 + 0.5 * (h01 * h01 + h11 * h11 + h21 * h21)
    g22 = h22 + 0.5 * (h02 * h02 + h12 * h12 + h22 * h22)
    g01 = 0.5 * (h01 + h10 + h00 * h01 + h10 * h11 + h20 * h21)
    g12 = 0.5 * (h12 + h21 + h01 * h02 + h11 * h12 + h21 * h22)
    g02 = 0.5 * (h02 + h20 + h00 * h02 + h10 * h12 + h20 * h22)
    if not (detF > 0.0 and 1.0 + 2.0 * min(g00, min(g11, g22)) > 0.0):
        for I in range(6):
            S[I] = 0.0
            for J in range(6):
                D[I, J] = 0.0
        return 1

    # scratch (one allocation): w (3), V (3x3), R, M, X, Dt (6x6 each)
    buf = np.empty(156)
    w = buf[0:3]
    V = buf[3:12].reshape((3, 3))
    R = buf[12:48].reshape((6, 6))
    M = buf[48:84].reshape((6, 6))
    X = buf[84:120].reshape((6, 6))
    Dt = buf[120:156].reshape((6, 6))

    _eigh3(g00, g11, g22, g01, g12, g02, w, V)
    l0 = 1.0 + 2.0 * w[0]
    l1 = 1.0 + 2.0 * w[1]
    l2 = 1.0 + 2.0 * w[2]
    if not (l0 > 0.0 and l1 > 0.0 and l2 > 0.0):  # C not positive definite in floating point
        for I in range(6):
            S[I] = 0.0
            for J in range(6):
                D[I, J] = 0.0
        return 1
    e0 = 0.5 * math.log1p(2.0 * w[0])
    e1 = 0.5 * math.log1p(2.0 * w[1])
    e2 = 0.5 * math.log1p(2.0 * w[2])

    # divided differences of ln(x)/2: t_ab first, f_abc second (f_aaa = f''/2 = -1/(4 l_a^2))
    t00 = 0.5 / l0
    t11 = 0.5 / l1
    t22 = 0.5 / l2
    t01 = _dd1(l0, l1, e0, e1)
    t12 = _dd1(l1, l2, e1, e2)
    t02 = _dd1(l0, l2, e0, e2)
    f000 = -0.25 / (l0 * l0)
    f111 = -0.25 / (l1 * l1)
    f222 = -0.25 / (l2 * l2)
    f001 = _dd2(l0, l0, l1, t00, t01, t01)
    f002 = _dd2(l0, l0, l2, t00, t02, t02)
    f011 = _dd2(l1, l1, l0, t11, t01, t01)
    f112 = _dd2(l1, l1, l2, t11, t12, t12)
    f022 = _dd2(l2, l2, l0, t22, t02, t02)
    f122 = _dd2(l2, l2, l1, t22, t12, t12)
    f012 = _dd2(l0, l1, l2, t01, t12, t02)

    # Mandel rotation R: global Mandel = R principal Mandel (orthogonal); pairs 00 11 22 01 12 02
    for I in range(6):
        if I < 3:
            i = I
            j = I
            wi = 1.0
        elif I == 3:
            i = 0
            j = 1
            wi = sq2
        elif I == 4:
            i = 1
            j = 2
            wi = sq2
        else:
            i = 0
            j = 2
            wi = sq2
        R[I, 0] = wi * V[i, 0] * V[j, 0]
        R[I, 1] = wi * V[i, 1] * V[j, 1]
        R[I, 2] = wi * V[i, 2] * V[j, 2]
        R[I, 3] = wi * isq2 * (V[i, 0] * V[j, 1] + V[i, 1] * V[j, 0])
        R[I, 4] = wi * isq2 * (V[i, 1] * V[j, 2] + V[i, 2] * V[j, 1])
        R[I, 5] = wi * isq2 * (V[i, 0] * V[j, 2] + V[i, 2] * V[j, 0])

    # E_log (Mandel) = R [e0, e1, e2, 0, 0, 0]; trial elastic strain x, trial stress T
    ep0 = hist_n[0]
    ep1 = hist_n[1]
    ep2 = hist_n[2]
    ep3 = sq2 * hist_n[3]
    ep4 = sq2 * hist_n[4]
    ep5 = sq2 * hist_n[5]
    b0 = hist_n[7]
    b1 = hist_n[8]
    b2 = hist_n[9]
    b3 = sq2 * hist_n[10]
    b4 = sq2 * hist_n[11]
    b5 = sq2 * hist_n[12]
    alpha_n = hist_n[H_ALPHA]
    wp_n = hist_n[H_WP]
    x0 = R[0, 0] * e0 + R[0, 1] * e1 + R[0, 2] * e2 - ep0
    x1 = R[1, 0] * e0 + R[1, 1] * e1 + R[1, 2] * e2 - ep1
    x2 = R[2, 0] * e0 + R[2, 1] * e1 + R[2, 2] * e2 - ep2
    x3 = R[3, 0] * e0 + R[3, 1] * e1 + R[3, 2] * e2 - ep3
    x4 = R[4, 0] * e0 + R[4, 1] * e1 + R[4, 2] * e2 - ep4
    x5 = R[5, 0] * e0 + R[5, 1] * e1 + R[5, 2] * e2 - ep5
    ltr = lam * (x0 + x1 + x2)
    T0 = ltr + m2 * x0
    T1 = ltr + m2 * x1
    T2 = ltr + m2 * x2
    T3 = m2 * x3
    T4 = m2 * x4
    T5 = m2 * x5
    # z coordinates (Q^T) of the trial relative stress T - beta
    q00 = params[P_Q3 + 0]
    q01 = params[P_Q3 + 1]
    q02 = params[P_Q3 + 2]
    q10 = params[P_Q3 + 3]
    q11 = params[P_Q3 + 4]
    q12 = params[P_Q3 + 5]
    q20 = params[P_Q3 + 6]
    q21 = params[P_Q3 + 7]
    q22 = params[P_Q3 + 8]
    s0 = T0 - b0
    s1 = T1 - b1
    s2 = T2 - b2
    zt1 = q01 * s0 + q11 * s1 + q21 * s2
    zt2 = q02 * s0 + q12 * s1 + q22 * s2
    zt3 = T3 - b3
    zt4 = T4 - b4
    zt5 = T5 - b5
    p1 = params[P_P + 1]
    p2 = params[P_P + 2]
    p3 = params[P_P + 3]
    p4 = params[P_P + 4]
    p5 = params[P_P + 5]
    sb_tr = math.sqrt(p1 * zt1 * zt1 + p2 * zt2 * zt2 + p3 * zt3 * zt3 + p4 * zt4 * zt4 + p5 * zt5 * zt5)
    sy, hs = _hardening(params, alpha_n)
    is_vm = params[P_HILL] == 0.0

    status = 0
    # algorithmic dT/dE_log in z coordinates: diag(dz) + cc v v^T (elastic: diag(3K, 2mu, ..., 2mu))
    dz0 = 3.0 * bulk
    dz1 = m2
    dz2 = m2
    dz3 = m2
    dz4 = m2
    dz5 = m2
    cc = 0.0
    v1 = 0.0
    v2 = 0.0
    v3 = 0.0
    v4 = 0.0
    v5 = 0.0
    if sb_tr - sy > 1e-12 * sy:
        kap = m2 + 2.0 / 3.0 * hkin
        tol = RM_TOL * sb_tr
        conv = False
        s = 0.0
        if is_vm:
            # radial return: scalar Newton on delta_gamma, bracketed
            cr = 1.5 * kap
            dg = 0.0
            lo = 0.0
            hi = sb_tr / cr
            for _it in range(RM_MAXIT):
                sy, hs = _hardening(params, alpha_n + dg)
                r = sb_tr - cr * dg - sy
                if abs(r) <= tol:
                    conv = True
                    break
                if r > 0.0:
                    lo = dg
                else:
                    hi = dg
                dgn = dg + r / (cr + hs)
                if not (dgn > lo and dgn < hi):
                    dgn = 0.5 * (lo + hi)
                dg = dgn
            s = dg / (sb_tr - cr * dg)
        else:
            # Hill: scalar Newton on s = delta_gamma / sigma_bar, bracketed, for the residual
            # 1/sigma_bar(s) - 1/sigma_y(alpha_n + s sigma_bar(s)) (same root as sigma_bar - sigma_y)
            lo = 0.0
            hi = np.inf
            for _it in range(RM_MAXIT):
                a1 = 1.0 / (1.0 + kap * s * p1)
                a2 = 1.0 / (1.0 + kap * s * p2)
                a3 = 1.0 / (1.0 + kap * s * p3)
                a4 = 1.0 / (1.0 + kap * s * p4)
                a5 = 1.0 / (1.0 + kap * s * p5)
                z1 = zt1 * a1
                z2 = zt2 * a2
                z3 = zt3 * a3
                z4 = zt4 * a4
                z5 = zt5 * a5
                sb = math.sqrt(p1 * z1 * z1 + p2 * z2 * z2 + p3 * z3 * z3 + p4 * z4 * z4 + p5 * z5 * z5)
                sy, hs = _hardening(params, alpha_n + s * sb)
                r = sb - sy
                if abs(r) <= tol:
                    conv = True
                    break
                if r > 0.0:
                    lo = s
                else:
                    hi = s
                sbs = -kap * (p1 * p1 * z1 * z1 * a1 + p2 * p2 * z2 * z2 * a2 + p3 * p3 * z3 * z3 * a3
                              + p4 * p4 * z4 * z4 * a4 + p5 * p5 * z5 * z5 * a5) / sb
                # 1/sigma_bar is linear in s for von Mises: fast and monotone from s = 0
                rho = 1.0 / sb - 1.0 / sy
                drho = -sbs / (sb * sb) + hs * (sb + s * sbs) / (sy * sy)
                sn = s - rho / drho
                if not (sn > lo and sn < hi):
                    if hi < np.inf:
                        sn = 0.5 * (lo + hi)
                    else:
                        sn = 2.0 * s + 1.0 / (kap * p1)
                s = sn
        if not conv:
            status = 2
        a1 = 1.0 / (1.0 + kap * s * p1)
        a2 = 1.0 / (1.0 + kap * s * p2)
        a3 = 1.0 / (1.0 + kap * s * p3)
        a4 = 1.0 / (1.0 + kap * s * p4)
        a5 = 1.0 / (1.0 + kap * s * p5)
        z1 = zt1 * a1
        z2 = zt2 * a2
        z3 = zt3 * a3
        z4 = zt4 * a4
        z5 = zt5 * a5
        sb = math.sqrt(p1 * z1 * z1 + p2 * z2 * z2 + p3 * z3 * z3 + p4 * z4 * z4 + p5 * z5 * z5)
        dgam = s * sb
        sy, hs = _hardening(params, alpha_n + dgam)
        # plastic strain increment (Mandel) Q (s p z); T -= 2 mu dEp; beta += 2/3 H_kin dEp
        y1 = s * p1 * z1
        y2 = s * p2 * z2
        d0 = q01 * y1 + q02 * y2
        d1 = q11 * y1 + q12 * y2
        d2 = q21 * y1 + q22 * y2
        d3 = s * p3 * z3
        d4 = s * p4 * z4
        d5 = s * p5 * z5
        T0 -= m2 * d0
        T1 -= m2 * d1
        T2 -= m2 * d2
        T3 -= m2 * d3
        T4 -= m2 * d4
        T5 -= m2 * d5
        ck = 2.0 / 3.0 * hkin
        hist[0] = ep0 + d0
        hist[1] = ep1 + d1
        hist[2] = ep2 + d2
        hist[3] = (ep3 + d3) * isq2
        hist[4] = (ep4 + d4) * isq2
        hist[5] = (ep5 + d5) * isq2
        hist[H_ALPHA] = alpha_n + dgam
        hist[7] = b0 + ck * d0
        hist[8] = b1 + ck * d1
        hist[9] = b2 + ck * d2
        hist[10] = (b3 + ck * d3) * isq2
        hist[11] = (b4 + ck * d4) * isq2
        hist[12] = (b5 + ck * d5) * isq2
        hist[H_WP] = wp_n + T0 * d0 + T1 * d1 + T2 * d2 + T3 * d3 + T4 * d4 + T5 * d5
        hist[H_FLAG] = 1.0
        # consistent tangent in z coordinates
        dz1 = m2 * (1.0 - s * p1 * a1 * m2)
        dz2 = m2 * (1.0 - s * p2 * a2 * m2)
        dz3 = m2 * (1.0 - s * p3 * a3 * m2)
        dz4 = m2 * (1.0 - s * p4 * a4 * m2)
        dz5 = m2 * (1.0 - s * p5 * a5 * m2)
        v1 = m2 * p1 * a1 * z1
        v2 = m2 * p2 * a2 * z2
        v3 = m2 * p3 * a3 * z3
        v4 = m2 * p4 * a4 * z4
        v5 = m2 * p5 * a5 * z5
        sbs = -kap * (p1 * p1 * z1 * z1 * a1 + p2 * p2 * z2 * z2 * a2 + p3 * p3 * z3 * z3 * a3
                      + p4 * p4 * z4 * z4 * a4 + p5 * p5 * z5 * z5 * a5) / sb
        cc = (1.0 - hs * s) / (sb * (sbs - hs * (sb + s * sbs)))
    else:
        hist[H_FLAG] = 0.0

    # principal Mandel components of T: u = R^T T; S~ = P u with P_I = 2 t_I; S = R S~
    u0 = R[0, 0] * T0 + R[1, 0] * T1 + R[2, 0] * T2 + R[3, 0] * T3 + R[4, 0] * T4 + R[5, 0] * T5
    u1 = R[0, 1] * T0 + R[1, 1] * T1 + R[2, 1] * T2 + R[3, 1] * T3 + R[4, 1] * T4 + R[5, 1] * T5
    u2 = R[0, 2] * T0 + R[1, 2] * T1 + R[2, 2] * T2 + R[3, 2] * T3 + R[4, 2] * T4 + R[5, 2] * T5
    u3 = R[0, 3] * T0 + R[1, 3] * T1 + R[2, 3] * T2 + R[3, 3] * T3 + R[4, 3] * T4 + R[5, 3] * T5
    u4 = R[0, 4] * T0 + R[1, 4] * T1 + R[2, 4] * T2 + R[3, 4] * T3 + R[4, 4] * T4 + R[5, 4] * T5
    u5 = R[0, 5] * T0 + R[1, 5] * T1 + R[2, 5] * T2 + R[3, 5] * T3 + R[4, 5] * T4 + R[5, 5] * T5
    P0 = 2.0 * t00
    P1 = 2.0 * t11
    P2 = 2.0 * t22
    P3 = 2.0 * t01
    P4 = 2.0 * t12
    P5 = 2.0 * t02
    k0 = P0 * u0
    k1 = P1 * u1
    k2 = P2 * u2
    k3 = P3 * u3
    k4 = P4 * u4
    k5 = P5 * u5
    for I in range(6):
        sv = R[I, 0] * k0 + R[I, 1] * k1 + R[I, 2] * k2 + R[I, 3] * k3 + R[I, 4] * k4 + R[I, 5] * k5
        S[I] = sv if I < 3 else sv * isq2

    # C~ = R^T C_alg R in principal Mandel coordinates, C_alg = Q (diag(dz) + cc v v^T) Q^T;
    # von Mises: Q diag(dz) Q^T is isotropic (3K on the hydrostatic mode, dz1 on the others)
    for I in range(6):
        M[I, 0] = R[0, I] * q00 + R[1, I] * q10 + R[2, I] * q20
        M[I, 1] = R[0, I] * q01 + R[1, I] * q11 + R[2, I] * q21
        M[I, 2] = R[0, I] * q02 + R[1, I] * q12 + R[2, I] * q22
        M[I, 3] = R[3, I]
        M[I, 4] = R[4, I]
        M[I, 5] = R[5, I]
    for I in range(6):
        Dt[0, I] = M[I, 1] * v1 + M[I, 2] * v2 + M[I, 3] * v3 + M[I, 4] * v4 + M[I, 5] * v5  # (M v)_I
    Dt[1, 0] = P0
    Dt[1, 1] = P1
    Dt[1, 2] = P2
    Dt[1, 3] = P3
    Dt[1, 4] = P4
    Dt[1, 5] = P5
    if is_vm:
        iso_v = (dz0 - dz1) / 3.0
        for I in range(6):
            ci = cc * Dt[0, I]
            for J in range(6):
                X[I, J] = ci * Dt[0, J]
            X[I, I] += dz1
        for I in range(3):
            for J in range(3):
                X[I, J] += iso_v
    else:
        for I in range(6):
            mi0 = M[I, 0] * dz0
            mi1 = M[I, 1] * dz1
            mi2 = M[I, 2] * dz2
            mi3 = M[I, 3] * dz3
            mi4 = M[I, 4] * dz4
            mi5 = M[I, 5] * dz5
            ci = cc * Dt[0, I]
            for J in range(6):
                X[I, J] = (mi0 * M[J, 0] + mi1 * M[J, 1] + mi2 * M[J, 2] + mi3 * M[J, 3] + mi4 * M[J, 4]
                           + mi5 * M[J, 5] + ci * Dt[0, J])
    # D~ = P C~ P + G: material part, then the geometric part T : L in principal Mandel coordinates,
    # G_ijkl = 2 [f_ijl (d_jk T_il + d_ik T_jl) + f_ijk (d_jl T_ik + d_il T_jk)] times w_I w_J
    for I in range(6):
        pi = Dt[1, I]
        for J in range(6):
            M[I, J] = pi * X[I, J] * Dt[1, J]
    M[0, 0] += 8.0 * f000 * u0
    M[1, 1] += 8.0 * f111 * u1
    M[2, 2] += 8.0 * f222 * u2
    M[3, 3] += 4.0 * (f011 * u1 + f001 * u0)
    M[4, 4] += 4.0 * (f122 * u2 + f112 * u1)
    M[5, 5] += 4.0 * (f022 * u2 + f002 * u0)
    g = 4.0 * f001 * u3
    M[0, 3] += g
    M[3, 0] += g
    g = 4.0 * f011 * u3
    M[1, 3] += g
    M[3, 1] += g
    g = 4.0 * f112 * u4
    M[1, 4] += g
    M[4, 1] += g
    g = 4.0 * f122 * u4
    M[2, 4] += g
    M[4, 2] += g
    g = 4.0 * f002 * u5
    M[0, 5] += g
    M[5, 0] += g
    g = 4.0 * f022 * u5
    M[2, 5] += g
    M[5, 2] += g
    c4 = 2.0 * sq2 * f012
    g = c4 * u5
    M[3, 4] += g
    M[4, 3] += g
    g = c4 * u4
    M[3, 5] += g
    M[5, 3] += g
    g = c4 * u3
    M[4, 5] += g
    M[5, 4] += g
    # back to the global basis: D' = R D~ R^T, then engineering Voigt D = D' / (w_I w_J)
    for I in range(6):
        for K in range(6):
            X[I, K] = (R[I, 0] * M[0, K] + R[I, 1] * M[1, K] + R[I, 2] * M[2, K] + R[I, 3] * M[3, K]
                       + R[I, 4] * M[4, K] + R[I, 5] * M[5, K])
    for I in range(6):
        wi = 1.0 if I < 3 else isq2
        for J in range(I, 6):
            wj = 1.0 if J < 3 else isq2
            d = (X[I, 0] * R[J, 0] + X[I, 1] * R[J, 1] + X[I, 2] * R[J, 2] + X[I, 3] * R[J, 3]
                 + X[I, 4] * R[J, 4] + X[I, 5] * R[J, 5]) * (wi * wj)
            D[I, J] = d
            D[J, I] = d
    return status
