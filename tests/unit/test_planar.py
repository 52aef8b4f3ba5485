"""Planar bodies (plane strain, plane stress, axisymmetric): element tangents against central differences of the
residual (elastic and J2 plastic states, every cell), patch tests with a homogeneous finite deformation on distorted
meshes, the generators' sets and edge loads, mass, and the input refusals (one line, exit 2)."""

from __future__ import annotations

import math
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from scipy.optimize import brentq

from covcontact.assembly import Pattern
from covcontact.elements.planar import PlanarBody, edge_load_vector, planar_masses
from covcontact.fem.planar_cells import EDGES, PLANAR_CELLS
from covcontact.materials import J2Plasticity, NeoHooke, SaintVenantKirchhoff
from covcontact.materials.hyperelastic import stress_tangent
from covcontact.mesh.faces import check_orientation
from covcontact.mesh.generators_planar import annulus, quarter_disc, rectangle

FORMS = ("plane_strain", "plane_stress", "axisymmetric")
ELASTIC = NeoHooke(E=200.0, nu=0.3)
PLASTIC = J2Plasticity(E=200.0, nu=0.3, yield_stress=0.4, hardening={"law": "linear", "modulus": 10.0})


def distorted(cell: str, nx: int = 2, ny: int = 2, seed: int = 1, origin=(1.0, 0.0)):
    """A rectangle [1, 2.2] x [0, 1] mesh of ``cell`` with its interior corner nodes moved at random (straight
    edges: mid-nodes at the middle of their corners, quad9 centres at the mean of the corners)."""
    m = rectangle(1.2, 1.0, nx, ny, cell=cell, origin=origin)
    X = m.points.copy()
    corners = np.unique(m.cells[:, :4 if cell.startswith("quad") else 3])
    boundary = np.unique(np.concatenate([m.node_sets[k] for k in ("xmin", "xmax", "ymin", "ymax")]))
    inner = np.setdiff1d(corners, boundary)
    rng = np.random.default_rng(seed)
    X[inner, :2] += 0.12 * rng.uniform(-1.0, 1.0, (inner.size, 2)) * [1.2 / nx, 1.0 / ny]
    for e in EDGES[cell]:
        if e.size == 3:
            X[m.cells[:, e[2]]] = 0.5 * (X[m.cells[:, e[0]]] + X[m.cells[:, e[1]]])
    if cell == "quad9":
        X[m.cells[:, 8]] = X[m.cells[:, :4]].mean(axis=1)
    m.points = X
    return m


def assemble(body: PlanarBody, u: np.ndarray, state=None):
    P = Pattern(body.n_nodes, [body.cells])
    data = P.zeros()
    r = np.zeros(3 * body.n_nodes)
    st = body.kernel_state(state, state) if state is not None else None
    assert body.assemble(u, data, r, P, state=st) == -1
    return r, P.csr(data).toarray(), (body.trial_of(st) if st is not None else None)


def residual(body: PlanarBody, u: np.ndarray, state=None) -> np.ndarray:
    r = np.zeros(3 * body.n_nodes)
    st = body.kernel_state(state, state) if state is not None else None
    assert body.assemble(u, np.zeros(0), r, None, want_K=False, state=st) == -1
    return r


def planar_u(n: int, scale: float, seed: int) -> np.ndarray:
    u = scale * np.random.default_rng(seed).uniform(-1.0, 1.0, (n, 3))
    u[:, 2] = 0.0
    return u


@pytest.mark.parametrize("form", FORMS)
@pytest.mark.parametrize("cell", PLANAR_CELLS)
@pytest.mark.parametrize("plastic", [False, True], ids=["elastic", "j2"])
def test_tangent_against_central_differences(cell, form, plastic):
    mesh = distorted(cell, 1, 1)
    body = PlanarBody(cell, mesh.points, mesh.cells, PLASTIC if plastic else ELASTIC, form, thickness=0.7)
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
    assert np.allclose(K, K.T, atol=1e-12 * np.abs(K).max())
    assert np.all(r[2::3] == 0.0) and np.all(K[2::3] == 0.0)


