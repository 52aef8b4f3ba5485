"""The compiled kernels of contact in the plane (docs/theory.md section 28; the formulation in contact/planar.py's
docstring): a segment's shape functions and point, the closest-point projection on it, the residual and tangent
parts of a slave on a segment and on a vertex."""

from __future__ import annotations

import numpy as np
from numba import njit

from .element import CASE_A, CASE_B, CASE_C, CASE_EXACT

#: accepted distance outside [-1, 1] of a projection on a segment
INSIDE_TOL = 1e-6
#: largest number of Newton iterations of the projection
MAX_ITER = 40


@njit(cache=True)
def segment_shapes(nen, xi, N, dN, ddN):
    """N, N,xi, N,xixi of a 2-node (ends -1, 1) or 3-node (ends, then the mid-node at 0) segment."""
    if nen == 2:
        N[0] = 0.5 * (1.0 - xi)
        N[1] = 0.5 * (1.0 + xi)
        dN[0] = -0.5
        dN[1] = 0.5
        ddN[0] = 0.0
        ddN[1] = 0.0
    else:
        N[0] = 0.5 * xi * (xi - 1.0)
        N[1] = 0.5 * xi * (xi + 1.0)
        N[2] = 1.0 - xi * xi
        dN[0] = xi - 0.5
        dN[1] = xi + 0.5
        dN[2] = -2.0 * xi
        ddN[0] = 1.0
        ddN[1] = 1.0
        ddN[2] = -2.0


@njit(cache=True)
def segment_point(xseg, xi):
    """(x, rho, x,xixi) in the plane (2-vectors) of a segment (nen, >= 2) at xi."""
    nen = xseg.shape[0]
    N = np.empty(3)
    dN = np.empty(3)
    ddN = np.empty(3)
    segment_shapes(nen, xi, N, dN, ddN)
    x = np.zeros(2)
    r = np.zeros(2)
    r2 = np.zeros(2)
    for b in range(nen):
        for p in range(2):
            x[p] += N[b] * xseg[b, p]
            r[p] += dN[b] * xseg[b, p]
            r2[p] += ddN[b] * xseg[b, p]
    return x, r, r2


@njit(cache=True)
def project_on_segment(xseg, xs, xi0):
    """Closest point of slave xs on the curve of segment xseg: Newton on (x_s - x(xi)) . rho = 0 from xi0.

    Returns (xi, g, converged): g = (x_s - x(xi)) . n. Iterates leave [-2, 2]: not converged."""
    xi = xi0
    for _ in range(MAX_ITER):
        x, r, r2 = segment_point(xseg, xi)
        d0 = xs[0] - x[0]
        d1 = xs[1] - x[1]
        f = d0 * r[0] + d1 * r[1]
        fp = -(r[0] * r[0] + r[1] * r[1]) + d0 * r2[0] + d1 * r2[1]
        if fp >= 0.0:  # far on the concave side beyond the centre of curvature: step as on the chord
            fp = -(r[0] * r[0] + r[1] * r[1])
        step = -f / fp
        xi += step
        if abs(xi) > 2.0:
            return xi, np.inf, False
        if abs(step) < 1e-14:
            break
    x, r, r2 = segment_point(xseg, xi)
    la = np.sqrt(r[0] * r[0] + r[1] * r[1])
    if la == 0.0:
        return xi, np.inf, False
    g = ((xs[0] - x[0]) * r[1] - (xs[1] - x[1]) * r[0]) / la
    return xi, g, True


