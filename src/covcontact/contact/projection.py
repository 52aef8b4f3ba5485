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

from covcontact.contact.geometry import facet_geometry, facet_point

#: projection status codes
CONVERGED = 0
NOT_CONVERGED = 1
DEGENERATE = 2

#: largest Newton step |dxi| in element coordinates
STEP_CAP = 0.5
_MAX_HALVINGS = 40
_EPS = 2.220446049250313e-16


@njit(cache=True)
def projection_work(nen):
    """Scratch arrays for ``project_on_facet_work`` (allocate once per thread, reuse for every call)."""
    return (np.empty(nen), np.empty((nen, 2)), np.empty((nen, 2, 2)), np.empty(3), np.empty(3),
            np.empty((2, 3)), np.empty((2, 2)), np.empty((2, 2)), np.empty(3), np.empty((2, 2)))


@njit(cache=True)
def project_on_facet_info(xyz, xs, xi, max_iter=30, tol=1e-12):
    """As ``project_on_facet``, and also returns the number of Newton iterations used.

    Returns:
        (status, g, nit).
    """
    return project_on_facet_work(xyz, xs, xi, projection_work(xyz.shape[0]), max_iter, tol)


@njit(cache=True)
def project_on_facet_work(xyz, xs, xi, work, max_iter=30, tol=1e-12):
    """As ``project_on_facet_info`` with the caller's scratch ``work = projection_work(nen)``: no allocation,
    for hot loops over many slaves.

    Returns:
        (status, g, nit).
    """
    N, dN, ddN, rho, rho_t, rho_cov, a_cov, a_con, nrm, h_cov = work

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
        area = facet_geometry(xyz, xi[0], xi[1], N, dN, ddN, rho, rho_cov, a_cov, a_con, nrm, h_cov)
        d0 = xs[0] - rho[0]
        d1 = xs[1] - rho[1]
        d2 = xs[2] - rho[2]
        f0 = 0.5 * (d0 * d0 + d1 * d1 + d2 * d2)
        F0 = d0 * rho_cov[0, 0] + d1 * rho_cov[0, 1] + d2 * rho_cov[0, 2]
        F1 = d0 * rho_cov[1, 0] + d1 * rho_cov[1, 1] + d2 * rho_cov[1, 2]
        a00 = a_cov[0, 0]
        a01 = a_cov[0, 1]
        a11 = a_cov[1, 1]
        newton = False
        if area > 0.0:
            g = d0 * nrm[0] + d1 * nrm[1] + d2 * nrm[2]
            c00 = a00 - g * h_cov[0, 0]
            c01 = a01 - g * h_cov[0, 1]
            c11 = a11 - g * h_cov[1, 1]
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
            facet_point(xyz, xi[0] + t * dx0, xi[1] + t * dx1, N, dN, ddN, rho_t)
            e0 = xs[0] - rho_t[0]
            e1 = xs[1] - rho_t[1]
            e2 = xs[2] - rho_t[2]
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

    area = facet_geometry(xyz, xi[0], xi[1], N, dN, ddN, rho, rho_cov, a_cov, a_con, nrm, h_cov)
    if area == 0.0:
        return DEGENERATE, 0.0, nit
    g = (xs[0] - rho[0]) * nrm[0] + (xs[1] - rho[1]) * nrm[1] + (xs[2] - rho[2]) * nrm[2]
    return status, g, nit


@njit(cache=True)
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
