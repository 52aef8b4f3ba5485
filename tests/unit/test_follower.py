"""Follower pressures (covcontact.elements.follower; docs/theory.md, "Follower pressures"; docs/input.md,
``[[pressure]] follower``): the load stiffness against central differences on every face and edge type, and
homogeneous states under a hydrostatic pressure on the current faces against their closed forms (St. Venant-
Kirchhoff), where a dead pressure gives another, also closed-form, answer."""

from __future__ import annotations

import numpy as np
import pytest

from covcontact.elements.follower import edge_blocks, face_blocks
from covcontact.fem.cells import any_face

#: reference nodes of each face type (the VTK orders of quad4, quad8, quad9, tri3, tri6) in (xi, eta)
_FACES = {
    4: [(-1, -1), (1, -1), (1, 1), (-1, 1)],
    8: [(-1, -1), (1, -1), (1, 1), (-1, 1), (0, -1), (1, 0), (0, 1), (-1, 0)],
    9: [(-1, -1), (1, -1), (1, 1), (-1, 1), (0, -1), (1, 0), (0, 1), (-1, 0), (0, 0)],
    3: [(0, 0), (1, 0), (0, 1)],
    6: [(0, 0), (1, 0), (0, 1), (0.5, 0), (0.5, 0.5), (0, 0.5)],
}


def _distorted(nfn: int, seed: int) -> np.ndarray:
    """A curved, skewed face of ``nfn`` nodes lifted out of its plane (two faces sharing nothing)."""
    rng = np.random.default_rng(seed)
    ref = np.array(_FACES[nfn], dtype=float)
    x = np.column_stack([ref, 0.3 * ref[:, 0] * ref[:, 1]]) + 0.08 * rng.standard_normal((nfn, 3))
    return np.vstack([x, x[::-1] + [0.2, 0.1, 1.0]])


def _fd_error(fun, x: np.ndarray, conn: np.ndarray) -> float:
    """Relative Frobenius error of the analytic tangent of ``fun(x) -> (R, K)`` against central differences."""
    R, K = fun(x)
    h = 1e-6
    num = np.zeros_like(K)
    nfn = conn.shape[1]
    for b in range(nfn):
        for j in range(3):
            xp, xm = x.copy(), x.copy()
            xp[conn[:, b], j] += h
            xm[conn[:, b], j] -= h
            num[:, :, 3 * b + j] = (fun(xp)[0] - fun(xm)[0]) / (2 * h)
    return float(np.linalg.norm(K - num) / np.linalg.norm(K))


@pytest.mark.parametrize("nfn", [4, 8, 9, 3, 6])
def test_face_load_stiffness_is_exact(nfn):
    """Every face type, curved and out of plane: K = dR/dx to 1e-8 relative (central differences, h = 1e-6)."""
    x = _distorted(nfn, nfn)
    faces = np.arange(2 * nfn).reshape(2, nfn)
    err = _fd_error(lambda y: face_blocks(y, faces, 3.7), x, faces)
    assert err < 1e-8


@pytest.mark.parametrize("form", ["plane_strain", "axisymmetric"])
@pytest.mark.parametrize("nfn", [2, 3])
def test_edge_load_stiffness_is_exact(nfn, form):
    """Linear and quadratic edges, plane (thickness 0.3) and axisymmetric (the current radius enters): to 1e-8."""
    rng = np.random.default_rng(nfn)
    s = np.array([-1.0, 1.0, 0.0][:nfn])
    x = np.column_stack([1.5 + 0.5 * s, 0.4 * s * s, 0 * s]) + 0.05 * rng.standard_normal((nfn, 3)) * [1, 1, 0]
    x = np.vstack([x, x + [0.7, 0.2, 0.0]])
    edges = np.arange(2 * nfn).reshape(2, nfn)
    err = _fd_error(lambda y: edge_blocks(y, edges, -2.3, form, 0.3), x, edges)
    assert err < 1e-8


