"""Contact laws, each written once: the normal law (penalty or augmented Lagrangian) and the inverse of
c_ij = a_ij - g h_ij that the exact tangents and the friction kernels share (docs/theory.md section 3).

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
def is_active(g, lam_k, eps_n):
    """The activity test g + lam_k / eps_N <= 0 (scalars or arrays; +inf gaps are inactive)."""
    return effective_gap(g, lam_k, eps_n) <= 0.0


@njit(cache=True)
def normal_pressure(g, lam_k, eps_n):
    """lam_k + eps_N g: minus the normal traction of an active pair (negative in contact)."""
    return lam_k + eps_n * g


def uzawa_update(lam_k: np.ndarray, g: np.ndarray, eps_n: np.ndarray) -> np.ndarray:
    """The augmented-Lagrangian update lam_k <- min(lam_k + eps_N g, 0) (gaps without contact point: 0)."""
    gg = np.where(np.isfinite(g), g, 0.0)
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
