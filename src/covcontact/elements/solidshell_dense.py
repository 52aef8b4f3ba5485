"""Small dense factorisations of the solid-shells' local EAS Newton (:mod:`.solidshell_kernels`): Cholesky
when the EAS matrix H is positive definite, LU with partial pivoting otherwise (materials with history),
on the leading n x n block of preallocated arrays (no allocation inside the element loop)."""

from __future__ import annotations

import math

from numba import njit


@njit(cache=True)
def _chol(A, n, L):
    """Lower Cholesky factor L of the leading n x n block of A; False if not positive definite."""
    for i in range(n):
        for j in range(i + 1):
            s = A[i, j]
            for k in range(j):
                s -= L[i, k] * L[j, k]
            if i == j:
                if not (s > 0.0):
                    return False
                L[i, i] = math.sqrt(s)
            else:
                L[i, j] = s / L[j, j]
    return True


@njit(cache=True)
def _chol_solve(L, n, b):
    """b <- A^-1 b with A = L L^T (n x n)."""
    for i in range(n):
        s = b[i]
        for k in range(i):
            s -= L[i, k] * b[k]
        b[i] = s / L[i, i]
    for i in range(n - 1, -1, -1):
        s = b[i]
        for k in range(i + 1, n):
            s -= L[k, i] * b[k]
        b[i] = s / L[i, i]


@njit(cache=True)
def _lu(A, n, LU, piv):
    """LU factors with partial pivoting of the leading n x n block of A (into LU, row swaps in piv);
    False if singular. The EAS matrix of a material with history falls back to it when H is indefinite
    (an algorithmic tangent that is not positive definite)."""
    for i in range(n):
        for j in range(n):
            LU[i, j] = A[i, j]
    for k in range(n):
        p = k
        big = abs(LU[k, k])
        for i in range(k + 1, n):
            if abs(LU[i, k]) > big:
                big = abs(LU[i, k])
                p = i
        piv[k] = p
        if not (big > 0.0):
            return False
        if p != k:
            for j in range(n):
                t = LU[k, j]
                LU[k, j] = LU[p, j]
                LU[p, j] = t
        for i in range(k + 1, n):
            f = LU[i, k] / LU[k, k]
            LU[i, k] = f
            for j in range(k + 1, n):
                LU[i, j] -= f * LU[k, j]
    return True


@njit(cache=True)
def _lu_solve(LU, piv, n, b):
    """b <- A^-1 b with the factors of :func:`_lu`."""
    for k in range(n):
        p = piv[k]
        if p != k:
            t = b[k]
            b[k] = b[p]
            b[p] = t
    for i in range(n):
        s = b[i]
        for k in range(i):
            s -= LU[i, k] * b[k]
        b[i] = s
    for i in range(n - 1, -1, -1):
        s = b[i]
        for k in range(i + 1, n):
            s -= LU[i, k] * b[k]
        b[i] = s / LU[i, i]


@njit(cache=True)
def _factor(H, n, Hf, piv, allow_lu):
    """Factor the EAS matrix: 1 Cholesky (H positive definite), 2 LU (only if allow_lu), 0 failed."""
    if _chol(H, n, Hf):
        return 1
    if allow_lu and _lu(H, n, Hf, piv):
        return 2
    return 0


@njit(cache=True)
def _solve(Hf, piv, n, b, mode):
    """b <- H^-1 b with the factors of :func:`_factor` (mode 1 Cholesky, 2 LU)."""
    if mode == 1:
        _chol_solve(Hf, n, b)
    else:
        _lu_solve(Hf, piv, n, b)