@pytest.mark.parametrize("nfn", [4, 9, 6])
def test_load_stiffness_of_a_varying_pressure_is_exact(nfn):
    """A pressure varying over the faces (``profile``: value (c + g . X) at the reference point X of each integration
    point): the same tangent check, faces and axisymmetric edges."""
    from covcontact.elements.follower import point_factors

    x = _distorted(nfn, 11)
    faces = np.arange(2 * nfn).reshape(2, nfn)
    factor = point_factors(x, faces, (0.5, 1.0, -2.0, 3.0))
    err = _fd_error(lambda y: face_blocks(y, faces, 1.3, factor=factor), x, faces)
    assert err < 1e-8
    edges = np.array([[0, 1, 2]])
    xe = np.array([[1.0, 0.0, 0.0], [2.0, 0.3, 0.0], [1.5, 0.2, 0.0]])
    factor = point_factors(xe, edges, (1.0, 0.0, 4.0, 0.0), planar=True)
    err = _fd_error(lambda y: edge_blocks(y, edges, 0.7, "axisymmetric", 1.0, factor=factor), xe, edges)
    assert err < 1e-8


def test_dead_profile_is_the_follower_at_the_reference():
    """A dead pressure with a profile gets the nodal forces the follower pressure has at the reference positions; a
    linear profile through the thickness of an end face is a pure couple (zero force, moment value x 1)."""
    from covcontact.assembly.system import System
    from covcontact.loads import Pressure
    from covcontact.materials import SaintVenantKirchhoff
    from covcontact.mesh.generators import plate
    from covcontact.problem import Body

    h = 0.1
    mesh = plate(2.0, 1.0, h, 2, 1, cell="hex8")
    prof = (-6.0 / h ** 2, 0.0, 0.0, 12.0 / h ** 3)
    load = Pressure("s", "xmax", 5.0, profile=prof)
    sysm = System([Body("s", mesh, SaintVenantKirchhoff(E=1.0, nu=0.0), "solid-shell", {})], loads=[load])
    f = sysm.load_vector(load).reshape(-1, 3)
    faces = mesh.face_sets["xmax"]
    from covcontact.elements.follower import point_factors

    R, _ = face_blocks(mesh.points, faces, 5.0, False, point_factors(mesh.points, faces, prof))
    g = np.zeros_like(f)
    np.add.at(g, faces.ravel(), -R.reshape(-1, 3))
    assert np.allclose(f, g, atol=1e-12)
    assert np.allclose(f.sum(axis=0), 0.0, atol=1e-12)
    moment = np.sum(np.cross(mesh.points - [2.0, 0.5, h / 2], f), axis=0)
    assert moment == pytest.approx([0.0, -5.0, 0.0], abs=1e-12)


def test_profile_key_is_read_and_checked(tmp_path):
    """``profile = { constant, gradient }`` reaches the load; an unknown key in it is one line naming it."""
    from covcontact.io.loader import load_problem
    from covcontact.io.validate import InputError

    loads = '[[pressure]]\nset = "c.xmax"\nvalue = 2.0\nfollower = true\nprofile = { constant = 0.5, gradient = [0.0, 0.0, 1.0] }\n'
    path = tmp_path / "p.toml"
    path.write_text(_CUBE.replace("CELL", "hex8").replace("LOADS", loads))
    (pressure,) = load_problem(path).pressures
    assert pressure.follower and pressure.profile == (0.5, 0.0, 0.0, 1.0)
    path.write_text(_CUBE.replace("CELL", "hex8").replace("LOADS", loads.replace("gradient", "gradiant")))
    with pytest.raises(InputError, match=r"pressure\[0\]\.profile.*gradiant.*gradient"):
        load_problem(path)


@pytest.mark.parametrize("nfn", [4, 8, 9, 3, 6])
def test_reference_faces_give_the_dead_load_vector(nfn):
    """At the reference positions the follower forces are the dead pressure's (covcontact.assembly.system's
    face_load_vector): one meaning of 'pressure', two ways of applying it."""
    from covcontact.assembly.system import face_load_vector

    x = _distorted(nfn, 7)
    faces = np.arange(2 * nfn).reshape(2, nfn)
    R, _ = face_blocks(x, faces, 2.0, want_K=False)
    dead = -2.0 * face_load_vector(x, faces)
    assert np.allclose(-R.reshape(-1, 3), dead[faces.ravel()], atol=1e-14)
    N, _, w = any_face(nfn)
    assert np.isclose(N.sum(axis=1) @ w, {4: 4.0, 8: 4.0, 9: 4.0, 3: 0.5, 6: 0.5}[nfn])


