"""Compiled kernels of the solid-shell elements (formulation in :mod:`covcontact.elements.solidshell`).

Per element: the covariant base vectors G_i (reference) and g_i (current) are evaluated at a list of
points (the Gauss points first, then the ANS tying points); there the compatible covariant strains
E_ij = 1/2 (g_i . g_j - G_i . G_j) are formed. At Gauss point g every covariant component c is an
interpolation sum_k w_gck E_c(p_k) over its tying points (just the Gauss point itself for an untied
component), turned into Cartesian Voigt strain by the local Jacobian, E_cart = T_g E_nat. The enhanced
strain Gamma_g alpha (EAS, natural modes mapped with the centre Jacobian and scaled by det J_c / det J_g)
is added, the EAS parameters alpha are solved per element by a local Newton, and the tangent is
condensed: K = K_uu - K_ua H^-1 K_au.

Voigt order of natural and Cartesian strain: (rr, ss, tt, rs, st, rt) and (11, 22, 33, 12, 23, 13),
engineering shear (2 E_ij), the order of :mod:`covcontact.materials`.

Materials with history (J2): every evaluation of the local EAS Newton calls ``material_update`` at each
Gauss point with an F such that F^T F = I + 2 E (E the enhanced strain) from the element's committed
history ``hne`` (ng, nh) (a copy made before anything is written) and writes the trial history ``hist``
(ng, nh); the last evaluation is at the solved alpha, so history, S and the algorithmic tangent D (which
condenses alpha) belong to it.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..materials.hyperelastic import SVK, VOIGT_PAIRS, material_response
from ..materials.update import material_update
from .solid import _jacobian
from .solidshell_dense import _factor, _solve

#: element flags: 0 ok, 1 strain not admissible (det F <= 0 / C not positive definite),
#: 2 det J0 <= 0, 3 local EAS Newton failed
FLAG_INVERTED = 1
FLAG_REFERENCE = 2
FLAG_EAS = 3
#: local EAS Newton (Neo-Hooke): relative and absolute strain-increment tolerances, iteration limit
EAS_TOL = 1e-11
EAS_ATOL = 1e-15
EAS_MAXIT = 30


@njit(cache=True)
def _strain_transform(Ji, T):
    """T (6, 6): Cartesian Voigt strain = T @ covariant Voigt strain (Ji[i, k] = dxi_i / dX_k)."""
    for K in range(6):
        k = VOIGT_PAIRS[K, 0]
        l = VOIGT_PAIRS[K, 1]
        fK = 1.0 if k == l else 2.0
        for I in range(6):
            i = VOIGT_PAIRS[I, 0]
            j = VOIGT_PAIRS[I, 1]
            if i == j:
                c = Ji[i, k] * Ji[i, l]
            else:
                c = 0.5 * (Ji[i, k] * Ji[j, l] + Ji[j, k] * Ji[i, l])
            T[K, I] = fK * c


@njit(cache=True)
def _stretch(E, F):
    """An F with F^T F = C = I + 2 E (upper Cholesky factor); False if C is not positive definite."""
    c00 = 1.0 + 2.0 * E[0]
    c11 = 1.0 + 2.0 * E[1]
    c22 = 1.0 + 2.0 * E[2]
    if not (c00 > 0.0):
        return False
    l00 = math.sqrt(c00)
    l10 = E[3] / l00
    l20 = E[5] / l00
    d = c11 - l10 * l10
    if not (d > 0.0):
        return False
    l11 = math.sqrt(d)
    l21 = (E[4] - l20 * l10) / l11
    d = c22 - l20 * l20 - l21 * l21
    if not (d > 0.0):
        return False
    F[0, 0] = l00
    F[0, 1] = l10
    F[0, 2] = l20
    F[1, 0] = 0.0
    F[1, 1] = l11
    F[1, 2] = l21
    F[2, 0] = 0.0
    F[2, 1] = 0.0
    F[2, 2] = math.sqrt(d)
    return True


@njit(cache=True)
def _response(kind, params, E, F, S, D):
    """S and D at Cartesian Green-Lagrange strain E; 1 if E is not admissible (S = 0, D = Hooke).

    St. Venant-Kirchhoff is evaluated from E directly (S = lambda tr E I + 2 mu E, the law of
    material_response without forming C = I + 2 E, whose round-off would dominate the small strains
    of thin shells); other materials through material_response at an F with F^T F = C.
    """
    ok = _stretch(E, F)
    if ok and kind != SVK:
        return material_response(kind, params, F, S, D)
    lam = params[2]
    mu = params[3]
    for I in range(6):
        for K in range(6):
            D[I, K] = 0.0
    for I in range(3):
        for K in range(3):
            D[I, K] = lam
        D[I, I] += 2.0 * mu
        D[I + 3, I + 3] = mu
    if not ok:
        for I in range(6):
            S[I] = 0.0
        return 1
    tr = E[0] + E[1] + E[2]
    for I in range(3):
        S[I] = lam * tr + 2.0 * mu * E[I]
        S[I + 3] = mu * E[I + 3]
    return 0


@njit(cache=True)
def _prepare(Xe, ue, dNp, dNc, w, tie_ptr, tie_pt, tie_w, eas_comp, eas_val,
             Gp, gp, Ep, Tg, Ec, Gam, detg, J0, Ji, T0, En, dU):
    """Geometry and assumed strains of one element.

    Returns FLAG_REFERENCE (det J0 <= 0, outputs incomplete), FLAG_INVERTED (the compatible det F <= 0
    at a Gauss point, outputs complete) or 0.
    """
    nen = Xe.shape[0]
    npt = dNp.shape[0]
    ng = w.size
    neas = eas_comp.size
    detc = _jacobian(Xe, dNc, J0, Ji)
    if not (detc > 0.0):
        return FLAG_REFERENCE
    _strain_transform(Ji, T0)
    for p in range(npt):
        for i in range(3):
            for k in range(3):
                sG = 0.0
                su = 0.0
                for a in range(nen):
                    d = dNp[p, a, i]
                    sG += d * Xe[a, k]
                    su += d * ue[a, k]
                Gp[p, i, k] = sG
                gp[p, i, k] = sG + su
                dU[i, k] = su
        # E_ij = 1/2 (G_i . u_j + G_j . u_i + u_i . u_j), u_i = d u / d xi_i (no cancellation)
        for I in range(6):
            i = VOIGT_PAIRS[I, 0]
            j = VOIGT_PAIRS[I, 1]
            v = 0.0
            for k in range(3):
                v += Gp[p, i, k] * dU[j, k] + Gp[p, j, k] * dU[i, k] + dU[i, k] * dU[j, k]
            Ep[p, I] = 0.5 * v if i == j else v
    flag = 0
    for g in range(ng):
        det = _jacobian(Xe, dNp[g], J0, Ji)
        if not (det > 0.0):
            return FLAG_REFERENCE
        detg[g] = det
        # det F of the compatible deformation = det[g_1, g_2, g_3] / det[G_1, G_2, G_3]
        detx = (gp[g, 0, 0] * (gp[g, 1, 1] * gp[g, 2, 2] - gp[g, 1, 2] * gp[g, 2, 1])
                - gp[g, 0, 1] * (gp[g, 1, 0] * gp[g, 2, 2] - gp[g, 1, 2] * gp[g, 2, 0])
                + gp[g, 0, 2] * (gp[g, 1, 0] * gp[g, 2, 1] - gp[g, 1, 1] * gp[g, 2, 0]))
        if not (detx > 0.0):
            flag = FLAG_INVERTED
        _strain_transform(Ji, Tg[g])
        for I in range(6):
            s = 0.0
            for q in range(tie_ptr[6 * g + I], tie_ptr[6 * g + I + 1]):
                s += tie_w[q] * Ep[tie_pt[q], I]
            En[I] = s
        for K in range(6):
            s = 0.0
            for I in range(6):
                s += Tg[g, K, I] * En[I]
            Ec[g, K] = s
        r = detc / det
        for m in range(neas):
            c = eas_comp[m]
            f = r * eas_val[g, m]
            for K in range(6):
                Gam[g, K, m] = f * T0[K, c]
    return flag


@njit(cache=True)
def _material(kind, params, E, F, S, D, hn, hist):
    """S, D at Cartesian Green-Lagrange strain E for a material with history: ``material_update`` at an F
    with F^T F = I + 2 E from the committed history hn, trial written to hist. Returns 0, or 1 if E is not
    admissible (S = 0, D = Hooke, hist = hn) or the material reports a failure."""
    if _stretch(E, F):
        return 0 if material_update(kind, params, F, hn, hist, S, D) == 0 else 1
    for k in range(hist.size):
        hist[k] = hn[k]
    _response(kind, params, E, F, S, D)
    return 1


@njit(cache=True)
def _evaluate(kind, params, w, Ec, Gam, detg, alpha, S, D, h, H, Et, F, hne, hist):
    """S, D at every Gauss point for parameters alpha; EAS residual h and matrix H. Returns a flag.

    hne, hist (ng, nh): committed and trial material history (nh = 0: hyperelastic, no history)."""
    ng = w.size
    neas = alpha.size
    nh = hist.shape[1]
    flag = 0
    for m in range(neas):
        h[m] = 0.0
        for n in range(neas):
            H[m, n] = 0.0
    for g in range(ng):
        for K in range(6):
            s = Ec[g, K]
            for m in range(neas):
                s += Gam[g, K, m] * alpha[m]
            Et[g, K] = s
        if nh > 0:
            if _material(kind, params, Et[g], F, S[g], D[g], hne[g], hist[g]) != 0:
                flag = FLAG_INVERTED
        elif _response(kind, params, Et[g], F, S[g], D[g]) != 0:
            flag = FLAG_INVERTED
        wd = w[g] * detg[g]
        for m in range(neas):
            s = 0.0
            for K in range(6):
                s += Gam[g, K, m] * S[g, K]
            h[m] += wd * s
            for n in range(m, neas):
                s = 0.0
                for K in range(6):
                    t = 0.0
                    for L in range(6):
                        t += D[g, K, L] * Gam[g, L, n]
                    s += Gam[g, K, m] * t
                H[m, n] += wd * s
    for m in range(neas):
        for n in range(m):
            H[m, n] = H[n, m]
    return flag


@njit(cache=True)
def _local_solve(kind, params, w, Ec, Gam, detg, alpha, S, D, h, H, Hf, dal, Et, F, hne, hist, piv):
    """Solve the EAS equations h(alpha) = 0 (alpha in place, from its current value).

    On return S, D hold the response at the solution and H the (unfactored) EAS matrix. SVK: h is
    linear in alpha, one solve is exact and S is updated linearly. Neo-Hooke and J2: Newton until the
    strain increment |Gamma dalpha| <= EAS_TOL |E|, then one more evaluation at the solution (J2: every
    evaluation runs the return mapping from the committed history hne; hist holds the trial history, S
    and D the consistent tangent of that last evaluation; an indefinite H, possible with an algorithmic
    tangent, is solved by LU with partial pivoting, piv (neas,) int64 scratch).
    """
    ng = w.size
    neas = alpha.size
    for m in range(neas):
        if not np.isfinite(alpha[m]):
            for n in range(neas):
                alpha[n] = 0.0
            break
    done = False
    for it in range(EAS_MAXIT):
        flag = _evaluate(kind, params, w, Ec, Gam, detg, alpha, S, D, h, H, Et, F, hne, hist)
        if flag != 0 or neas == 0 or done:
            return flag
        mode = _factor(H, neas, Hf, piv, hist.shape[1] > 0)
        if mode == 0:
            return FLAG_EAS
        for m in range(neas):
            dal[m] = -h[m]
        _solve(Hf, piv, neas, dal, mode)
        for m in range(neas):
            alpha[m] += dal[m]
        dmax = 0.0
        emax = 0.0
        for g in range(ng):
            for K in range(6):
                s = 0.0
                for m in range(neas):
                    s += Gam[g, K, m] * dal[m]
                dmax = max(dmax, abs(s))
                emax = max(emax, abs(Et[g, K] + s))
                if kind == SVK:
                    Et[g, K] += s
            if kind == SVK:
                for K in range(6):
                    s = 0.0
                    for m in range(neas):
                        t = 0.0
                        for L in range(6):
                            t += D[g, K, L] * Gam[g, L, m]
                        s += t * dal[m]
                    S[g, K] += s
        if kind == SVK:
            return 0
        if not np.isfinite(dmax):
            return FLAG_EAS
        done = dmax <= EAS_TOL * emax or dmax <= EAS_ATOL
    return FLAG_EAS


@njit(cache=True)
def _forces(dNp, gp, w, tie_ptr, tie_pt, tie_w, Tg, detg, S, sig, fe, want_K, Ke):
    """Internal forces fe and the geometric stiffness (added to Ke) from the Gauss-point stresses.

    The weighted covariant stress of every Gauss point is distributed over the tying points of each
    component: sig[p] (3, 3) is the stress acting on the covariant strain at point p.
    """
    npt = dNp.shape[0]
    nen = dNp.shape[1]
    ng = w.size
    for p in range(npt):
        for i in range(3):
            for j in range(3):
                sig[p, i, j] = 0.0
    for g in range(ng):
        wd = w[g] * detg[g]
        for I in range(6):
            s = 0.0
            for K in range(6):
                s += Tg[g, K, I] * S[g, K]
            s *= wd
            i = VOIGT_PAIRS[I, 0]
            j = VOIGT_PAIRS[I, 1]
            for q in range(tie_ptr[6 * g + I], tie_ptr[6 * g + I + 1]):
                v = tie_w[q] * s
                p = tie_pt[q]
                sig[p, i, j] += v
                if i != j:
                    sig[p, j, i] += v
    for r in range(3 * nen):
        fe[r] = 0.0
    for p in range(npt):
        nz = False
        for i in range(3):
            for j in range(3):
                if sig[p, i, j] != 0.0:
                    nz = True
        if not nz:
            continue
        for a in range(nen):
            q0 = dNp[p, a, 0] * sig[p, 0, 0] + dNp[p, a, 1] * sig[p, 1, 0] + dNp[p, a, 2] * sig[p, 2, 0]
            q1 = dNp[p, a, 0] * sig[p, 0, 1] + dNp[p, a, 1] * sig[p, 1, 1] + dNp[p, a, 2] * sig[p, 2, 1]
            q2 = dNp[p, a, 0] * sig[p, 0, 2] + dNp[p, a, 1] * sig[p, 1, 2] + dNp[p, a, 2] * sig[p, 2, 2]
            for k in range(3):
                fe[3 * a + k] += q0 * gp[p, 0, k] + q1 * gp[p, 1, k] + q2 * gp[p, 2, k]
            if want_K:
                for b in range(a, nen):
                    v = q0 * dNp[p, b, 0] + q1 * dNp[p, b, 1] + q2 * dNp[p, b, 2]
                    for k in range(3):
                        Ke[3 * a + k, 3 * b + k] += v


@njit(cache=True)
def _material_tangent(dNp, gp, w, tie_ptr, tie_pt, tie_w, Tg, detg, D, Gam, Bn, Bc, DB, DG, Kua, Ke):
    """Ke += int Bc^T D Bc (upper triangle) and Kua = int Bc^T D Gamma, Bc = T_g B_nat."""
    nen = dNp.shape[1]
    nd = 3 * nen
    ng = w.size
    neas = Gam.shape[2]
    for r in range(nd):
        for m in range(neas):
            Kua[r, m] = 0.0
    for g in range(ng):
        wd = w[g] * detg[g]
        for I in range(6):
            for r in range(nd):
                Bn[I, r] = 0.0
            i = VOIGT_PAIRS[I, 0]
            j = VOIGT_PAIRS[I, 1]
            for q in range(tie_ptr[6 * g + I], tie_ptr[6 * g + I + 1]):
                p = tie_pt[q]
                wt = tie_w[q]
                for a in range(nen):
                    di = wt * dNp[p, a, i]
                    if i == j:
                        for k in range(3):
                            Bn[I, 3 * a + k] += di * gp[p, i, k]
                    else:
                        dj = wt * dNp[p, a, j]
                        for k in range(3):
                            Bn[I, 3 * a + k] += di * gp[p, j, k] + dj * gp[p, i, k]
        for K in range(6):
            for r in range(nd):
                s = 0.0
                for I in range(6):
                    s += Tg[g, K, I] * Bn[I, r]
                Bc[K, r] = s
        for K in range(6):
            for r in range(nd):
                s = 0.0
                for L in range(6):
                    s += D[g, K, L] * Bc[L, r]
                DB[K, r] = wd * s
            for m in range(neas):
                s = 0.0
                for L in range(6):
                    s += D[g, K, L] * Gam[g, L, m]
                DG[K, m] = wd * s
        for r in range(nd):
            for c in range(r, nd):
                s = 0.0
                for K in range(6):
                    s += Bc[K, r] * DB[K, c]
                Ke[r, c] += s
            for m in range(neas):
                s = 0.0
                for K in range(6):
                    s += Bc[K, r] * DG[K, m]
                Kua[r, m] += s


@njit(cache=True)
def _condense(Ke, Kua, Hf, neas, x, piv, mode):
    """Ke -= Kua H^-1 Kua^T (upper triangle), H factored by :func:`_factor` (mode)."""
    nd = Ke.shape[0]
    if neas == 0:
        return
    for r in range(nd):
        for m in range(neas):
            x[m] = Kua[r, m]
        _solve(Hf, piv, neas, x, mode)
        for c in range(r, nd):
            s = 0.0
            for m in range(neas):
                s += Kua[c, m] * x[m]
            Ke[r, c] -= s


@njit(cache=True)
def _element(kind, params, Xe, ue, alpha, dNp, dNc, w, tie_ptr, tie_pt, tie_w, eas_comp, eas_val,
             want_K, Ke, fe, ws3, ws4, ws2, wsg, wv, hist_n, hist, hne):
    """Internal force fe and condensed tangent Ke of one element; alpha updated in place.

    Scratch: ws3 = (Gp, gp, sig) (npt, 3, 3) each; ws4 = (Tg, D) (ng, 6, 6); ws2 = (Ep, S, Et, Ec);
    wsg = (Gam, detg); wv = small vectors/matrices. Material history (ng, nh): hist_n committed (read,
    may be the same array as hist), hist trial (written), hne scratch (the copy of hist_n the local
    solve works from). A failed element (det J0 <= 0, local Newton failed) keeps hist = hist_n.
    Returns a flag (0 ok).
    """
    Gp, gp, sig = ws3
    Tg, D = ws4
    Ep, S, Et, Ec = ws2
    Gam, detg = wsg
    J0, Ji, T0, F, En, h, H, Hf, dal, a0, x, Bn, Bc, DB, DG, Kua, piv = wv
    nd = fe.size
    neas = alpha.size
    nh = hist.shape[1]
    for g in range(w.size):
        for k in range(nh):
            hne[g, k] = hist_n[g, k]
    for m in range(neas):
        a0[m] = alpha[m]
    flag = _prepare(Xe, ue, dNp, dNc, w, tie_ptr, tie_pt, tie_w, eas_comp, eas_val, Gp, gp, Ep, Tg, Ec, Gam,
                    detg, J0, Ji, T0, En, F)
    if flag != FLAG_REFERENCE:
        f2 = _local_solve(kind, params, w, Ec, Gam, detg, alpha, S, D, h, H, Hf, dal, Et, F, hne, hist, piv)
        if f2 != 0:
            flag = f2
    if flag != 0:
        for m in range(neas):
            alpha[m] = a0[m] if np.isfinite(a0[m]) else 0.0
        if flag != FLAG_INVERTED:
            for g in range(w.size):
                for k in range(nh):
                    hist[g, k] = hne[g, k]
        for r in range(nd):
            fe[r] = 0.0
        if want_K:
            for r in range(nd):
                for c in range(nd):
                    Ke[r, c] = 0.0
        if flag == FLAG_REFERENCE:
            return flag
        # keep finite outputs at the admissible part (S = 0 where E is not admissible)
        if flag == FLAG_EAS:
            return flag
    if want_K:
        for r in range(nd):
            for c in range(nd):
                Ke[r, c] = 0.0
    _forces(dNp, gp, w, tie_ptr, tie_pt, tie_w, Tg, detg, S, sig, fe, want_K, Ke)
    if want_K:
        _material_tangent(dNp, gp, w, tie_ptr, tie_pt, tie_w, Tg, detg, D, Gam, Bn, Bc, DB, DG, Kua, Ke)
        if neas > 0 and flag == 0:
            mode = _factor(H, neas, Hf, piv, nh > 0)
            if mode != 0:
                _condense(Ke, Kua, Hf, neas, x, piv, mode)
            else:
                flag = FLAG_EAS
        for r in range(nd):
            for c in range(r + 1, nd):
                Ke[c, r] = Ke[r, c]
    return flag
