"""Spectral tools of the matrix logarithm: a 3 x 3 symmetric eigensolver (cyclic Jacobi) and the first and
second divided differences of f(x) = 1/2 ln x with their Taylor limits for (nearly) equal arguments
(docs/theory.md, section 12)."""

from __future__ import annotations

import math

from numba import njit

@njit(cache=True, inline="always")
def _jacobi_rot(app, aqq, apq):
    """Jacobi rotation (t, c, s) annihilating apq of the symmetric pair block [[app, apq], [apq, aqq]]."""
    d = aqq - app
    if abs(apq) < 1e-5 * abs(d):
        x = apq / d
        t = x * (1.0 - x * x)  # t = x - x^3 + O(x^5)
        c = 1.0 - 0.5 * t * t  # 1/sqrt(1 + t^2) + O(t^4)
    else:
        t = 2.0 * apq / (abs(d) + math.sqrt(d * d + 4.0 * apq * apq))
        if d < 0.0:
            t = -t
        c = 1.0 / math.sqrt(1.0 + t * t)
    return t, c, t * c


@njit(cache=True)
def _eigh3(a00, a11, a22, a01, a12, a02, w, V):
    """Eigenvalues w (3,) and eigenvectors V (columns) of a symmetric 3x3 matrix by cyclic Jacobi,
    iterated until the off-diagonal part is below 1e-17 of the diagonal."""
    v00 = 1.0
    v01 = 0.0
    v02 = 0.0
    v10 = 0.0
    v11 = 1.0
    v12 = 0.0
    v20 = 0.0
    v21 = 0.0
    v22 = 1.0
    for _sweep in range(40):
        if abs(a01) + abs(a12) + abs(a02) <= 1e-17 * (abs(a00) + abs(a11) + abs(a22)):
            break
        if a01 != 0.0:  # (p, q) = (0, 1), r = 2
            t, c, s = _jacobi_rot(a00, a11, a01)
            a00 -= t * a01
            a11 += t * a01
            a01 = 0.0
            g = a02
            a02 = c * g - s * a12
            a12 = s * g + c * a12
            g = v00
            v00 = c * g - s * v01
            v01 = s * g + c * v01
            g = v10
            v10 = c * g - s * v11
            v11 = s * g + c * v11
            g = v20
            v20 = c * g - s * v21
            v21 = s * g + c * v21
        if a12 != 0.0:  # (p, q) = (1, 2), r = 0
            t, c, s = _jacobi_rot(a11, a22, a12)
            a11 -= t * a12
            a22 += t * a12
            a12 = 0.0
            g = a01
            a01 = c * g - s * a02
            a02 = s * g + c * a02
            g = v01
            v01 = c * g - s * v02
            v02 = s * g + c * v02
            g = v11
            v11 = c * g - s * v12
            v12 = s * g + c * v12
            g = v21
            v21 = c * g - s * v22
            v22 = s * g + c * v22
        if a02 != 0.0:  # (p, q) = (0, 2), r = 1
            t, c, s = _jacobi_rot(a00, a22, a02)
            a00 -= t * a02
            a22 += t * a02
            a02 = 0.0
            g = a01
            a01 = c * g - s * a12
            a12 = s * g + c * a12
            g = v00
            v00 = c * g - s * v02
            v02 = s * g + c * v02
            g = v10
            v10 = c * g - s * v12
            v12 = s * g + c * v12
            g = v20
            v20 = c * g - s * v22
            v22 = s * g + c * v22
    w[0] = a00
    w[1] = a11
    w[2] = a22
    V[0, 0] = v00
    V[0, 1] = v01
    V[0, 2] = v02
    V[1, 0] = v10
    V[1, 1] = v11
    V[1, 2] = v12
    V[2, 0] = v20
    V[2, 1] = v21
    V[2, 2] = v22


@njit(cache=True, inline="always")
def _dd1(la, lb, ea, eb):
    """First divided difference of f(x) = ln(x)/2 at la, lb (ea = f(la), eb = f(lb)).

    With d = ea - eb: (ea - eb)/(la - lb) for |d| >= 1e-3, else g(d) / (2 sqrt(la lb)) with
    g(d) = d / sinh d = 1 - d^2/6 + 7 d^4/360 + O(d^6) (la - lb = 2 sqrt(la lb) sinh d); the limit
    la = lb gives f'(la) = 1/(2 la) exactly.
    """
    d = ea - eb
    if abs(d) >= 1e-3:
        return d / (la - lb)
    d2 = d * d
    return 0.5 * (1.0 - d2 / 6.0 + 7.0 * d2 * d2 / 360.0) / math.sqrt(la * lb)


@njit(cache=True, inline="always")
def _dd2(x0, x1, x2, t01, t12, t02):
    """Second divided difference of f(x) = ln(x)/2 at x0, x1, x2 (t_ij the first divided differences).

    Divided by the largest separation when that is > 1e-3 of the largest value; else the Taylor series
    about the mean m: f[.,.,.] = (-1/4 - h2/8 + h3/10 - h4/12) / m^2 with h_k the complete homogeneous
    symmetric polynomials of (x_i - m)/m (h2 = -e2, h3 = e3, h4 = e2^2 in the elementary ones).
    """
    d01 = abs(x0 - x1)
    d12 = abs(x1 - x2)
    d02 = abs(x0 - x2)
    big = max(x0, max(x1, x2))
    if d02 >= d01 and d02 >= d12:
        if d02 > 1e-3 * big:
            return (t12 - t01) / (x2 - x0)  # pivot x1
    elif d01 >= d12:
        if d01 > 1e-3 * big:
            return (t02 - t12) / (x0 - x1)  # pivot x2
    else:
        if d12 > 1e-3 * big:
            return (t01 - t02) / (x1 - x2)  # pivot x0
    m = (x0 + x1 + x2) / 3.0
    v0 = (x0 - m) / m
    v1 = (x1 - m) / m
    v2 = (x2 - m) / m
    e2 = v0 * v1 + v1 * v2 + v0 * v2
    e3 = v0 * v1 * v2
    return (-0.25 + e2 / 8.0 + e3 / 10.0 - e2 * e2 / 12.0) / (m * m)