_CUBE = """
[problem]
name = "cube"

[[bodies]]
name = "c"
element = "CELL"
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 1.0, nx = 2, ny = 2, nz = 2 }
material = { model = "svk", E = 1000.0, nu = 0.3 }

[[dirichlet]]
set = "c.xmin"
components = "x"
value = 0.0

[[dirichlet]]
set = "c.ymin"
components = "y"
value = 0.0

[[dirichlet]]
set = "c.zmin"
components = "z"
value = 0.0

LOADS
[steps]
count = 4
"""


def _hydrostatic(p: float, follower: bool, sides=("xmax", "ymax", "zmax"), prefix: str = "c") -> str:
    flag = "follower = true\n" if follower else ""
    return "".join(f'[[pressure]]\nset = "{prefix}.{s}"\nvalue = {p}\n{flag}\n' for s in sides)


def _svk_stretch(p: float, follower: bool, E: float = 1000.0, nu: float = 0.3) -> float:
    """The stretch s of a St. Venant-Kirchhoff cube under the hydrostatic pressure p: S = K3 (s^2 - 1) / 2 I with
    K3 = 3 lambda + 2 mu = E / (1 - 2 nu); on the current faces the Cauchy stress S / s is -p, on the reference
    faces the first Piola stress s S is -p."""
    from scipy.optimize import brentq

    K3 = E / (1 - 2 * nu)
    if follower:
        return (-p + np.sqrt(p * p + K3 * K3)) / K3
    return brentq(lambda s: s * K3 * (s * s - 1) / 2 + p, 0.3, 1.0, xtol=1e-15)


@pytest.mark.parametrize("cell", ["hex8", "hex20", "tet10", "hex27"])
def test_hydrostatic_follower_pressure_is_the_cauchy_stress(tmp_path, cell):
    """A cube on three symmetry planes under p = 150 on its other three faces: on the current faces the Cauchy
    stress is -p I, s = (-p + sqrt(p^2 + K3^2)) / K3 (0.9417 here) at every node to 1e-9, and each support carries
    p times the current area s^2; the dead pressure's stretch (s^3 K3 (s^2 - 1) / 2 = -p s^2... s = 0.9374) is
    another one, which shows what the key changes."""
    from covcontact.io.loader import load_problem

    p = 150.0
    stretch = {}
    for follower in (True, False):
        path = tmp_path / f"cube_{follower}.toml"
        path.write_text(_CUBE.replace("CELL", cell).replace("LOADS", _hydrostatic(p, follower)))
        prob = load_problem(path)
        res = prob.run(out=tmp_path / f"out_{follower}")
        assert res.exit_code == 0
        s = _svk_stretch(p, follower)
        X = prob.bodies[0].mesh.points
        assert res.u.reshape(-1, 3)[: len(X)] == pytest.approx((s - 1) * X, abs=1e-9)
        rx = res.summary["steps"][-1]["reactions"]["c.xmin"][0]
        assert rx == pytest.approx(p * (s * s if follower else 1.0), rel=1e-9)
        stretch[follower] = s
    assert stretch[True] - stretch[False] > 4e-3


_PLANAR = """
[problem]
name = "square"

[[bodies]]
name = "q"
formulation = "FORM"
element = "CELL"
mesh = { generator = "rectangle", lx = 1.0, ly = 1.0, nx = 2, ny = 2 }
material = { model = "svk", E = 1000.0, nu = 0.3 }
THICK
[[dirichlet]]
set = "q.xmin"
components = "x"
value = 0.0

[[dirichlet]]
set = "q.ymin"
components = "y"
value = 0.0

LOADS
[steps]
count = 4
"""


