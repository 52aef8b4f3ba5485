"""Total-Lagrangian solid elements: tangent and residual against finite differences, rigid-body
motion, inverted elements, several bodies in one pattern, homogeneous stress."""

from __future__ import annotations

import numpy as np
import pytest

from covcontact.assembly import Pattern
from covcontact.elements import SolidBody
from covcontact.fem.shapes import NODES
from covcontact.materials import NeoHooke, SaintVenantKirchhoff

MATERIALS = {"svk": SaintVenantKirchhoff(E=200.0, nu=0.3), "neo-hooke": NeoHooke(E=200.0, nu=0.3)}


def two_elements(cell: str, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Two distorted elements of ``cell`` sharing a face (x = 1), nodes merged."""
    rng = np.random.default_rng(seed)
    ref = NODES[cell]
    pts = np.vstack([ref, ref + [2.0, 0.0, 0.0]])
    X, inv = np.unique(np.round(pts, 12), axis=0, return_inverse=True)
    cells = inv.reshape(2, -1).astype(np.int64)
    X = 0.5 * X * [1.0, 0.8, 1.3] + 0.08 * rng.uniform(-1.0, 1.0, X.shape)
    return np.ascontiguousarray(X), cells


def residual(body: SolidBody, u: np.ndarray) -> np.ndarray:
    r = np.zeros(3 * body.n_nodes)
    assert body.assemble(u, np.zeros(0), r, None, want_K=False) == -1
    return r


def tangent(body: SolidBody, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    P = Pattern(body.n_nodes, [body.cells])
    data = P.zeros()
    r = np.zeros(3 * body.n_nodes)
    assert body.assemble(u, data, r, P) == -1
    return P.csr(data).toarray(), r


@pytest.mark.parametrize("mat", list(MATERIALS))
@pytest.mark.parametrize("cell", ["hex8", "hex27", "hex18"])
def test_tangent_and_residual_match_fd(cell, mat):
    X, cells = two_elements(cell, seed=1)
    body = SolidBody(cell, X, cells, MATERIALS[mat])
    assert body.check_reference() == []
    u = 0.12 * np.random.default_rng(2).uniform(-1.0, 1.0, X.shape)  # large: ~25% of the element size
    K, r = tangent(body, u)
    assert np.allclose(r, residual(body, u), rtol=0, atol=1e-14 * np.abs(r).max())
    h = 1e-6
    Kfd = np.empty_like(K)
    gfd = np.empty(3 * body.n_nodes)
    for j in range(3 * body.n_nodes):
        up = u.copy().ravel()
        um = u.copy().ravel()
        up[j] += h
        um[j] -= h
        Kfd[:, j] = (residual(body, up) - residual(body, um)) / (2.0 * h)
        gfd[j] = (body.energy(up) - body.energy(um)) / (2.0 * h)
    assert np.abs(K - Kfd).max() <= 1e-6 * np.abs(K).max()
    assert np.abs(K - K.T).max() <= 1e-12 * np.abs(K).max()
    assert np.abs(r - gfd).max() <= 1e-6 * np.abs(r).max()


def rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    a = axis / np.linalg.norm(axis)
    W = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    return np.eye(3) + np.sin(angle) * W + (1.0 - np.cos(angle)) * W @ W  # Rodrigues


@pytest.mark.parametrize("cell", ["hex8", "hex27"])
def test_rigid_body_motion_is_stress_free(cell):
    X, cells = two_elements(cell, seed=3)
    body = SolidBody(cell, X, cells, MATERIALS["svk"])
    scale = 200.0 * 0.5**2  # E times a face area: the size of nodal forces under unit strain
    t = np.array([0.3, -1.2, 2.0])
    assert np.abs(residual(body, np.tile(t, (body.n_nodes, 1)))).max() <= 1e-12 * scale
    R = rotation(np.array([1.0, 2.0, -0.5]), 1.1)  # a finite rotation of 63 degrees
    u = X @ R.T - X + t
    assert np.abs(residual(body, u)).max() <= 1e-12 * scale
    assert abs(body.energy(u)) <= 1e-24 * scale
    # the tangent of a rotated stress-free body is the rotated initial stiffness
    K0 = tangent(body, np.zeros_like(X))[0]
    Rb = np.kron(np.eye(body.n_nodes), R)
    assert np.abs(tangent(body, u)[0] - Rb @ K0 @ Rb.T).max() <= 1e-10 * np.abs(K0).max()


@pytest.mark.parametrize("mat", list(MATERIALS))
def test_inverted_element_is_reported_and_outputs_stay_finite(mat):
    X, cells = two_elements("hex8", seed=4)
    body = SolidBody("hex8", X, cells, MATERIALS[mat])
    u = np.zeros_like(X)
    only2 = np.setdiff1d(cells[1], cells[0])
    u[only2, 0] = -1.5  # the far face of element 1 pushed through its shared face: det F < 0
    P = Pattern(body.n_nodes, [cells])
    data = P.zeros()
    r = np.zeros(3 * body.n_nodes)
    assert body.assemble(u, data, r, P) == 1
    assert np.isfinite(data).all() and np.isfinite(r).all()


def test_check_reference_finds_inverted_cells():
    X, cells = two_elements("hex8", seed=5)
    bad = cells.copy()
    bad[1] = bad[1][[4, 5, 6, 7, 0, 1, 2, 3]]  # top and bottom faces swapped: det J0 < 0
    assert SolidBody("hex8", X, bad, MATERIALS["svk"]).check_reference() == [1]
    with pytest.raises(ValueError, match="cells"):
        SolidBody("hex8", X, cells[:, :4], MATERIALS["svk"])
    with pytest.raises(ValueError, match="cell type"):
        SolidBody("pyramid5", X, cells, MATERIALS["svk"])


def test_two_bodies_in_one_pattern():
    X1, c1 = two_elements("hex8", seed=6)
    X2, c2 = two_elements("hex27", seed=7)
    b1 = SolidBody("hex8", X1, c1, MATERIALS["svk"])
    b2 = SolidBody("hex27", X2, c2, MATERIALS["neo-hooke"])
    n1 = b1.n_nodes
    n = n1 + b2.n_nodes + 2  # two spare nodes (e.g. rigid-body reference nodes)
    P = Pattern(n, [c1, c2 + n1])
    rng = np.random.default_rng(8)
    u1 = 0.05 * rng.standard_normal(X1.shape)
    u2 = 0.05 * rng.standard_normal(X2.shape)
    data = P.zeros()
    r = np.zeros(3 * n)
    assert b1.assemble(u1, data, r, P) == -1
    assert b2.assemble(u2, data, r, P, node_offset=n1) == -1
    K = P.csr(data).toarray()
    K1, r1 = tangent(b1, u1)
    K2, r2 = tangent(b2, u2)
    m1, m2 = 3 * n1, 3 * (n1 + b2.n_nodes)
    assert np.array_equal(K[:m1, :m1], K1) and np.array_equal(K[m1:m2, m1:m2], K2)
    assert not K[:m1, m1:].any() and not K[m2:].any()
    assert np.array_equal(r[:m1], r1) and np.array_equal(r[m1:m2], r2) and not r[m2:].any()


@pytest.mark.parametrize("cell", ["hex8", "hex27"])
def test_homogeneous_stretch_stress_and_energy(cell):
    X, cells = two_elements(cell, seed=9)
    mat = MATERIALS["svk"]
    body = SolidBody(cell, X, cells, mat)
    lam = 1.2
    u = X * [lam - 1.0, 0.0, 0.0]
    # uniaxial deformation F = diag(lam, 1, 1): E11 = (lam^2 - 1)/2, S11 = (lambda + 2 mu) E11,
    # S22 = S33 = lambda E11, sigma = F S F^T / J
    E11 = 0.5 * (lam**2 - 1.0)
    S11, S22 = (mat.lam + 2.0 * mat.mu) * E11, mat.lam * E11
    st = body.stress(u)
    ref = np.array([lam * S11, S22 / lam, S22 / lam, 0.0, 0.0, 0.0])
    for field in (st.cauchy, st.cauchy_nodal):
        assert np.abs(field - ref).max() <= 1e-12 * S11
    assert np.abs(st.pk2 - [S11, S22, S22, 0, 0, 0]).max() <= 1e-12 * S11
    assert np.abs(st.green_lagrange - [E11, 0, 0, 0, 0, 0]).max() <= 1e-14
    assert np.allclose(st.von_mises, abs(lam * S11 - S22 / lam), rtol=1e-12)
    # strain energy of a homogeneous deformation is W(F) times the volume: compare two deformations
    W = 0.5 * mat.lam * E11**2 + mat.mu * E11**2  # W = lambda/2 (tr E)^2 + mu E:E
    g = 0.3
    u2 = X @ np.array([[0.0, g, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]).T  # simple shear F = I + g e1 (x) e2
    E2 = 0.5 * np.array([[0.0, g, 0.0], [g, g * g, 0.0], [0.0, 0.0, 0.0]])
    W2 = 0.5 * mat.lam * np.trace(E2) ** 2 + mat.mu * np.sum(E2 * E2)
    assert abs(body.energy(u) / W - body.energy(u2) / W2) <= 1e-12 * body.energy(u) / W
    assert set(st.cell_data()) == {"cauchy", "pk2", "green_lagrange", "von_mises"}
