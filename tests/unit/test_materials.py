"""Hyperelastic materials: tangent and stress against finite differences, symmetry, small-strain limit,
objectivity, validation."""

from __future__ import annotations

import numpy as np
import pytest

from covcontact.materials import (
    NEO_HOOKE,
    SVK,
    NeoHooke,
    SaintVenantKirchhoff,
    material_from_name,
    strain_energy,
    stress_tangent,
)

MATERIALS = [SaintVenantKirchhoff(E=210.0, nu=0.3), NeoHooke(E=210.0, nu=0.3), NeoHooke(E=3.0, nu=0.45)]
PAIRS = [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (0, 2)]


def random_F(seed: int, amp: float = 0.3) -> np.ndarray:
    """A random deformation gradient with det F > 0 (stretch and rotation)."""
    rng = np.random.default_rng(seed)
    F = np.eye(3) + amp * rng.uniform(-1.0, 1.0, (3, 3))
    assert np.linalg.det(F) > 0.2
    return F


def F_of_E(E: np.ndarray) -> np.ndarray:
    """The symmetric stretch U = sqrt(I + 2E): a deformation gradient whose Green-Lagrange strain is E."""
    lam, V = np.linalg.eigh(np.eye(3) + 2.0 * E)
    return (V * np.sqrt(lam)) @ V.T


def green_lagrange(F: np.ndarray) -> np.ndarray:
    return 0.5 * (F.T @ F - np.eye(3))


def perturb(E: np.ndarray, J: int, h: float) -> np.ndarray:
    """E plus h in Voigt component J with engineering shear (h/2 on both off-diagonal entries)."""
    i, j = PAIRS[J]
    Ep = E.copy()
    if i == j:
        Ep[i, i] += h
    else:
        Ep[i, j] += 0.5 * h
        Ep[j, i] += 0.5 * h
    return Ep


def hooke(E: float, nu: float) -> np.ndarray:
    """Isotropic linear elasticity in Voigt form with engineering shear (standard textbook matrix)."""
    c = E / ((1.0 + nu) * (1.0 - 2.0 * nu))
    D = np.zeros((6, 6))
    D[:3, :3] = c * nu
    D[np.arange(3), np.arange(3)] = c * (1.0 - nu)
    D[np.arange(3, 6), np.arange(3, 6)] = E / (2.0 * (1.0 + nu))
    return D


@pytest.mark.parametrize("mat", MATERIALS, ids=lambda m: f"{m.name}-{m.nu}")
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_tangent_matches_fd_of_stress(mat, seed):
    F = random_F(seed)
    S, D, status = stress_tangent(mat, F)
    assert status == 0
    E = green_lagrange(F)
    h = 1e-6
    Dfd = np.empty((6, 6))
    for J in range(6):
        Sp = stress_tangent(mat, F_of_E(perturb(E, J, h)))[0]
        Sm = stress_tangent(mat, F_of_E(perturb(E, J, -h)))[0]
        Dfd[:, J] = (Sp - Sm) / (2.0 * h)
    assert np.abs(D - Dfd).max() <= 1e-6 * np.abs(D).max()
    # S depends on F only through C: the symmetric stretch gives the same stress
    assert np.allclose(stress_tangent(mat, F_of_E(E))[0], S, rtol=1e-12, atol=1e-12 * np.abs(S).max())


@pytest.mark.parametrize("mat", MATERIALS, ids=lambda m: f"{m.name}-{m.nu}")
@pytest.mark.parametrize("seed", [3, 4])
def test_stress_matches_fd_of_energy(mat, seed):
    F = random_F(seed)
    S = stress_tangent(mat, F)[0]
    E = green_lagrange(F)
    h = 1e-6
    Sfd = np.array([(strain_energy(mat, F_of_E(perturb(E, J, h))) - strain_energy(mat, F_of_E(perturb(E, J, -h))))
                    / (2.0 * h) for J in range(6)])
    assert np.abs(S - Sfd).max() <= 1e-6 * np.abs(S).max()


