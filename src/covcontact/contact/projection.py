"""Closest point projection of a slave point onto one master facet (docs/theory.md section 4).

Solves F_i(xi) = (r_s - rho(xi)) . rho_i = 0 by Newton's method with the Hessian of
1/2 |r_s - rho|^2, c_ij = a_ij - g h_ij. Where c is not positive definite (near or beyond the
focal surface) the step falls back to Gauss-Newton with a_ij, and every step is halved until the
distance does not grow; |dxi| is capped. The result is not clipped to [-1, 1]^2: the caller
decides whether the point lies on the facet. The function never returns NaN and never runs more
than ``max_iter`` Newton iterations.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from covcontact.contact.geometry import DEGENERATE_TOL, bilinear_coefficients

#: projection status codes
CONVERGED = 0
NOT_CONVERGED = 1
DEGENERATE = 2

#: largest Newton step |dxi| in element coordinates
STEP_CAP = 0.5
_MAX_HALVINGS = 40
_EPS = 2.220446049250313e-16


@njit(cache=True, error_model="numpy")
def facet_monomials(xyz, c):
    """The facet as a polynomial: rho(xi) = sum_mq c[m, q] xi1^m xi2^q, c (3, 3, 3) out (quad4: m, q <= 1).

    Evaluating the monomial form costs a few dozen flops per point, against the shape-function sums of
    ``facet_geometry``; the projection's Newton loop runs on it.
    """
    if xyz.shape[0] == 4:
        for p in range(3):
            c[0, 0, p], c[1, 0, p], c[0, 1, p], c[1, 1, p] = bilinear_coefficients(xyz[0, p], xyz[1, p], xyz[2, p],
                                                                                    xyz[3, p])
            c[2, 0, p] = 0.0
            c[2, 1, p] = 0.0
            c[0, 2, p] = 0.0
            c[1, 2, p] = 0.0
            c[2, 2, p] = 0.0
        return
    # quad9: the 1D transform (values at -1, +1, 0 -> monomials) along xi1 for each row of nodes, then along xi2;
    # nodes (VTK order) 0 (-1,-1), 1 (1,-1), 2 (1,1), 3 (-1,1), 4 (0,-1), 5 (1,0), 6 (0,1), 7 (-1,0), 8 (0,0)
    for p in range(3):
        for q in range(3):
            if q == 0:  # row xi2 = -1
                a, b, z = xyz[0, p], xyz[1, p], xyz[4, p]
            elif q == 1:  # row xi2 = +1
                a, b, z = xyz[3, p], xyz[2, p], xyz[6, p]
            else:  # row xi2 = 0
                a, b, z = xyz[7, p], xyz[5, p], xyz[8, p]
            c[0, q, p] = z
            c[1, q, p] = 0.5 * (b - a)
            c[2, q, p] = 0.5 * (a + b) - z
        for m in range(3):
            a, b, z = c[m, 0, p], c[m, 1, p], c[m, 2, p]
            c[m, 0, p] = z
            c[m, 1, p] = 0.5 * (b - a)
            c[m, 2, p] = 0.5 * (a + b) - z


@njit(cache=True, error_model="numpy")
def _mono_geometry(c, x1, x2, G):
    """G (6, 3) out: rho, rho_1, rho_2, rho_11, rho_12, rho_22 of the monomial form c at (x1, x2)."""
    for p in range(3):
        u0 = c[0, 0, p] + x2 * (c[0, 1, p] + x2 * c[0, 2, p])
        u1 = c[1, 0, p] + x2 * (c[1, 1, p] + x2 * c[1, 2, p])
        u2 = c[2, 0, p] + x2 * (c[2, 1, p] + x2 * c[2, 2, p])
        v0 = c[0, 1, p] + 2.0 * x2 * c[0, 2, p]
        v1 = c[1, 1, p] + 2.0 * x2 * c[1, 2, p]
        v2 = c[2, 1, p] + 2.0 * x2 * c[2, 2, p]
        G[0, p] = u0 + x1 * (u1 + x1 * u2)
        G[1, p] = u1 + 2.0 * x1 * u2
        G[2, p] = v0 + x1 * (v1 + x1 * v2)
        G[3, p] = 2.0 * u2
        G[4, p] = v1 + 2.0 * x1 * v2
        G[5, p] = 2.0 * (c[0, 2, p] + x1 * (c[1, 2, p] + x1 * c[2, 2, p]))


@njit(cache=True, error_model="numpy")
def _mono_point(c, x1, x2, p):
    """Coordinate p of rho(x1, x2)."""
    u0 = c[0, 0, p] + x2 * (c[0, 1, p] + x2 * c[0, 2, p])
    u1 = c[1, 0, p] + x2 * (c[1, 1, p] + x2 * c[1, 2, p])
    u2 = c[2, 0, p] + x2 * (c[2, 1, p] + x2 * c[2, 2, p])
    return u0 + x1 * (u1 + x1 * u2)


@njit(cache=True, error_model="numpy")
def _mono_frame(G):
    """(area, n0, n1, n2, a00, a01, a11, h00, h01, h11) from G of ``_mono_geometry``; area 0 (n, h zero) at a
    degenerate point (as ``facet_geometry``)."""
    a00 = G[1, 0] * G[1, 0] + G[1, 1] * G[1, 1] + G[1, 2] * G[1, 2]
    a01 = G[1, 0] * G[2, 0] + G[1, 1] * G[2, 1] + G[1, 2] * G[2, 2]
    a11 = G[2, 0] * G[2, 0] + G[2, 1] * G[2, 1] + G[2, 2] * G[2, 2]
    c0 = G[1, 1] * G[2, 2] - G[1, 2] * G[2, 1]
    c1 = G[1, 2] * G[2, 0] - G[1, 0] * G[2, 2]
    c2 = G[1, 0] * G[2, 1] - G[1, 1] * G[2, 0]
    area = np.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
    if not (area > DEGENERATE_TOL * np.sqrt(a00 * a11)) or not np.isfinite(area):
        return 0.0, 0.0, 0.0, 0.0, a00, a01, a11, 0.0, 0.0, 0.0
    n0 = c0 / area
    n1 = c1 / area
    n2 = c2 / area
    h00 = G[3, 0] * n0 + G[3, 1] * n1 + G[3, 2] * n2
    h01 = G[4, 0] * n0 + G[4, 1] * n1 + G[4, 2] * n2
    h11 = G[5, 0] * n0 + G[5, 1] * n1 + G[5, 2] * n2
    return area, n0, n1, n2, a00, a01, a11, h00, h01, h11


@njit(cache=True, error_model="numpy", inline="always")
def planar_start(x, faces, f, xs, xi):
    """Start of a projection without history: xi where the tangent plane at the centre of the corners' bilinear
    map comes nearest xs (one uncapped Gauss-Newton step from the centre), clipped to [-1, 1]^2.

    ``x`` (n, 3) node positions, ``faces[f]`` the facet's nodes (its first four are the corners); xi (2,) out.
    A slave over a mildly warped facet starts within a few per cent of its converged point, instead of at the
    centre or a node, from which the capped Newton steps take longer.
    """
    i0, i1, i2, i3 = faces[f, 0], faces[f, 1], faces[f, 2], faces[f, 3]
    bb = 0.0
    bc = 0.0
    cc = 0.0
    db = 0.0
    dc = 0.0
    for p in range(3):
        a, b, c, _ = bilinear_coefficients(x[i0, p], x[i1, p], x[i2, p], x[i3, p])
        d = xs[p] - a
        bb += b * b
        bc += b * c
        cc += c * c
        db += d * b
        dc += d * c
    det = bb * cc - bc * bc
    if det > 1e-12 * bb * cc:
        xi[0] = min(max((cc * db - bc * dc) / det, -1.0), 1.0)
        xi[1] = min(max((bb * dc - bc * db) / det, -1.0), 1.0)
    else:
        xi[0] = 0.0
        xi[1] = 0.0


@njit(cache=True, error_model="numpy")
def projection_work(nen):
    """Scratch arrays for ``project_on_facet_work`` (allocate once per thread, reuse for every call)."""
    return np.empty((3, 3, 3)), np.empty((6, 3))


@njit(cache=True, error_model="numpy")
def project_on_facet_info(xyz, xs, xi, max_iter=30, tol=1e-12):
    """As ``project_on_facet``, and also returns the number of Newton iterations used.

    Returns:
        (status, g, nit).
    """
    return project_on_facet_work(xyz, xs, xi, projection_work(xyz.shape[0]), max_iter, tol)


@njit(cache=True, error_model="numpy")
def project_on_facet_work(xyz, xs, xi, work, max_iter=30, tol=1e-12):
    """As ``project_on_facet_info`` with the caller's scratch ``work = projection_work(nen)``: no allocation,
    for hot loops over many slaves.

    Returns:
        (status, g, nit).
    """
    c, G = work
    return project_inline(xyz, xs, xi, c, G, max_iter, tol)


@njit(cache=True, error_model="numpy", inline="always")
def project_inline(xyz, xs, xi, c, G, max_iter, tol):
    """The projection itself, compiled into its caller (the contact driver's hot loop, where a call that passes
    arrays costs a reference count per array and per call); scratch c (3, 3, 3) and G (6, 3). The facet is
    evaluated in its monomial form (``facet_monomials``). Returns (status, g, nit)."""

    # guard against non-finite input: never propagate NaN
    scale = 0.0
    for k in range(3):
        if not np.isfinite(xs[k]):
            return DEGENERATE, 0.0, 0
    for a in range(xyz.shape[0]):
        for p in range(3):
            v = xyz[a, p]
            if not np.isfinite(v):
                return DEGENERATE, 0.0, 0
            scale = max(scale, abs(v))
    facet_monomials(xyz, c)
    xs_norm = np.sqrt(xs[0] * xs[0] + xs[1] * xs[1] + xs[2] * xs[2])
    # round-off floor of |F| / |rho_i|, i.e. of |dxi| |rho_i|
    floor = 64.0 * _EPS * (scale + xs_norm)
    if not (np.isfinite(xi[0]) and np.isfinite(xi[1])):
        xi[0] = 0.0
        xi[1] = 0.0

    status = NOT_CONVERGED
    nit = 0
    for it in range(max_iter):
        nit = it + 1
        _mono_geometry(c, xi[0], xi[1], G)
        area, n0, n1, n2, a00, a01, a11, h00, h01, h11 = _mono_frame(G)
        d0 = xs[0] - G[0, 0]
        d1 = xs[1] - G[0, 1]
        d2 = xs[2] - G[0, 2]
        f0 = 0.5 * (d0 * d0 + d1 * d1 + d2 * d2)
        F0 = d0 * G[1, 0] + d1 * G[1, 1] + d2 * G[1, 2]
        F1 = d0 * G[2, 0] + d1 * G[2, 1] + d2 * G[2, 2]
        newton = False
        dx0 = 0.0
        dx1 = 0.0
        if area > 0.0:
            g = d0 * n0 + d1 * n1 + d2 * n2
            c00 = a00 - g * h00
            c01 = a01 - g * h01
            c11 = a11 - g * h11
            detc = c00 * c11 - c01 * c01
            if c00 > 0.0 and c11 > 0.0 and detc > 1e-10 * c00 * c11:
                newton = True
                dx0 = (c11 * F0 - c01 * F1) / detc
                dx1 = (c00 * F1 - c01 * F0) / detc
        if not newton:
            deta = a00 * a11 - a01 * a01
            if a00 > 0.0 and a11 > 0.0 and deta > 1e-12 * a00 * a11:
                dx0 = (a11 * F0 - a01 * F1) / deta
                dx1 = (a00 * F1 - a01 * F0) / deta
            else:
                tr = a00 + a11
                if not (tr > 0.0):
                    return DEGENERATE, 0.0, nit
                # steepest descent on 1/2 |r_s - rho|^2 (gradient -F)
                dx0 = F0 / tr
                dx1 = F1 / tr
        s = np.sqrt(dx0 * dx0 + dx1 * dx1)
        if not np.isfinite(s):
            return DEGENERATE, 0.0, nit
        if s > STEP_CAP:
            dx0 *= STEP_CAP / s
            dx1 *= STEP_CAP / s
            s = STEP_CAP
        rho_scale = np.sqrt(0.5 * (a00 + a11))
        if s < tol or s * rho_scale < floor:
            xi[0] += dx0
            xi[1] += dx1
            status = CONVERGED
            break
        if newton and s < 1e-2:
            # small full Newton step on a positive definite Hessian: the quadratic model holds, no check
            xi[0] += dx0
            xi[1] += dx1
            continue
        # step halving on the distance; f is known only up to its round-off |d| * floor
        f_tol = 1e-13 * f0 + 4.0 * floor * (np.sqrt(2.0 * f0) + floor)
        t = 1.0
        accepted = False
        for k in range(_MAX_HALVINGS):
            e0 = xs[0] - _mono_point(c, xi[0] + t * dx0, xi[1] + t * dx1, np.int64(0))
            e1 = xs[1] - _mono_point(c, xi[0] + t * dx0, xi[1] + t * dx1, np.int64(1))
            e2 = xs[2] - _mono_point(c, xi[0] + t * dx0, xi[1] + t * dx1, np.int64(2))
            ft = 0.5 * (e0 * e0 + e1 * e1 + e2 * e2)
            if ft <= f0 + f_tol:
                accepted = True
                break
            t *= 0.5
        if not accepted:
            # no descent even for a tiny step: stationary up to round-off
            if s * rho_scale < 1e-6 * (scale + xs_norm):
                status = CONVERGED
            break
        xi[0] += t * dx0
        xi[1] += t * dx1

    _mono_geometry(c, xi[0], xi[1], G)
    area, n0, n1, n2 = _mono_frame(G)[:4]
    if area == 0.0:
        return DEGENERATE, 0.0, nit
    g = (xs[0] - G[0, 0]) * n0 + (xs[1] - G[0, 1]) * n1 + (xs[2] - G[0, 2]) * n2
    return status, g, nit


@njit(cache=True, error_model="numpy")
def project_on_facet(xyz, xs, xi, max_iter=30, tol=1e-12):
    """Closest point projection of ``xs`` onto the facet ``xyz``.

    Args:
        xyz: (n, 3) facet nodes, n = 4 (quad4) or 9 (quad9), VTK order.
        xs: (3,) slave point.
        xi: (2,) in/out: start value in, converged element coordinates out (not clipped).
        max_iter: largest number of Newton iterations.
        tol: convergence tolerance on |dxi|.

    Returns:
        (status, g): status 0 converged, 1 not converged in max_iter, 2 degenerate facet (or
        non-finite input); g = (r_s - rho) . n, the signed normal gap (negative: penetration).
    """
    status, g, _nit = project_on_facet_info(xyz, xs, xi, max_iter, tol)
    return status, g
