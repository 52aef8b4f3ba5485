"""Nearly incompressible planar bodies: F-bar does not lock (docs/verification.md, "Planar bodies", F-bar).

Cook's membrane (Cook 1974), plane strain: a tapered panel with corners (0, 0), (48, 44), (48, 60), (0, 44), clamped
on x = 0 and loaded by a uniform vertical shear on x = 48 (16 long), one linear step K(0) u = f (the linearised
problem). Two set-ups, as tests/verification/test_cook.py has them for the 3D F-bar hex8:

- lambda = 7500, G = 0.375 (nu = 0.499975), total load 1: the vertical displacement of the mid-edge (48, 52) is
  16.4326 in P. Krysl's FinEALE toolkit (example "Cook_3D_strain", a Richardson extrapolation of NICE-T6 triangles),
  the published figure we can name;
- E = 250, nu = 0.4999, total load 100: the corner (48, 60) moves 7.77 (the extrapolation of our 3D F-bar hex8 and
  hex27 sequences, tests/verification/test_cook.py; no published value for exactly this set-up was at hand).

Plain quad4 locks (a third of the answer); F-bar quad4 (the centre's volume change), quad8 and quad9 (J projected on
1, xi, eta) and tri6 (the element mean) converge.

Lame's thick cylinder, plane strain, nu = 0.4999, through the program (``options = { fbar = true }``): the radial
displacement of the bore within 1 % of the closed form (Timoshenko and Goodier, section 33), where plain quad4 gives
a fraction of it.
"""

from __future__ import annotations

import textwrap

import numpy as np
import pytest
import scipy.sparse.linalg as sla

from covcontact.assembly import Pattern
from covcontact.elements.planar import PlanarBody, edge_load_vector
from covcontact.elements.planar_fbar import PlanarFbarBody
from covcontact.io.loader import load_problem
from covcontact.materials import NeoHooke
from covcontact.mesh.generators_planar import rectangle

KRYSL_MID_EDGE = 16.432584376299037
TIP_REFERENCE = 7.77


def cook(n: int, cell: str, fbar: bool, material, total_load: float) -> dict[str, float]:
    m = rectangle(48.0, 44.0, n, n, cell=cell)
    X = m.points.copy()
    X[:, 1] += X[:, 0] / 48.0 * (44.0 - 28.0 * X[:, 1] / 44.0)
    body = (PlanarFbarBody if fbar else PlanarBody)(cell, X, m.cells, material, "plane_strain")
    f = np.zeros_like(X)
    f[:, 1] = total_load / 16.0 * edge_load_vector(X, m.face_set("xmax"), "plane_strain", area_only=True)[:, 1]
    assert abs(f[:, 1].sum() - total_load) <= 1e-12 * total_load
    P = Pattern(body.n_nodes, [body.cells])
    data = P.zeros()
    r = np.zeros(3 * body.n_nodes)
    assert body.assemble(np.zeros_like(X), data, r, P) == -1
    assert np.abs(r).max() <= 1e-9 * total_load
    fixed = np.zeros((body.n_nodes, 3), dtype=bool)
    fixed[m.node_set("xmin")] = True
    fixed[:, 2] = True
    free = np.flatnonzero(~fixed.ravel())
    u = np.zeros(3 * body.n_nodes)
    u[free] = sla.spsolve(P.csr(data)[free][:, free].tocsc(), f.ravel()[free])
    u = u.reshape(-1, 3)
    out = {}
    for name, y in (("tip", 60.0), ("mid", 52.0)):
        node = np.flatnonzero((np.abs(X[:, 0] - 48.0) < 1e-9) & (np.abs(X[:, 1] - y) < 1e-9))
        assert node.size == 1
        out[name] = float(u[node[0], 1])
    return out


def aitken(a: float, b: float, c: float) -> float:
    return c - (c - b) ** 2 / ((c - b) - (b - a))


def test_cook_membrane_quad4_fbar_converges_plain_locks():
    mat = NeoHooke(E=250.0, nu=0.4999)
    fbar = [cook(n, "quad4", True, mat, 100.0)["tip"] for n in (4, 8, 16, 32)]
    plain = [cook(n, "quad4", False, mat, 100.0)["tip"] for n in (4, 8, 16, 32)]
    print("Cook tip, quad4 F-bar:", " ".join(f"{v:.4f}" for v in fbar), " plain:", " ".join(f"{v:.4f}" for v in plain),
          f" extrapolated {aitken(*fbar[-3:]):.4f}")
    assert np.all(np.diff(fbar) > 0.0)
    assert abs(fbar[-1] / TIP_REFERENCE - 1.0) < 0.015
    assert abs(aitken(*fbar[-3:]) / TIP_REFERENCE - 1.0) < 0.005
    assert all(p < 0.4 * TIP_REFERENCE for p in plain)


