"""F-bar tet10 (the element's mean volume change) and hex20 (J projected onto the element's linear functions):
exact tangents against central differences (elastic, plastic), the patch test on distorted meshes, and rigid
rotations stress free (docs/theory.md, section 18)."""

from __future__ import annotations

import numpy as np
import pytest
from test_fbar import F_HOM, fd_tangent, residual, rotation, tangent

from covcontact.elements.fbar import FbarBody
from covcontact.materials import J2Plasticity, LinearHardening, NeoHooke, stress_tangent
from covcontact.mesh.convert import SOURCE, convert
from covcontact.mesh.generators import block


def distorted(cell: str, n: int = 2, amp: float = 0.12, seed: int = 0):
    """A block of ``cell`` with its interior nodes moved: the bricks' (hex8, then split into straight-sided
    tetrahedra, whose mid-nodes are the edges' midpoints) or the hex27 nodes (then trimmed to curved hex20)."""
    src = block(1.0, 1.0, 1.0, n, n, n, SOURCE[cell])
    inner = np.all((src.points > 1e-9) & (src.points < 1.0 - 1e-9), axis=1)
    src.points[inner] += amp / n * np.random.default_rng(seed).uniform(-1.0, 1.0, (int(inner.sum()), 3))
    m = convert(src, cell)
    X = m.points
    interior = np.flatnonzero(np.all((X > 1e-9) & (X < 1.0 - 1e-9), axis=1))
    return X, m.cells, interior


def _j2():
    return J2Plasticity(E=200.0, nu=0.3, yield_stress=0.5, hardening=LinearHardening(modulus=20.0))


@pytest.mark.parametrize("mat", ["neo-hooke", "j2"])
@pytest.mark.parametrize("cell", ["tet10", "hex20"])
def test_tangent_matches_central_differences(cell, mat):
    """Exact tangent of the spatial F-bar form to 1e-6 (relative to its largest entry), nearly incompressible
    Neo-Hooke and J2 loaded into the plastic range; evaluating never changes the committed history."""
    X, cells, _ = distorted(cell, n=1)
    cells = cells[:2] if cell == "tet10" else cells
    used = np.unique(cells)
    new = np.full(len(X), -1)
    new[used] = np.arange(used.size)
    X, cells = X[used], new[cells]
    material = NeoHooke(E=200.0, nu=0.4999) if mat == "neo-hooke" else _j2()
    body = FbarBody(cell, X, cells, material)
    assert body.check_reference() == []
    u = 0.06 * np.random.default_rng(2).uniform(-1.0, 1.0, X.shape)
    state = body.new_state()
    trial = {"hist_n": state["hist"], "hist": state["hist"].copy()}
    K, _ = tangent(body, u, state=trial)
    if mat == "j2":
        assert trial["hist"].any()  # yielded
    Kfd = fd_tangent(body, u, 1e-6, lambda: {"hist_n": state["hist"], "hist": state["hist"].copy()})
    assert np.abs(K - Kfd).max() <= 1e-6 * np.abs(K).max()
    assert not state["hist"].any()


@pytest.mark.parametrize("cell", ["tet10", "hex20"])
def test_patch_homogeneous_deformation(cell):
    """A homogeneous deformation of a distorted block is reproduced exactly: the exact stress at every point and no
    out-of-balance force at interior nodes (the projected volume change of a constant J is that J)."""
    X, cells, interior = distorted(cell)
    material = NeoHooke(E=200.0, nu=0.4999)
    body = FbarBody(cell, X, cells, material)
    u = X @ F_HOM.T - X
    S, _, _ = stress_tangent(material, F_HOM)
    assert np.abs(body.stress(u).pk2 - S).max() <= 1e-10 * np.abs(S).max()
    r = residual(body, u).reshape(-1, 3)
    assert np.abs(r[interior]).max() <= 1e-10 * np.abs(r).max()


@pytest.mark.parametrize("cell", ["tet10", "hex20"])
def test_rigid_rotation_is_stress_free(cell):
    X, cells, _ = distorted(cell)
    body = FbarBody(cell, X, cells, NeoHooke(E=200.0, nu=0.4999))
    Q = rotation([1.0, 2.0, 0.5], 0.7)
    r = residual(body, X @ Q.T - X)
    assert np.abs(r).max() <= 1e-9


def test_only_the_spatial_form():
    X, cells, _ = distorted("tet10", n=1)
    with pytest.raises(ValueError, match="spatial form only"):
        FbarBody("tet10", X, cells, NeoHooke(E=1.0, nu=0.3), form="variational")
    m = convert(block(1.0, 1.0, 1.0, 1, 1, 1, "hex8"), "tet4")
    with pytest.raises(ValueError, match="F-bar elements are"):
        FbarBody("tet4", m.points, m.cells, NeoHooke(E=1.0, nu=0.3))
