"""Covariant geometry of a quad4 / quad9 master facet (docs/theory.md section 3).

At element coordinates (xi1, xi2) of a facet with current nodal positions ``xyz`` (n, 3):

    rho   = sum_k N_k x_k,   rho_i = d rho / d xi^i,   a_ij = rho_i . rho_j,   a^ij = (a_ij)^-1
    n     = rho_1 x rho_2 / |rho_1 x rho_2|   (out of the master body for outward node order)
    h_ij  = rho_,ij . n

All functions are compiled, write into caller-allocated arrays and never allocate.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from covcontact.fem.shapes import IDX, lagrange1d

_IDX4 = IDX["quad4"]
_IDX9 = IDX["quad9"]

#: relative threshold on |rho_1 x rho_2| / (|rho_1| |rho_2|) below which a facet point is degenerate
DEGENERATE_TOL = 1e-12


@njit(cache=True, error_model="numpy", inline="always")
def bilinear_coefficients(x0, x1, x2, x3):
    """One coordinate of a quad4 facet from its corner values: rho = a + b xi1 + c xi2 + d xi1 xi2; returns
    (a, b, c, d)."""
    return (0.25 * (x0 + x1 + x2 + x3), 0.25 * (x1 + x2 - x0 - x3), 0.25 * (x2 + x3 - x0 - x1),
            0.25 * (x0 + x2 - x1 - x3))


@njit(cache=True)
def surface_shapes(nen, xi1, xi2, N, dN, ddN):
    """Shape functions of a quad4 (nen = 4) or quad9 (nen = 9) facet, non-allocating.

    Writes N (nen,), dN (nen, 2), ddN (nen, 2, 2); VTK node order as ``fem.shapes``.
    """
    order = 1 if nen == 4 else 2
    for a in range(nen):
        if nen == 4:
            i = _IDX4[a, 0]
            j = _IDX4[a, 1]
        else:
            i = _IDX9[a, 0]
            j = _IDX9[a, 1]
        v1, d1, dd1 = lagrange1d(order, i, xi1)
        v2, d2, dd2 = lagrange1d(order, j, xi2)
        N[a] = v1 * v2
        dN[a, 0] = d1 * v2
        dN[a, 1] = v1 * d2
        ddN[a, 0, 0] = dd1 * v2
        ddN[a, 0, 1] = d1 * d2
        ddN[a, 1, 0] = d1 * d2
        ddN[a, 1, 1] = v1 * dd2


@njit(cache=True)
def facet_point(xyz, xi1, xi2, N, dN, ddN, rho):
    """Only the position rho(xi) (and the shape functions); cheaper than ``facet_geometry``."""
    nen = xyz.shape[0]
    surface_shapes(nen, xi1, xi2, N, dN, ddN)
    for p in range(3):
        s = 0.0
        for k in range(nen):
            s += N[k] * xyz[k, p]
        rho[p] = s


@njit(cache=True)
def facet_geometry(xyz, xi1, xi2, N, dN, ddN, rho, rho_cov, a_cov, a_con, n, h_cov):
    """All quantities of docs/theory.md section 3 at (xi1, xi2).

    Args:
        xyz: (nen, 3) nodal positions, nen = 4 or 9.
        xi1, xi2: element coordinates (not restricted to [-1, 1]).
        N, dN, ddN: (nen,), (nen, 2), (nen, 2, 2) out, shape functions.
        rho: (3,) out, position. rho_cov: (2, 3) out, covariant base vectors rho_i.
        a_cov, a_con: (2, 2) out, metric a_ij and its inverse a^ij.
        n: (3,) out, unit normal. h_cov: (2, 2) out, curvature h_ij.

    Returns:
        The area element |rho_1 x rho_2|; 0.0 at a degenerate point, where n, a_con and h_cov are
        set to zero.
    """
    nen = xyz.shape[0]
    surface_shapes(nen, xi1, xi2, N, dN, ddN)
    for p in range(3):
        s = 0.0
        s1 = 0.0
        s2 = 0.0
        for k in range(nen):
            x = xyz[k, p]
            s += N[k] * x
            s1 += dN[k, 0] * x
            s2 += dN[k, 1] * x
        rho[p] = s
        rho_cov[0, p] = s1
        rho_cov[1, p] = s2
    for i in range(2):
        for j in range(2):
            a_cov[i, j] = (
                rho_cov[i, 0] * rho_cov[j, 0] + rho_cov[i, 1] * rho_cov[j, 1] + rho_cov[i, 2] * rho_cov[j, 2]
            )
    c0 = rho_cov[0, 1] * rho_cov[1, 2] - rho_cov[0, 2] * rho_cov[1, 1]
    c1 = rho_cov[0, 2] * rho_cov[1, 0] - rho_cov[0, 0] * rho_cov[1, 2]
    c2 = rho_cov[0, 0] * rho_cov[1, 1] - rho_cov[0, 1] * rho_cov[1, 0]
    area = np.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
    ref = np.sqrt(a_cov[0, 0] * a_cov[1, 1])
    # det a = area^2 in exact arithmetic, but a_11 a_22 - a_12^2 loses it to cancellation once area / ref falls
    # below about 1e-8 (near a fold of a facet's continuation beyond its edges): there it can be zero or negative
    # although area passed the test, so the inverse is taken only where det is positive too
    det = a_cov[0, 0] * a_cov[1, 1] - a_cov[0, 1] * a_cov[1, 0]
    if not (area > DEGENERATE_TOL * ref) or not np.isfinite(area) or not (det > 0.0):
        for p in range(3):
            n[p] = 0.0
        for i in range(2):
            for j in range(2):
                a_con[i, j] = 0.0
                h_cov[i, j] = 0.0
        return 0.0
    n[0] = c0 / area
    n[1] = c1 / area
    n[2] = c2 / area
    a_con[0, 0] = a_cov[1, 1] / det
    a_con[1, 1] = a_cov[0, 0] / det
    a_con[0, 1] = -a_cov[0, 1] / det
    a_con[1, 0] = -a_cov[1, 0] / det
    for i in range(2):
        for j in range(i, 2):
            s = 0.0
            for k in range(nen):
                w = ddN[k, i, j]
                s += w * (xyz[k, 0] * n[0] + xyz[k, 1] * n[1] + xyz[k, 2] * n[2])
            h_cov[i, j] = s
            h_cov[j, i] = s
    return area


@njit(cache=True)
def raise_both(a_con, h_cov, h_con):
    """h^ij = a^ik h_kl a^lj into h_con (2, 2)."""
    for i in range(2):
        for j in range(2):
            s = 0.0
            for k in range(2):
                for m in range(2):
                    s += a_con[i, k] * h_cov[k, m] * a_con[m, j]
            h_con[i, j] = s