@pytest.mark.parametrize("cell,n", [("quad4", (8, 16, 32)), ("quad8", (4, 8, 16)), ("quad9", (4, 8, 16)),
                                    ("tri6", (4, 8, 16))])
def test_cook_membrane_mid_edge_against_fineale(cell, n):
    lam, G = 7500.0, 0.375
    mat = NeoHooke(E=G * (3.0 * lam + 2.0 * G) / (lam + G), nu=0.5 * lam / (lam + G))
    mid = [cook(k, cell, True, mat, 1.0)["mid"] for k in n]
    plain = cook(n[-1], cell, False, mat, 1.0)["mid"]
    print(f"Cook mid-edge, {cell} F-bar at {n}:", " ".join(f"{v:.4f}" for v in mid),
          f" extrapolated {aitken(*mid):.4f};  plain {cell} at {n[-1]}: {plain:.4f}")
    assert abs(mid[-1] / KRYSL_MID_EDGE - 1.0) < 0.01
    assert abs(aitken(*mid) / KRYSL_MID_EDGE - 1.0) < 0.003
    assert abs(mid[-1] / KRYSL_MID_EDGE - 1.0) < 0.5 * abs(plain / KRYSL_MID_EDGE - 1.0)


A_IN, B_OUT, E, NU, P = 1.0, 2.0, 1000.0, 0.4999, 0.01


def lame_text(cell: str, fbar: bool, form: str) -> str:
    mesh = ('mesh = { generator = "annulus", r_inner = 1.0, r_outer = 2.0, nr = 8, nt = 6, angle = 90.0 }'
            if form == "plane_strain" else
            'mesh = { generator = "rectangle", lx = 1.0, ly = 0.25, nx = 8, ny = 2, origin = [1.0, 0.0] }')
    holds = ([("angle0", "y"), ("angle1", "x")] if form == "plane_strain" else [("ymin", "y"), ("ymax", "y")])
    conds = "".join(f'[[dirichlet]]\nset = "tube.{s}"\ncomponents = "{c}"\nvalue = 0.0\n' for s, c in holds)
    opts = "options = { fbar = true }" if fbar else ""
    inner = "inner" if form == "plane_strain" else "xmin"
    return textwrap.dedent(f"""
        [problem]
        name = "lame"
        [[bodies]]
        name = "tube"
        formulation = "{form}"
        element = "{cell}"
        {mesh}
        material = {{ model = "neo-hooke", E = {E}, nu = {NU} }}
        {opts}
        [[pressure]]
        set = "tube.{inner}"
        value = {P}
        """) + conds


@pytest.mark.parametrize("form", ["plane_strain", "axisymmetric"])
def test_nearly_incompressible_thick_cylinder(tmp_path, form):
    """Plane strain, or an axisymmetric tube with fixed ends (the same closed form): u_r(a) within 1 % with F-bar
    quad4 and quad8; plain quad4 locks."""
    ca = P * A_IN**2 / (B_OUT**2 - A_IN**2)
    exact = (1 + NU) * ca / E * ((1 - 2 * NU) * A_IN + B_OUT**2 / A_IN)
    got = {}
    for cell, fbar in (("quad4", True), ("quad8", True), ("quad4", False)):
        path = tmp_path / f"{form}_{cell}_{fbar}.toml"
        path.write_text(lame_text(cell, fbar, form))
        res = load_problem(path).run(out=tmp_path / path.stem)
        assert res.exit_code == 0
        u = np.asarray(res.u).reshape(-1, 3)
        X = res.model.system.blocks[0].solid.X
        assert isinstance(res.model.system.blocks[0].solid, PlanarFbarBody) == fbar
        r = np.hypot(X[:, 0], X[:, 1])
        bore = np.isclose(r if form == "plane_strain" else X[:, 0], A_IN)
        ur = (u[bore, 0] * X[bore, 0] + u[bore, 1] * X[bore, 1]) / r[bore] if form == "plane_strain" else u[bore, 0]
        got[(cell, fbar)] = float(ur.mean() / exact)
        if fbar:
            assert np.abs(ur / exact - 1.0).max() < 0.01, (cell, ur / exact)
    print(f"thick cylinder nu = {NU}, {form}: u_r(a) / Lame:",
          ", ".join(f"{c}{' F-bar' if f else ''} {v:.4f}" for (c, f), v in got.items()))
    assert got[("quad4", False)] < 0.9
