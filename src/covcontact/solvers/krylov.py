"""Right-preconditioned GMRES, the Krylov method of the inexact Newton corrections (docs/theory.md section 2)
and of the single-precision factorisations' refinement."""

from __future__ import annotations

import numpy as np


def gmres_right(A, b: np.ndarray, prec, tol: float, m: int, partial: bool = False, flexible: bool = False):
    """One cycle of GMRES(m) on A x = b from x = 0 with right preconditioning x = prec(y): the Arnoldi basis
    by classical Gram-Schmidt with one reorthogonalisation, Givens rotations for the least-squares problem.
    Returns (x or None if ||b - A x|| > tol ||b|| after m iterations, iterations); with ``partial`` the
    minimiser after m iterations is returned even when it misses the tolerance (None only at a breakdown).
    ``flexible`` keeps the preconditioned vectors and forms x from them (FGMRES): needed when prec is not
    linear to working precision, e.g. a substitution in single precision, where prec(sum y_j v_j) differs
    from sum y_j prec(v_j) by the single-precision rounding."""
    n = b.shape[0]
    beta = float(np.linalg.norm(b))
    if beta == 0.0:
        return np.zeros(n), 0
    V = np.empty((m + 1, n))
    Z = np.empty((m, n)) if flexible else None
    H = np.zeros((m + 1, m))
    cs = np.zeros(m)
    sn = np.zeros(m)
    g = np.zeros(m + 1)
    g[0] = beta
    V[0] = b / beta
    k = 0
    for j in range(m):
        z = prec(V[j])
        if Z is not None:
            Z[j] = z
        w = A @ z
        h = V[: j + 1] @ w
        w -= h @ V[: j + 1]
        h2 = V[: j + 1] @ w  # reorthogonalise once
        w -= h2 @ V[: j + 1]
        h += h2
        hn = float(np.linalg.norm(w))
        H[: j + 1, j] = h
        H[j + 1, j] = hn
        for i in range(j):  # the earlier rotations on the new column
            a, c = H[i, j], H[i + 1, j]
            H[i, j], H[i + 1, j] = cs[i] * a + sn[i] * c, -sn[i] * a + cs[i] * c
        r = float(np.hypot(H[j, j], H[j + 1, j]))
        if r == 0.0:
            return None, j + 1
        cs[j], sn[j] = H[j, j] / r, H[j + 1, j] / r
        H[j, j], H[j + 1, j] = r, 0.0
        g[j + 1] = -sn[j] * g[j]
        g[j] = cs[j] * g[j]
        k = j + 1
        if abs(g[j + 1]) <= tol * beta:
            break
        if hn == 0.0:
            if partial:
                break
            return None, k
        V[j + 1] = w / hn
    if abs(g[k]) > tol * beta and not partial:
        return None, k
    y = np.linalg.solve(np.triu(H[:k, :k]), g[:k])
    return (y @ Z[:k] if Z is not None else prec(y @ V[:k])), k
