"""Contact laws, each written once: the normal law (penalty or augmented Lagrangian, optionally smoothed over
a band of gaps) and the inverse of
c_ij = a_ij - g h_ij that the exact tangents and the friction kernels share (docs/theory.md section 3).

The kernels take the law as (eps_N, lam_k, band): band = 0 the penalty law, band > 0 the penalty law
smoothed over that width, band = -c0 < 0 the exponential pressure-overclosure law with clearance c0 (eps_N
then the nodal force at zero gap).

Normal law: with the Uzawa multiplier lam_k <= 0 of the last update (0 for pure penalty) the effective
gap is g_e = g + lam_k / eps_N, the normal traction lam_N = eps_N <g_e> = <lam_k + eps_N g> and the pair
is *active* when g_e <= 0 (also at a small positive geometric gap g when lam_k < 0). The functions are
compiled and accept scalars (inside kernels) or arrays (in the Python layer) alike.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def effective_gap(g, lam_k, eps_n):
    """g_e = g + lam_k / eps_N (scalars or arrays)."""
    return g + lam_k / eps_n


@njit(cache=True)
def is_active(g, lam_k, eps_n, band=0.0):
    """The activity test g + lam_k / eps_N <= 0, or < band / 2 with a smoothing band, or g < c0 for the
    exponential law (band = -c0) (scalars or arrays; +inf gaps are inactive)."""
    if band > 0.0:
        return effective_gap(g, lam_k, eps_n) < 0.5 * band
    if band < 0.0:
        return g < -band
    return effective_gap(g, lam_k, eps_n) <= 0.0


#: the exponential law continues linearly beyond this value of t = 1 - g / c0 (an overclosure of 2 c0)
EXP_T_MAX = 3.0


@njit(cache=True)
def exponential_law(g, eps_n, c0):
    """The exponential pressure-overclosure law (scalars): (sigma, dsigma). eps_n is the nodal force at zero
    gap (p0 times the node's area), c0 the clearance at which the force starts; with t = 1 - g / c0:
    sigma = -eps_n t (e^t - 1) / (e - 1) for 0 < t <= EXP_T_MAX, continued linearly beyond."""
    t = 1.0 - g / c0
    if t <= 0.0:
        return 0.0, 0.0
    scale = eps_n / (np.e - 1.0)
    if t <= EXP_T_MAX:
        et = np.exp(t)
        return -scale * t * (et - 1.0), scale * (et - 1.0 + t * et) / c0
    et = np.exp(EXP_T_MAX)
    slope = scale * (et - 1.0 + EXP_T_MAX * et) / c0
    return -scale * EXP_T_MAX * (et - 1.0) - slope * (t - EXP_T_MAX) * c0, slope


@njit(cache=True)
def smooth_law(g, lam_k, eps_n, band):
    """The smoothed normal law (scalars): (sigma, dsigma), sigma = -lam_N <= 0 the signed normal traction and
    dsigma its derivative by g. With b = band / 2 and g_e = g + lam_k / eps_N: sigma = eps_N g_e for
    g_e <= -b (the penalty law itself), -eps_N (b - g_e)^2 / (4 b) for |g_e| < b, 0 beyond: C1 at the
    band's ends."""
    ge = effective_gap(g, lam_k, eps_n)
    b = 0.5 * band
    if ge <= -b:
        return eps_n * ge, eps_n
    if ge >= b:
        return 0.0, 0.0
    t = b - ge
    return -eps_n * t * t / (4.0 * b), eps_n * t / (2.0 * b)


@njit(cache=True)
def linear_equivalent(g, lam_k, eps_n, band):
    """(eps', lam_k') of the linear law lam_k' + eps' g that has the smoothed law's traction and slope at this
    g (an active g: g_e < band / 2): the kernels, written for the linear law, then evaluate the smoothed one
    exactly (residual sigma n, tangent dsigma n n + sigma hess g)."""
    if band == 0.0:
        return eps_n, lam_k
    if band > 0.0:
        sig, dsig = smooth_law(g, lam_k, eps_n, band)
    else:
        sig, dsig = exponential_law(g, eps_n, -band)
    return dsig, sig - dsig * g


def linear_equivalents(g: np.ndarray, lam_k: np.ndarray, eps_n: np.ndarray, band: float):
    """``linear_equivalent`` over arrays of active slaves."""
    if band == 0.0:
        return eps_n, lam_k
    e = np.empty_like(eps_n)
    m = np.empty_like(lam_k)
    for k in range(len(g)):
        e[k], m[k] = linear_equivalent(g[k], lam_k[k], eps_n[k], band)
    return e, m


@njit(cache=True)
def normal_pressure(g, lam_k, eps_n):
    """lam_k + eps_N g: minus the normal traction of an active pair (negative in contact)."""
    return lam_k + eps_n * g


def uzawa_update(lam_k: np.ndarray, g: np.ndarray, eps_n: np.ndarray, band: float = 0.0) -> np.ndarray:
    """The augmented-Lagrangian update lam_k <- min(lam_k + eps_N g, 0) (gaps without contact point: 0); with
    a smoothing band lam_k <- sigma(g), the smoothed traction."""
    gg = np.where(np.isfinite(g), g, 0.0)
    if band > 0.0:
        return np.array([min(smooth_law(gg[k], lam_k[k], eps_n[k], band)[0], 0.0) for k in range(len(gg))])
    return np.minimum(normal_pressure(gg, lam_k, eps_n), 0.0)


@njit(cache=True)
def c_inverse(a_cov, a_con, h_cov, g, out):
    """out = c^ij, the inverse of c_ij = a_ij - g h_ij; a^ij where c_ij is singular (the slave on the focal
    surface of the master, where the exact Hessian does not exist). Returns True when c_ij was invertible."""
    c00 = a_cov[0, 0] - g * h_cov[0, 0]
    c01 = a_cov[0, 1] - g * h_cov[0, 1]
    c11 = a_cov[1, 1] - g * h_cov[1, 1]
    detc = c00 * c11 - c01 * c01
    if abs(detc) > 1e-14 * abs(a_cov[0, 0] * a_cov[1, 1]):
        out[0, 0] = c11 / detc
        out[1, 1] = c00 / detc
        out[0, 1] = -c01 / detc
        out[1, 0] = -c01 / detc
        return True
    for i in range(2):
        for j in range(2):
            out[i, j] = a_con[i, j]
    return False
