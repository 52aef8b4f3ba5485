"""Gauss-Legendre rules on [-1, 1]^d as (points, weights)."""

from __future__ import annotations

import numpy as np


def gauss_1d(n: int) -> tuple[np.ndarray, np.ndarray]:
    """n-point Gauss-Legendre rule on [-1, 1]: exact for polynomials of degree 2n - 1."""
    if n < 1:
        raise ValueError("a Gauss rule needs at least one point")
    x, w = np.polynomial.legendre.leggauss(n)
    return x, w


def gauss_tensor(orders: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Tensor-product Gauss rule with ``orders[d]`` points in direction d.

    Points are ordered with the first direction running fastest. Returns points (npts, dim) and
    weights (npts,).
    """
    rules = [gauss_1d(n) for n in orders]
    grids = np.meshgrid(*[r[0] for r in rules], indexing="ij")
    wgrids = np.meshgrid(*[r[1] for r in rules], indexing="ij")
    pts = np.stack([g.transpose().ravel() for g in grids], axis=1)
    w = np.prod(np.stack([g.transpose().ravel() for g in wgrids], axis=1), axis=1)
    return np.ascontiguousarray(pts), w


def gauss_quad(n: int) -> tuple[np.ndarray, np.ndarray]:
    """n x n rule on the square."""
    return gauss_tensor((n, n))


def gauss_hex(n: int, nt: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """n x n x nt rule on the cube (nt defaults to n)."""
    return gauss_tensor((n, n, n if nt is None else nt))


#: default full-integration rules per cell type
DEFAULT_RULE = {"quad4": (2, 2), "quad9": (3, 3), "hex8": (2, 2, 2), "hex18": (3, 3, 2), "hex27": (3, 3, 3)}


def default_rule(cell: str) -> tuple[np.ndarray, np.ndarray]:
    """Full-integration Gauss rule for ``cell``."""
    return gauss_tensor(DEFAULT_RULE[cell])
