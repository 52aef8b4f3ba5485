"""F-bar planar bodies (plane strain, axisymmetric): the exact non-symmetric tangent against central differences of
the residual (elastic and J2 plastic, every F-bar cell), patch tests (a homogeneous finite deformation on distorted
meshes, exact; axisymmetric radial expansion, exact), F_bar = F for a homogeneous state, the refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_planar import (
    ELASTIC,
    PLASTIC,
    _cauchy,
    _exact_F,
    _run,
    _solve_patch,
    assemble,
    distorted,
    planar_u,
    residual,
)

from covcontact.elements.planar_fbar import PLANAR_FBAR_CELLS, PlanarFbarBody
from covcontact.materials import NeoHooke
from covcontact.materials.rubber import rubber_from_keys

FORMS = ("plane_strain", "axisymmetric")


@pytest.mark.parametrize("form", FORMS)
@pytest.mark.parametrize("cell", PLANAR_FBAR_CELLS)
@pytest.mark.parametrize("plastic", [False, True], ids=["elastic", "j2"])
def test_tangent_against_central_differences(cell, form, plastic):
    mesh = distorted(cell, 1, 1)
    body = PlanarFbarBody(cell, mesh.points, mesh.cells, PLASTIC if plastic else ELASTIC, form, thickness=0.7)
    assert not body.symmetric_tangent
    state = body.new_state()
    if plastic:  # a committed plastic state, then a further step from it
        u1 = planar_u(body.n_nodes, 0.03, 2)
        u1[:, 0] += 0.02 * mesh.points[:, 0]
        _, _, state = assemble(body, u1, state)
        assert state["hist"][:, :, 6].max() > 0.0  # yielded
        u = u1 + planar_u(body.n_nodes, 0.01, 3)
    else:
        u = planar_u(body.n_nodes, 0.08, 4)
    r, K, trial = assemble(body, u, state)
    if plastic:
        assert np.any(trial["hist"][:, :, 6] > state["hist"][:, :, 6] + 1e-9)  # still flowing
    h = 1e-6
    Kfd = np.zeros_like(K)
    for j in range(3 * body.n_nodes):
        if j % 3 == 2:
            continue
        up, um = u.copy().ravel(), u.copy().ravel()
        up[j] += h
        um[j] -= h
        Kfd[:, j] = (residual(body, up.reshape(-1, 3), state) - residual(body, um.reshape(-1, 3), state)) / (2 * h)
    assert np.abs(K - Kfd).max() <= 1e-6 * np.abs(K).max()
    assert np.all(r[2::3] == 0.0) and np.all(K[2::3] == 0.0)


@pytest.mark.parametrize("cell", ["quad4", "quad8"])
def test_tangent_nearly_incompressible_rubber(cell):
    """Mooney-Rivlin with K / mu = 2000 under a 20 % axial compression with a random disturbance, axisymmetric."""
    rubber = rubber_from_keys("mooney-rivlin", {"c10": 0.4, "c01": 0.1, "d1": 0.001})
    mesh = distorted(cell, 1, 1)
    body = PlanarFbarBody(cell, mesh.points, mesh.cells, rubber, "axisymmetric")
    u = planar_u(body.n_nodes, 0.02, 6)
    u[:, 1] -= 0.2 * mesh.points[:, 1]
    u[:, 0] += 0.1 * mesh.points[:, 0]
    _, K, _ = assemble(body, u)
    h = 1e-6
    Kfd = np.zeros_like(K)
    for j in range(3 * body.n_nodes):
        if j % 3 == 2:
            continue
        up, um = u.copy().ravel(), u.copy().ravel()
        up[j] += h
        um[j] -= h
        Kfd[:, j] = (residual(body, up.reshape(-1, 3)) - residual(body, um.reshape(-1, 3))) / (2 * h)
    assert np.abs(K - Kfd).max() <= 1e-6 * np.abs(K).max()


@pytest.mark.parametrize("cell", PLANAR_FBAR_CELLS)
def test_patch_homogeneous_finite_deformation(cell):
    """Plane strain: F = [[1.1, 0.2], [0.05, 0.95]] on the boundary of a distorted mesh: the exact displacement
    inside and the exact stress in every cell (F_bar = F)."""
    Fin = np.array([[1.1, 0.2], [0.05, 0.95]])
    mesh = distorted(cell, 3, 3)
    body = PlanarFbarBody(cell, mesh.points, mesh.cells, ELASTIC, "plane_strain", thickness=0.5)
    X = mesh.points
    u_exact = np.zeros_like(X)
    u_exact[:, :2] = X[:, :2] @ (Fin - np.eye(2)).T
    u = _solve_patch(body, mesh, u_exact)
    assert np.abs(u - u_exact).max() < 1e-11
    sig = body.gauss_cauchy(u).reshape(-1, 6)
    exact = _cauchy(ELASTIC, _exact_F("plane_strain", ELASTIC, Fin))
    assert np.abs(sig - exact[None, :]).max() < 1e-9 * np.abs(exact).max()


@pytest.mark.parametrize("cell", PLANAR_FBAR_CELLS)
def test_patch_axisymmetric_radial_expansion(cell):
    """u_r = c R, u_z = d Z: exact inside, F_bar = F = diag(1 + c, 1 + d, 1 + c) in every cell."""
    c, d = 0.04, -0.03
    mesh = distorted(cell, 3, 3)
    body = PlanarFbarBody(cell, mesh.points, mesh.cells, ELASTIC, "axisymmetric")
    u_exact = np.zeros_like(mesh.points)
    u_exact[:, 0] = c * mesh.points[:, 0]
    u_exact[:, 1] = d * mesh.points[:, 1]
    u = _solve_patch(body, mesh, u_exact)
    assert np.abs(u - u_exact).max() < 1e-11
    exact = _cauchy(ELASTIC, np.diag([1 + c, 1 + d, 1 + c]))
    sig = body.gauss_cauchy(u).reshape(-1, 6)
    assert np.abs(sig - exact[None, :]).max() < 1e-9 * np.abs(exact).max()


def test_refusals():
    mesh = distorted("quad4", 1, 1)
    with pytest.raises(ValueError, match="plane stress"):
        PlanarFbarBody("quad4", mesh.points, mesh.cells, ELASTIC, "plane_stress")
    m3 = distorted("tri3", 1, 1)
    with pytest.raises(ValueError, match="tri6"):
        PlanarFbarBody("tri3", m3.points, m3.cells, ELASTIC, "plane_strain")


def test_nearly_incompressible_quad4_does_not_lock():
    """A plane strain cantilever strip with nu = 0.4999 under a small tip shear: F-bar quad4's deflection is within
    20 % of the F-bar quad8's (the rest is quad4's shear locking in bending at two elements through the depth, which
    F-bar does not address); the plain quad4 locks volumetrically (a fraction of it)."""
    from covcontact.elements.planar import PlanarBody
    from covcontact.mesh.generators_planar import rectangle

    mat = NeoHooke(E=1.0, nu=0.4999)
    tips = {}
    for name, cell, cls in (("q4", "quad4", PlanarBody), ("fbar", "quad4", PlanarFbarBody),
                            ("q8fbar", "quad8", PlanarFbarBody)):
        m = rectangle(10.0, 1.0, 20, 2, cell=cell)
        body = cls(cell, m.points, m.cells, mat, "plane_strain")
        fixed = m.node_sets["xmin"]
        free = np.ones((body.n_nodes, 3), dtype=bool)
        free[:, 2] = False
        free[fixed] = False
        free = free.ravel()
        f = np.zeros((body.n_nodes, 3))
        tip = m.node_sets["xmax"]
        f[tip, 1] = 1e-6 / tip.size
        u = np.zeros(3 * body.n_nodes)
        for _ in range(3):
            r, K, _ = assemble(body, u.reshape(-1, 3))
            u[free] -= np.linalg.solve(K[np.ix_(free, free)], (r - f.ravel())[free])
        tips[name] = u.reshape(-1, 3)[tip, 1].mean()
    assert abs(tips["fbar"] / tips["q8fbar"] - 1.0) < 0.2
    assert tips["q4"] < 0.5 * tips["fbar"]


@pytest.mark.parametrize("body, expect", [
    ('formulation = "plane_stress"\noptions = { fbar = true }\n'
     'mesh = { generator = "rectangle", lx = 1, ly = 1, nx = 1, ny = 1 }', "fbar = true is for plane_strain"),
    ('formulation = "plane_strain"\nelement = "tri3"\noptions = { fbar = true }\n'
     'mesh = { generator = "rectangle", lx = 1, ly = 1, nx = 1, ny = 1 }', "needs quad4, quad8, quad9, tri6"),
    ('formulation = "axisymmetric"\nelement = "quad8"\noptions = { fbar = true, integration = "reduced" }\n'
     'mesh = { generator = "rectangle", lx = 1, ly = 1, nx = 1, ny = 1 }', "takes full integration"),
    ('formulation = "plane_strain"\noptions = { fbar = "yes" }\n'
     'mesh = { generator = "rectangle", lx = 1, ly = 1, nx = 1, ny = 1 }', "fbar must be true or false"),
])
def test_bad_input_one_line(tmp_path, body, expect):
    proc = _run(tmp_path, body)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and expect in lines[0], proc.stderr


@pytest.mark.parametrize("cell", ["quad4", "quad8", "quad9", "tri6"])
def test_disc_generator(cell):
    """The O-grid disc: counter-clockwise cells, the circle's nodes (mid-nodes included) on the circle, the area
    of the polygon close to pi a^2, no duplicate nodes, the named sets."""
    from covcontact.fem.planar_cells import reference_jacobians
    from covcontact.mesh.generators_planar import disc

    a, c = 2.5, np.array([20.0, 1.0])
    m = disc(a, 6, 3, cell=cell, center=c, bias=0.8)
    X = m.points
    assert np.all(reference_jacobians(cell, X, m.cells) > 0.0)
    o = m.node_sets["outer"]
    assert np.abs(np.hypot(*(X[o, :2] - c).T) - a).max() < 1e-12
    assert len(m.face_set("outer")) == 24
    assert len(np.unique(np.round(X[:, :2], 9), axis=0)) == m.n_nodes
    assert np.unique(m.cells).size == m.n_nodes
    area = reference_jacobians(cell, X, m.cells).sum() * (4.0 if cell.startswith("quad") else 0.5) / \
        (reference_jacobians(cell, X, m.cells).shape[1])
    assert area == pytest.approx(math.pi * a**2, rel=0.03)
    assert set(m.node_sets) >= {"all", "core", "outer", "top", "bottom", "left", "right"}
    assert np.all(X[m.node_sets["top"], 1] >= c[1] - 1e-12)