def test_reduced_quad8_tangent():
    mesh = distorted("quad8", 1, 1)
    body = PlanarBody("quad8", mesh.points, mesh.cells, ELASTIC, "axisymmetric", integration="reduced")
    assert body.weights.size == 4
    u = planar_u(body.n_nodes, 0.05, 5)
    _, K, _ = assemble(body, u)
    h = 1e-6
    for j in (0, 4, 12):
        up, um = u.copy().ravel(), u.copy().ravel()
        up[j] += h
        um[j] -= h
        col = (residual(body, up.reshape(-1, 3)) - residual(body, um.reshape(-1, 3))) / (2 * h)
        assert np.abs(K[:, j] - col).max() <= 1e-6 * np.abs(K).max()


def _exact_F(form: str, material, Fin: np.ndarray) -> np.ndarray:
    F = np.zeros((3, 3))
    F[:2, :2] = Fin
    F[2, 2] = 1.0
    if form == "plane_stress":
        def s33(f33):
            F[2, 2] = f33
            return stress_tangent(material, F)[0][2]
        F[2, 2] = brentq(s33, 0.5, 1.5, xtol=1e-15)
    return F


def _cauchy(material, F: np.ndarray) -> np.ndarray:
    S = stress_tangent(material, F)[0]
    St = np.array([[S[0], S[3], S[5]], [S[3], S[1], S[4]], [S[5], S[4], S[2]]])
    sig = F @ St @ F.T / np.linalg.det(F)
    return np.array([sig[0, 0], sig[1, 1], sig[2, 2], sig[0, 1], sig[1, 2], sig[0, 2]])


def _solve_patch(body: PlanarBody, mesh, u_exact: np.ndarray) -> np.ndarray:
    """Newton on the interior nodes' in-plane dofs with u_exact on the boundary, from u_exact disturbed by 1 % of
    the size inside; returns u."""
    boundary = np.unique(np.concatenate([mesh.node_sets[k] for k in ("xmin", "xmax", "ymin", "ymax")]))
    free = np.zeros((body.n_nodes, 3), dtype=bool)
    free[:, :2] = True
    free[boundary] = False
    free = free.ravel()
    u = u_exact.copy().ravel()
    u[free] += 0.01 * np.random.default_rng(7).uniform(-1.0, 1.0, int(free.sum()))
    for _ in range(12):
        r, K, _ = assemble(body, u.reshape(-1, 3))
        if np.abs(r[free]).max() < 1e-12:
            break
        u[free] -= np.linalg.solve(K[np.ix_(free, free)], r[free])
    return u.reshape(-1, 3)


@pytest.mark.parametrize("cell", PLANAR_CELLS)
@pytest.mark.parametrize("form", ["plane_strain", "plane_stress"])
def test_patch_homogeneous_finite_deformation(cell, form):
    """F = [[1.1, 0.2], [0.05, 0.95]] on the boundary of a distorted mesh: the exact displacement inside and the
    exact stress (with its out-of-plane component) in every cell; the residual at the exact field is zero."""
    Fin = np.array([[1.1, 0.2], [0.05, 0.95]])
    mesh = distorted(cell, 3, 3)
    body = PlanarBody(cell, mesh.points, mesh.cells, ELASTIC, form, thickness=0.5)
    X = mesh.points
    u_exact = np.zeros_like(X)
    u_exact[:, :2] = X[:, :2] @ (Fin - np.eye(2)).T
    r = residual(body, u_exact)
    free = np.setdiff1d(np.arange(body.n_nodes), np.concatenate([mesh.node_sets[k] for k in
                                                                 ("xmin", "xmax", "ymin", "ymax")]))
    assert np.abs(r.reshape(-1, 3)[free]).max() < 1e-11
    u = _solve_patch(body, mesh, u_exact)
    assert np.abs(u - u_exact).max() < 1e-11
    sig = body.gauss_cauchy(u).reshape(-1, 6)  # every Gauss point
    exact = _cauchy(ELASTIC, _exact_F(form, ELASTIC, Fin))
    assert np.abs(sig - exact[None, :]).max() < 1e-9 * np.abs(exact).max()
    if form == "plane_stress":
        assert np.abs(sig[:, 2]).max() < 1e-9 * np.abs(exact).max()