@pytest.mark.parametrize("mat", MATERIALS, ids=lambda m: f"{m.name}-{m.nu}")
def test_tangent_symmetric_and_objective(mat):
    F = random_F(5)
    S, D, _ = stress_tangent(mat, F)
    assert np.abs(D - D.T).max() <= 1e-13 * np.abs(D).max()
    # a superposed rotation changes neither S nor D
    t = 0.7
    Q = np.array([[np.cos(t), -np.sin(t), 0.0], [np.sin(t), np.cos(t), 0.0], [0.0, 0.0, 1.0]])
    S2, D2, _ = stress_tangent(mat, Q @ F)
    assert np.allclose(S2, S, rtol=1e-12, atol=1e-12 * np.abs(S).max())
    assert np.allclose(D2, D, rtol=1e-12, atol=1e-12 * np.abs(D).max())


@pytest.mark.parametrize("mat", MATERIALS, ids=lambda m: f"{m.name}-{m.nu}")
def test_small_strain_limit_is_hooke(mat):
    D_ref = hooke(mat.E, mat.nu)
    S0, D0, _ = stress_tangent(mat, np.eye(3))
    assert np.abs(S0).max() == 0.0  # stress free reference state (also for Neo-Hooke)
    assert np.allclose(D0, D_ref, rtol=1e-13, atol=1e-13 * mat.E)
    grad = 1e-7 * np.random.default_rng(6).uniform(-1.0, 1.0, (3, 3))
    eps = 0.5 * (grad + grad.T)
    eps_v = np.array([eps[0, 0], eps[1, 1], eps[2, 2], 2 * eps[0, 1], 2 * eps[1, 2], 2 * eps[0, 2]])
    S = stress_tangent(mat, np.eye(3) + grad)[0]
    assert np.abs(S - D_ref @ eps_v).max() <= 1e-6 * np.abs(D_ref @ eps_v).max()


def test_svk_stress_formula():
    mat = SaintVenantKirchhoff(E=100.0, nu=0.25)
    F = random_F(7)
    E = green_lagrange(F)
    S_ref = mat.lam * np.trace(E) * np.eye(3) + 2.0 * mat.mu * E  # S = lambda tr(E) I + 2 mu E
    S = stress_tangent(mat, F)[0]
    assert np.allclose(S, [S_ref[i, j] for i, j in PAIRS], rtol=1e-13, atol=1e-13 * mat.E)


def test_inverted_gradient_flags_and_stays_finite():
    F = np.diag([1.0, 1.0, -0.5])
    for mat in MATERIALS:
        S, D, status = stress_tangent(mat, F)
        assert status == 1
        assert np.isfinite(S).all() and np.isfinite(D).all()
    assert strain_energy(NeoHooke(E=1.0, nu=0.3), F) == np.inf


def test_parameters_and_names():
    m = material_from_name("Neo-Hooke", E=10.0, nu=0.2)
    assert isinstance(m, NeoHooke) and m.kind == NEO_HOOKE
    assert isinstance(material_from_name("neohooke", E=1.0, nu=0.0), NeoHooke)
    assert material_from_name("svk", E=1.0, nu=0.0).kind == SVK
    assert isinstance(material_from_name("saint-venant-kirchhoff", E=1.0, nu=0.1), SaintVenantKirchhoff)
    lam, mu = 10.0 * 0.2 / (1.2 * 0.6), 10.0 / 2.4
    assert np.allclose(m.params, [10.0, 0.2, lam, mu])
    with pytest.raises(ValueError, match="E"):
        SaintVenantKirchhoff(E=-1.0, nu=0.3)
    with pytest.raises(ValueError, match="nu"):
        NeoHooke(E=1.0, nu=0.5)
    with pytest.raises(ValueError, match="nu"):
        NeoHooke(E=1.0, nu=-1.0)
    with pytest.raises(ValueError, match="unknown material"):
        material_from_name("mooney", E=1.0, nu=0.3)
    with pytest.raises(ValueError, match="nu"):
        material_from_name("svk", E=1.0)