@pytest.mark.parametrize("cell", ["quad4", "quad8", "tri6"])
def test_planar_follower_pressure(tmp_path, cell):
    """Plane strain, thickness 0.4: p on the right and top edges; on the current edges sigma_11 = sigma_22 = -p, so
    (lambda + mu)(s^2 - 1) = -p, s = sqrt(1 - p / (lambda + mu)); the support's force p s L t. Axisymmetric (a
    solid cylinder of radius 1 from the axis): p on the mantle and the top is the 3D hydrostatic state, the current
    radius entering the load; the bottom's force p s^2 pi R^2."""
    from covcontact.io.loader import load_problem

    E, nu, p = 1000.0, 0.3, 150.0
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    for form in ("plane_strain", "axisymmetric"):
        path = tmp_path / f"{form}.toml"
        text = _PLANAR.replace("FORM", form).replace("CELL", cell).replace(
            "THICK", "thickness = 0.4\n" if form != "axisymmetric" else "").replace(
            "LOADS", _hydrostatic(p, True, ("xmax", "ymax"), "q"))
        path.write_text(text)
        prob = load_problem(path)
        res = prob.run(out=tmp_path / form)
        assert res.exit_code == 0
        s = np.sqrt(1 - p / (lam + mu)) if form == "plane_strain" else _svk_stretch(p, True, E, nu)
        X = prob.bodies[0].mesh.points
        U = res.u.reshape(-1, 3)[: len(X)]
        assert U[:, :2] == pytest.approx((s - 1) * X[:, :2], abs=1e-9)
        ry = res.summary["steps"][-1]["reactions"]["q.ymin"][1]
        assert ry == pytest.approx(p * (s * 0.4 if form == "plane_strain" else s * s * np.pi), rel=1e-9)


def _cantilever_deck(p: float = 20.0, steps: tuple[str, ...] = ("*STEP, NLGEOM, INC=1000",)) -> str:
    """A C3D20 cantilever 10 x 1 x 1 (10 elements), clamped at x = 0, under the pressure p on its top face (face 2 of
    every element), E = 1e5, nu = 0.3: one *STEP per entry of ``steps`` (its card), the pressure given in the first."""
    L, nx = 10.0, 10
    lab, nodes = {}, []
    for k in range(3):
        for j in range(3):
            for i in range(2 * nx + 1):
                if (i % 2) + (j % 2) + (k % 2) < 2:
                    lab[i, j, k] = len(nodes) + 1
                    nodes.append((lab[i, j, k], L * i / (2 * nx), 0.5 * j, 0.5 * k))
    text = "*NODE, NSET=NALL\n" + "".join(f"{n}, {x!r}, {y!r}, {z!r}\n" for n, x, y, z in nodes)
    text += "*ELEMENT, TYPE=C3D20, ELSET=BEAM\n"
    for e in range(nx):
        i = 2 * e
        order = [(i, 0, 0), (i + 2, 0, 0), (i + 2, 2, 0), (i, 2, 0), (i, 0, 2), (i + 2, 0, 2), (i + 2, 2, 2),
                 (i, 2, 2), (i + 1, 0, 0), (i + 2, 1, 0), (i + 1, 2, 0), (i, 1, 0), (i + 1, 0, 2), (i + 2, 1, 2),
                 (i + 1, 2, 2), (i, 1, 2), (i, 0, 1), (i + 2, 0, 1), (i + 2, 2, 1), (i, 2, 1)]
        labels = [e + 1] + [lab[q] for q in order]
        text += ", ".join(map(str, labels[:16])) + ",\n" + ", ".join(map(str, labels[16:])) + "\n"
    text += "*NSET, NSET=CLAMP\n" + "".join(f"{n},\n" for n, x, _, _ in nodes if x == 0.0)
    text += "*NSET, NSET=TIP\n" + "".join(f"{n},\n" for n, x, _, _ in nodes if x == L)
    text += "*MATERIAL, NAME=M\n*ELASTIC\n100000., 0.3\n*SOLID SECTION, ELSET=BEAM, MATERIAL=M\n*BOUNDARY\nCLAMP, 1, 3\n"
    for k, card in enumerate(steps):
        text += f"{card}\n*STATIC\n0.05, 1.\n" + (f"*DLOAD\nBEAM, P2, {p}\n" if k == 0 else "")
        text += "*NODE PRINT, NSET=TIP\nU\n*NODE PRINT, NSET=CLAMP, TOTALS=ONLY\nRF\n*END STEP\n"
    return text