@pytest.mark.parametrize("cell", PLANAR_CELLS)
def test_patch_axisymmetric_radial_expansion(cell):
    """u_r = c R, u_z = d Z on the boundary of a distorted mesh: exact inside, F = diag(1 + c, 1 + d, 1 + c) (hoop
    stretch r / R = 1 + c) in every cell."""
    c, d = 0.04, -0.03
    mesh = distorted(cell, 3, 3)
    body = PlanarBody(cell, mesh.points, mesh.cells, ELASTIC, "axisymmetric")
    u_exact = np.zeros_like(mesh.points)
    u_exact[:, 0] = c * mesh.points[:, 0]
    u_exact[:, 1] = d * mesh.points[:, 1]
    u = _solve_patch(body, mesh, u_exact)
    assert np.abs(u - u_exact).max() < 1e-11
    exact = _cauchy(ELASTIC, np.diag([1 + c, 1 + d, 1 + c]))
    sig = body.gauss_cauchy(u).reshape(-1, 6)  # every Gauss point
    assert np.abs(sig - exact[None, :]).max() < 1e-9 * np.abs(exact).max()


def test_plane_stress_plastic_point_has_no_out_of_plane_stress():
    mesh = distorted("quad4", 1, 1)
    body = PlanarBody("quad4", mesh.points, mesh.cells, PLASTIC, "plane_stress")
    u = np.zeros_like(mesh.points)
    u[:, 0] = 0.02 * mesh.points[:, 0]
    _, _, trial = assemble(body, u, body.new_state())
    st = body.stress(u, trial)
    assert abs(st.pk2[0, 2]) < 1e-10 * abs(st.pk2[0, 0]) and st.green_lagrange[0, 2] < 0.0


def test_volume_mass_and_edge_loads():
    """The Gauss volumes and the mass give t A or 2 pi R_c A; the pressure on the inner circle of an annulus gives the
    force p 2 a t over a quarter (and nothing along z)."""
    m = rectangle(1.0, 2.0, 2, 3, cell="quad8", origin=(3.0, 0.0))
    ax = PlanarBody("quad8", m.points, m.cells, ELASTIC, "axisymmetric")
    assert math.isclose(ax.gauss_volumes().sum(), 2 * math.pi * 3.5 * 2.0, rel_tol=1e-12)
    ps = PlanarBody("quad8", m.points, m.cells, ELASTIC, "plane_stress", thickness=0.3)
    assert math.isclose(ps.gauss_volumes().sum(), 0.3 * 2.0, rel_tol=1e-12)
    for cell in PLANAR_CELLS:
        mm = rectangle(1.0, 2.0, 2, 3, cell=cell, origin=(3.0, 0.0))
        M = planar_masses(cell, mm.points, mm.cells, 7.0, "axisymmetric")
        assert math.isclose(M.sum(), 7.0 * 2 * math.pi * 3.5 * 2.0, rel_tol=1e-12)
        M = planar_masses(cell, mm.points, mm.cells, 7.0, "plane_strain", 0.5)
        assert math.isclose(M.sum(), 7.0 * 0.5 * 2.0, rel_tol=1e-12)
    a = annulus(1.0, 2.0, 2, 16, angle=90.0, cell="quad8")
    f = edge_load_vector(a.points, a.face_sets["inner"], "plane_strain", 0.5)
    # outward normal on the inner circle points to the centre: int n ds over a quarter = -(a, a) t
    assert np.allclose(f.sum(axis=0), [-0.5, -0.5, 0.0], atol=1e-6)
    top = m.face_sets["ymax"]
    f = edge_load_vector(m.points, top, "axisymmetric")
    assert np.allclose(f.sum(axis=0), [0.0, math.pi * (4.0**2 - 3.0**2), 0.0], rtol=1e-12)


def test_generators_sets():
    for cell in PLANAR_CELLS:
        r = rectangle(2.0, 1.0, 4, 2, cell=cell)
        assert set(r.face_sets) == {"xmin", "xmax", "ymin", "ymax"} and r.face_sets["xmin"].shape[0] == 2
        a = annulus(1.0, 2.0, 2, 6, angle=60.0, cell=cell)
        assert set(a.face_sets) == {"inner", "outer", "angle0", "angle1"}
        rad = np.hypot(a.points[:, 0], a.points[:, 1])
        assert np.allclose(rad[a.node_sets["inner"]], 1.0) and np.allclose(rad[a.node_sets["outer"]], 2.0)
        assert np.allclose(a.points[a.node_sets["angle0"], 1], 0.0)
        q = quarter_disc(2.0, 6, 2, cell=cell, center=(0.0, 1.0))
        assert set(q.face_sets) == {"arc", "xmin", "ymin"} and q.face_sets["arc"].shape[0] == 6
        x, y = q.points[:, 0], q.points[:, 1] - 1.0
        assert x.min() == 0.0 and y.min() == 0.0 and np.all(q.points[:, 2] == 0.0)
        assert np.allclose(np.hypot(x, y)[q.node_sets["arc"]], 2.0)
        assert np.all(x[q.node_sets["xmin"]] == 0.0) and np.all(y[q.node_sets["ymin"]] == 0.0)
        assert check_orientation(q) == []
    with pytest.raises(ValueError, match="n must be even"):
        quarter_disc(1.0, 5, 2)


