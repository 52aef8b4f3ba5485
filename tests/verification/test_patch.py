"""Patch tests of the solid hexahedra on a distorted 2x2x2 block.

Reference: the patch test of Irons (Irons & Razzaque 1972; Zienkiewicz & Taylor, The Finite Element
Method, vol. 1, ch. 10): with a linear displacement field imposed on the boundary, a consistent
element reproduces that field at the interior nodes and a constant stress, on any distorted mesh.
A homogeneous deformation is also an exact solution of the nonlinear (large strain) problem.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse.linalg as spla

from covcontact.assembly import Pattern
from covcontact.elements import SolidBody
from covcontact.fem.shapes import IDX
from covcontact.materials import NeoHooke, SaintVenantKirchhoff


def distorted_block(cell: str, n: int = 2, seed: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """n^3 elements of ``cell`` on [0, 1]^3 with the interior nodes moved; returns X, cells, boundary."""
    p = 1 if cell == "hex8" else 2
    m = p * n + 1
    pos = np.array([0, p, 1])  # 1D node index (-1, 1, 0) -> position in the element's local grid
    i, j, k = np.meshgrid(np.arange(n), np.arange(n), np.arange(n), indexing="ij")
    base = p * np.stack([i.ravel(), j.ravel(), k.ravel()], axis=1)
    loc = pos[IDX[cell]]
    g = base[:, None, :] + loc[None, :, :]
    cells = (g[..., 0] + m * g[..., 1] + m * m * g[..., 2]).astype(np.int64)
    a, b, c = np.meshgrid(np.arange(m), np.arange(m), np.arange(m), indexing="ij")
    grid = np.stack([a.T.ravel(), b.T.ravel(), c.T.ravel()], axis=1)
    X = grid / (m - 1.0)
    boundary = np.flatnonzero(((grid == 0) | (grid == m - 1)).any(axis=1))
    interior = np.setdiff1d(np.arange(X.shape[0]), boundary)
    rng = np.random.default_rng(seed)
    X[interior] += 0.3 / (m - 1.0) * rng.uniform(-1.0, 1.0, (interior.size, 3))
    return X, cells, boundary


def linear_field(X: np.ndarray, scale: float, seed: int = 1) -> np.ndarray:
    rng = np.random.default_rng(seed)
    A = scale * rng.uniform(-1.0, 1.0, (3, 3))
    return X @ A.T + scale * rng.uniform(-1.0, 1.0, 3)


def system(body: SolidBody, P: Pattern, u: np.ndarray):
    data = P.zeros()
    r = np.zeros(P.n_dofs)
    assert body.assemble(u, data, r, P) == -1
    return P.csr(data), r


@pytest.mark.parametrize("cell", ["hex8", "hex27"])
def test_linear_patch_test(cell):
    X, cells, boundary = distorted_block(cell)
    body = SolidBody(cell, X, cells, SaintVenantKirchhoff(E=1000.0, nu=0.3))
    assert body.check_reference() == []
    P = Pattern(body.n_nodes, [cells])
    fixed = (3 * boundary[:, None] + np.arange(3)).ravel()
    free = np.setdiff1d(np.arange(P.n_dofs), fixed)
    assert free.size >= 3
    u_lin = linear_field(X, 1.0)
    # linear problem: initial stiffness K0, residual K0 u_b of the boundary values
    K0 = system(body, P, np.zeros_like(X))[0]
    u_b = np.zeros(P.n_dofs)
    u_b[fixed] = u_lin.ravel()[fixed]
    r = K0 @ u_b
    u = u_b.copy()
    u[free] = spla.spsolve(K0[free][:, free].tocsc(), -r[free])
    assert np.abs(u[free] - u_lin.ravel()[free]).max() <= 1e-10 * np.abs(u_lin).max()
    # the linear stress K0 u is zero at the interior dofs
    assert np.abs((K0 @ u)[free]).max() <= 1e-10 * np.abs(K0 @ u).max()
    # a linear displacement gives a homogeneous deformation: constant stress in every element
    st = body.stress(u.reshape(-1, 3))
    ref = np.abs(st.cauchy).max()
    assert ref > 0.0
    assert np.abs(st.cauchy - st.cauchy[0]).max() <= 1e-10 * ref
    assert np.abs(st.cauchy_nodal - st.cauchy[0]).max() <= 1e-10 * ref


@pytest.mark.parametrize("material", [SaintVenantKirchhoff(E=1000.0, nu=0.3), NeoHooke(E=1000.0, nu=0.45)],
                         ids=["svk", "neo-hooke"])
@pytest.mark.parametrize("cell", ["hex8", "hex27"])
def test_nonlinear_patch_test(cell, material):
    X, cells, boundary = distorted_block(cell, seed=2)
    body = SolidBody(cell, X, cells, material)
    P = Pattern(body.n_nodes, [cells])
    fixed = (3 * boundary[:, None] + np.arange(3)).ravel()
    free = np.setdiff1d(np.arange(P.n_dofs), fixed)
    u_lin = linear_field(X, 0.15, seed=3)  # a large homogeneous deformation (15 % strains)
    # start from the linear field with the interior nodes displaced randomly (a few % of the spacing)
    u = u_lin.ravel() + 0.05 / (np.cbrt(body.n_nodes) - 1.0) * np.random.default_rng(4).uniform(-1, 1, P.n_dofs)
    u[fixed] = u_lin.ravel()[fixed]
    assert np.abs(u[free] - u_lin.ravel()[free]).max() > 1e-3
    for _ in range(20):  # Newton on the interior dofs
        K, r = system(body, P, u.reshape(-1, 3))
        if np.abs(r[free]).max() <= 1e-11 * np.abs(r).max():
            break
        u[free] -= spla.spsolve(K[free][:, free].tocsc(), r[free])
    else:
        pytest.fail("Newton did not converge on the nonlinear patch")
    assert np.abs(u[free] - u_lin.ravel()[free]).max() <= 1e-10 * np.abs(u_lin).max()
    st = body.stress(u.reshape(-1, 3))
    assert np.abs(st.cauchy - st.cauchy[0]).max() <= 1e-10 * np.abs(st.cauchy).max()