#: produced by running CalculiX 2.20 (Debian's ccx, "ccx -i cant") on _cantilever_deck() (NLGEOM, its automatic
#: increments): the .dat's tip displacements of nodes 21 (x = 10, y = z = 0), 32 (y = 0.5, z = 0) and 107 (y = 0.5,
#: z = 1) and the clamp's total force at the step's end
_CCX_CANTILEVER_U = {21: (-6.916467e-01, 2.893573e-06, -2.862605e+00), 32: (-6.916489e-01, 0.0, -2.862593e+00),
                     107: (-3.077374e-01, 0.0, -2.939331e+00)}
_CCX_CANTILEVER_RF = (5.849917e+01, 0.0, 1.892793e+02)


def test_deck_pressure_with_nlgeom_follows_the_faces_as_in_calculix(tmp_path):
    """A C3D20 cantilever bent by a pressure on its top face (tip deflection 2.9 of a length 10, the tip turned by
    about 22 degrees): with NLGEOM CalculiX's pressure acts on the bent faces, so the clamp takes an axial force of
    58.5 beside the 189.3 across (a dead pressure: 0 and 200). covcontact reads the pressure as a follower
    (``follower = true`` in the import) and gives CalculiX's tip displacements within 1e-4 of the largest (measured
    3e-5: CalculiX's convergence tolerance) and its clamp force within 5e-4 (measured 1.4e-4)."""
    import re
    import tomllib

    from covcontact.cli import main

    deck = tmp_path / "cant.inp"
    deck.write_text(_cantilever_deck())
    assert main(["run", str(deck), "--out", str(tmp_path / "o"), "--quiet"]) == 0
    dat = (tmp_path / "o" / "cant.dat").read_text()
    last_u = dat.rsplit("displacements", 1)[1]
    rows = {int(f[0]): np.array([float(v) for v in f[1:]]) for f in (ln.split() for ln in last_u.splitlines())
            if len(f) == 4 and f[0].isdigit()}
    scale = 2.94
    for n, ref in _CCX_CANTILEVER_U.items():
        assert rows[n] == pytest.approx(ref, abs=1e-4 * scale)
    rf = [float(v) for v in re.findall(r"-?\d\.\d+E[-+]\d+", dat.rsplit("total force", 1)[1].split("\n", 1)[1])[:3]]
    assert rf == pytest.approx(_CCX_CANTILEVER_RF, abs=5e-4 * 198.0)
    assert main(["import", str(deck), "--out", str(tmp_path / "imp" / "c.toml")]) == 0
    (pressure,) = tomllib.loads((tmp_path / "imp" / "c.toml").read_text())["pressure"]
    assert pressure["follower"] is True


@pytest.mark.parametrize("steps, follower", [
    (("*STEP",), False),
    (("*STEP, NLGEOM=NO",), False),
    (("*STEP, NLGEOM", "*STEP"), True),
    (("*STEP, NLGEOM=YES",), True),
])
def test_deck_pressures_follow_where_nlgeom_holds(tmp_path, steps, follower):
    """A deck's pressure follows the faces where the step that gives it is geometrically nonlinear; NLGEOM, once
    given, holds in the later steps until NLGEOM=NO (CalculiX's manual, *STEP); without it the pressure is the dead
    load of a linear analysis."""
    import tomllib

    from covcontact.io.deck_import import import_deck

    deck = tmp_path / "c.inp"
    deck.write_text(_cantilever_deck(1.0, steps))
    imp = import_deck(deck, tmp_path / "imp" / "c.toml")
    (pressure,) = tomllib.loads(imp.problem.read_text())["pressure"]
    assert pressure.get("follower", False) is follower


def test_model_tangent_with_follower_pressures_is_exact(tmp_path):
    """The whole model's tangent (bodies and the load stiffness of three follower pressures) at the converged second
    step against central differences of its residual, every column: within 1e-6 (measured 8.7e-11)."""
    from covcontact.io.loader import load_problem
    from covcontact.tangent_check import check_tangent

    path = tmp_path / "cube.toml"
    path.write_text(_CUBE.replace("CELL", "hex8").replace("LOADS", _hydrostatic(150.0, True)))
    rep = check_tangent(load_problem(path), step=2, columns=None)
    assert rep["converged"] and rep["relative_error"] <= 1e-6, rep["relative_error"]