def _run(tmp_path, body: str, extra: str = "") -> subprocess.CompletedProcess:
    (tmp_path / "p.toml").write_text(textwrap.dedent(f"""
        [problem]
        name = "p"

        [[bodies]]
        name = "disc"
        {body}
        material = {{ model = "neo-hooke", E = 100.0, nu = 0.3 }}
        {extra}
        """))
    return subprocess.run([sys.executable, "-m", "covcontact", "run", str(tmp_path / "p.toml"), "--out", str(tmp_path / "out")],
                          capture_output=True, text=True, timeout=120)


@pytest.mark.parametrize("body, extra, expect", [
    ('formulation = "plane_strain"\nmesh = { generator = "block", lx = 1, ly = 1, lz = 1, nx = 1, ny = 1, nz = 1 }',
     "", "needs planar cells"),
    ('mesh = { generator = "rectangle", lx = 1, ly = 1, nx = 1, ny = 1 }', "", "cells are planar"),
    ('formulation = "axisymmetric"\nmesh = { generator = "rectangle", lx = 1, ly = 1, nx = 1, ny = 1, '
     'origin = [-0.5, 0.0] }', "", "radius x >= 0"),
    ('formulation = "axisymmetric"\nthickness = 2.0\nmesh = { generator = "rectangle", lx = 1, ly = 1, nx = 1, '
     'ny = 1 }', "", "thickness is for"),
    ('formulation = "plane_stress"\nelement = "quad4"\noptions = { integration = "reduced" }\n'
     'mesh = { generator = "rectangle", lx = 1, ly = 1, nx = 1, ny = 1 }', "", "reduced\" is for quad8"),
    ('formulation = "plane_strain"\nmesh = { generator = "rectangle", lx = 1, ly = 1, nx = 2, ny = 2 }',
     '[[rigid]]\nname = "ball"\nshape = "sphere"\ncenter = [0.5, 2.0, 0.0]\nradius = 1.0\n'
     '[[contact]]\nname = "c"\nslave = "disc.ymax"\nmaster = "ball"\npenalty = 1000.0',
     "the rigid master 'ball' of a planar pair must be an analytic line"),
])
def test_bad_input_one_line(tmp_path, body, extra, expect):
    proc = _run(tmp_path, body, extra)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and expect in lines[0], proc.stderr


def test_gmsh_2d_file(tmp_path):
    """A Gmsh 2D file: its quadrilaterals become a planar mesh (a clockwise cell turned counter-clockwise), its
    physical curves edge sets with outward normals."""
    from covcontact.mesh import read_mesh
    from covcontact.mesh.faces import edge_normals

    (tmp_path / "sq.msh").write_text(textwrap.dedent("""\
        $MeshFormat
        2.2 0 8
        $EndMeshFormat
        $PhysicalNames
        2
        1 1 "bottom"
        2 2 "plate"
        $EndPhysicalNames
        $Nodes
        6
        1 0 0 0
        2 1 0 0
        3 1 1 0
        4 0 1 0
        5 2 0 0
        6 2 1 0
        $EndNodes
        $Elements
        4
        1 1 2 1 1 1 2
        2 1 2 1 1 2 5
        3 3 2 2 1 1 4 3 2
        4 3 2 2 1 2 5 6 3
        $EndElements
        """))
    m = read_mesh(tmp_path / "sq.msh")
    assert m.cell_type == "quad4" and m.is_planar and m.n_cells == 2
    assert set(m.element_sets) >= {"plate"} and m.face_sets["bottom"].shape == (2, 2)
    n = edge_normals(m.points, m.face_sets["bottom"])
    assert np.all(n[:, 1] < 0.0)
    from covcontact.mesh.faces import check_orientation
    assert check_orientation(m) == []