@njit(cache=True)
def segment_core(xseg, xs, xi, eps, lam_k, case, want_parts, R, K, P):
    """Residual R (3 (nen + 1)), tangent K of ``case`` and, with ``want_parts``, the four parts P (4, nd, nd) of a
    slave xs on segment xseg (nen, 3) at its projection xi (all added into the zeroed outputs). Returns the gap g;
    R, K, P stay zero when the pair is inactive (g + lam_k / eps > 0)."""
    nen = xseg.shape[0]
    nb = nen + 1
    N = np.empty(3)
    dN = np.empty(3)
    ddN = np.empty(3)
    segment_shapes(nen, xi, N, dN, ddN)
    x = np.zeros(3)
    rho = np.zeros(3)
    r2 = np.zeros(3)
    for b in range(nen):
        for p in range(2):
            x[p] += N[b] * xseg[b, p]
            rho[p] += dN[b] * xseg[b, p]
            r2[p] += ddN[b] * xseg[b, p]
    a = rho[0] * rho[0] + rho[1] * rho[1]
    la = np.sqrt(a)
    n = np.zeros(3)
    n[0] = rho[1] / la
    n[1] = -rho[0] / la
    g = (xs[0] - x[0]) * n[0] + (xs[1] - x[1]) * n[1]
    ge = g + lam_k / eps
    if ge > 0.0:
        return g
    h = r2[0] * n[0] + r2[1] * n[1]
    c = a - g * h
    alpha = np.empty(nb)
    beta = np.empty(nb)
    for b in range(nen):
        alpha[b] = -N[b]
        beta[b] = -dN[b]
    alpha[nen] = 1.0
    beta[nen] = 0.0
    for b in range(nb):
        for p in range(3):
            R[3 * b + p] += eps * ge * alpha[b] * n[p]
    # (c_nn, M, W, S) of main, rotational, curvature, second order
    coef = np.zeros((4, 4))
    coef[0, 0] = 1.0
    coef[1, 2] = 1.0 / a
    coef[2, 1] = -ge * h / (a * a)
    coef[3, 1] = -ge * g * h * h / (a * a * c)
    coef[3, 2] = 1.0 / c - 1.0 / a
    coef[3, 3] = 1.0 / c
    use = np.zeros(4)
    use[0] = 1.0
    if case == CASE_A or case == CASE_B or case == CASE_EXACT:
        use[1] = 1.0
    if case == CASE_A or case == CASE_C or case == CASE_EXACT:
        use[2] = 1.0
    if case == CASE_EXACT:
        use[3] = 1.0
    for part in range(4):
        if use[part] == 0.0 and not want_parts:
            continue
        cnn, M, W, S = coef[part, 0], coef[part, 1], coef[part, 2], coef[part, 3]
        for b in range(nb):
            for cc in range(nb):
                ab = alpha[b] * alpha[cc]
                sbc = beta[b] * S * beta[cc]
                for p in range(2):
                    for q in range(2):
                        v = ab * (cnn * n[p] * n[q] + M * rho[p] * rho[q])
                        v += ge * (alpha[cc] * n[p] * beta[b] * W * rho[q] + alpha[b] * beta[cc] * W * rho[p] * n[q])
                        v -= ge * g * sbc * n[p] * n[q]
                        v *= eps
                        if use[part] != 0.0:
                            K[3 * b + p, 3 * cc + q] += v
                        if want_parts:
                            P[part, 3 * b + p, 3 * cc + q] += v
    return g


@njit(cache=True)
def vertex_core(xv, xs, sign, eps, lam_k, R, K):
    """A slave xs against the vertex xv (the closest point of the master curve): g = sign |x_s - x_v|, n =
    (x_s - x_v) / g; residual and exact tangent on (vertex, slave) added into R (6) and K (6, 6). Returns g."""
    d0 = xs[0] - xv[0]
    d1 = xs[1] - xv[1]
    dist = np.sqrt(d0 * d0 + d1 * d1)
    if dist == 0.0:
        return 0.0
    g = sign * dist
    ge = g + lam_k / eps
    if ge > 0.0:
        return g
    n = np.array([d0 / g, d1 / g])
    for p in range(2):
        R[p] -= eps * ge * n[p]
        R[3 + p] += eps * ge * n[p]
    for p in range(2):
        for q in range(2):
            v = eps * (n[p] * n[q] + ge / g * ((1.0 if p == q else 0.0) - n[p] * n[q]))
            K[p, q] += v
            K[3 + p, 3 + q] += v
            K[p, 3 + q] -= v
            K[3 + p, q] -= v
    return g


# -- the curve: segments, their neighbours, search and projection --------------------------------------------------