def test_dynamic_energy_account_counts_the_follower_work(tmp_path):
    """A dynamic stage (Newmark's trapezoidal rule, dt = 0.002 over 0.1) of the cube under the three follower
    pressures: the external work, counted on the current faces, equals the kinetic and strain energy at every step
    (balance error within 1e-4 of the energies; measured 5e-5)."""
    from covcontact.io.loader import load_problem

    text = _CUBE.replace("CELL", "hex8").replace("LOADS", _hydrostatic(100.0, True))
    text = text.replace('name = "cube"\n', 'name = "cube"\nprocedure = "dynamic"\ndt = 0.002\nt_end = 0.1\n'
                        'method = "newmark"\n').replace("nu = 0.3 }", "nu = 0.3, density = 1.0 }")
    text = text.replace("[steps]\ncount = 4\n", "")
    path = tmp_path / "dyn.toml"
    path.write_text(text)
    res = load_problem(path).run(out=tmp_path / "o", quiet=True)
    assert res.exit_code == 0
    steps = res.summary["steps"]
    assert len(steps) == 50 and steps[-1]["energy"]["external_work"] > 1.0
    assert max(abs(s["energy"]["balance_error"]) for s in steps) < 1e-4


def test_weighted_pieces_give_the_whole_face_s_forces_and_exact_stiffness():
    """A pressure on pieces of larger faces (Mesh.face_weights, mesh.shell: the two 4-node halves of a hex18's
    six-node side face, weighted 0 at their corners and 2 at their mid-side nodes; the four quarters of a 9-node face,
    weighted 4 at its centre): on a flat face the nodal forces are the whole face's consistent ones (the quadratic
    edge's 1/6, 2/3, 1/6 through each layer; the 9-node face's 1/36, 1/9, 4/9) to 1e-12, and the follower's load
    stiffness with those weights is exact (central differences, 1e-8), also on a distorted piece."""
    from covcontact.elements.follower import point_factors

    # the side face a (0) - m (1) - b (2) at the bottom, a' m' b' (3, 4, 5) at the top, along x (length 2), height 1
    x = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 0, 1], [1, 0, 1], [2, 0, 1]], dtype=float)
    halves = np.array([[0, 1, 4, 3], [1, 2, 5, 4]])
    w = 2.0 * np.isin(halves, [1, 4])
    R, _ = face_blocks(x, halves, 1.0, False, point_factors(x, halves, None, False, w))
    f = np.zeros((6, 3))
    np.add.at(f, halves.ravel(), R.reshape(-1, 3))
    np.testing.assert_allclose(np.abs(f[:, 1]), [1 / 6, 2 / 3, 1 / 6] * 2, atol=1e-12)  # (area 2: 1/2 per layer)
    q = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1], [0, -1], [1, 0], [0, 1], [-1, 0], [0, 0]], dtype=float)
    x9 = np.column_stack([q, np.zeros(9)])
    from covcontact.mesh.shell import _QUARTER_WEIGHT, _quarters

    face = np.arange(9)[None, :]
    quarters = _quarters(face)
    w9 = _QUARTER_WEIGHT * (quarters == 8)
    R, _ = face_blocks(x9, quarters, 1.0, False, point_factors(x9, quarters, None, False, w9))
    f = np.zeros((9, 3))
    np.add.at(f, quarters.ravel(), R.reshape(-1, 3))
    np.testing.assert_allclose(np.abs(f[:, 2]), 4.0 * np.array([1, 1, 1, 1, 4, 4, 4, 4, 16]) / 36, atol=1e-12)
    xd = _distorted(4, 7)
    faces = np.arange(8).reshape(2, 4)
    wd = np.array([[0.0, 2.0, 2.0, 0.0], [0.0, 0.0, 4.0, 0.0]])
    factor = point_factors(xd, faces, None, False, wd)
    err = _fd_error(lambda y: face_blocks(y, faces, 2.9, True, factor), xd, faces)
    assert err < 1e-8
