"""Tied pairs in the plane (``law = "tied"`` between edge sets of planar bodies): each slave node bonded by a vector
penalty to its closest point on the master edges in the reference configuration (docs/theory.md, sections 14 and
28). Checked: two blocks of non-matching meshes tied and pulled and sheared carry what one block carries; two tubes
tied into one under internal pressure against Lame's closed form (axisymmetric); the Newton tangent of a tied
problem against central differences; a tie to a rigid line refused with one line."""

from __future__ import annotations

import math
import textwrap

import numpy as np
import pytest

from covcontact.io.loader import load_problem
from covcontact.tangent_check import check_tangent

E, NU = 1000.0, 0.3


def _body(name: str, form: str, cell: str, lx: float, ly: float, nx: int, ny: int, ox: float, oy: float) -> str:
    return f"""
[[bodies]]
name = "{name}"
formulation = "{form}"
element = "{cell}"
mesh = {{ generator = "rectangle", lx = {lx}, ly = {ly}, nx = {nx}, ny = {ny}, origin = [{ox}, {oy}] }}
material = {{ model = "neo-hooke", E = {E}, nu = {NU} }}
"""


def _load(tmp_path, name: str, text: str):
    path = tmp_path / f"{name}.toml"
    path.write_text(textwrap.dedent(text))
    return load_problem(path)


def _run(tmp_path, name: str, text: str):
    res = _load(tmp_path, name, text).run(out=tmp_path / name, quiet=True)
    assert res.exit_code == 0
    return res


def blocks_text(tied: bool, cell: str = "quad4", nx_up: int = 4) -> str:
    """A plane strain block 1 x 1 held at its bottom and sheared (20) and pulled (10) at its top: in one piece (4 x 4
    elements), or as two halves (4 x 2 and nx_up x 2) tied at y = 0.5."""
    load = '\n[[traction]]\nset = "{top}.ymax"\nvalue = [20.0, 10.0, 0.0]\n'
    fix = '\n[[dirichlet]]\nset = "low.ymin"\ncomponents = "xy"\nvalue = 0.0\n'
    head = '[problem]\nname = "tied"\n[steps]\ncount = 2\n'
    if not tied:
        return head + _body("low", "plane_strain", cell, 1.0, 1.0, 4, 4, 0.0, 0.0) + fix + load.format(top="low")
    return (head + _body("low", "plane_strain", cell, 1.0, 0.5, 4, 2, 0.0, 0.0)
            + _body("up", "plane_strain", cell, 1.0, 0.5, nx_up, 2, 0.0, 0.5) + fix + load.format(top="up")
            + '\n[[contact]]\nname = "glue"\nslave = "up.ymin"\nmaster = "low.ymax"\nlaw = "tied"\npenalty = "auto"\n')


def _top_mean(res, body: str) -> np.ndarray:
    blk = next(b for b in res.model.system.blocks if b.name == body)
    u = np.asarray(res.u).reshape(-1, 3)[blk.offset: blk.offset + blk.n_nodes]
    X = blk.solid.X if hasattr(blk.solid, "X") else None
    X = np.asarray(X)
    top = np.isclose(X[:, 1], X[:, 1].max())
    return u[top, :2].mean(axis=0)


@pytest.mark.parametrize("cell", ["quad4", "quad8"])
def test_matching_tied_halves_carry_what_one_block_carries(tmp_path, cell):
    """Sheared and pulled at the top: a frictionless contact would slide and open; the tie carries both. Halves of 4
    elements across each make the one-piece block's discretisation but for the tie's compliance (its penalty 100 E /
    h per area, two orders stiffer than the elements): the top moves as the one-piece block's within 0.3 %."""
    one = _top_mean(_run(tmp_path, f"one_{cell}", blocks_text(False, cell)), "low")
    res = _run(tmp_path, f"two_{cell}", blocks_text(True, cell))
    two = _top_mean(res, "up")
    assert np.linalg.norm(two - one) <= 3e-3 * np.linalg.norm(one), (one, two)
    _tie_forces_balance_the_load(res)


@pytest.mark.parametrize("nx_up", [3, 5])
def test_non_matching_tied_halves(tmp_path, nx_up):
    """Quad8 halves of 4 and nx_up elements across tied: the top displacement within 1 % of the converged one-piece
    block's (16 x 16 quad8 elements), the discretisation's own error (the 4 x 4 one-piece block is 0.7 % from it)."""
    ref = _top_mean(_run(tmp_path, "fine", blocks_text(False, "quad8").replace("nx = 4, ny = 4", "nx = 16, ny = 16")),
                    "low")
    res = _run(tmp_path, f"two_{nx_up}", blocks_text(True, "quad8", nx_up))
    two = _top_mean(res, "up")
    assert np.linalg.norm(two - ref) <= 1e-2 * np.linalg.norm(ref), (ref, two)
    _tie_forces_balance_the_load(res)


def _tie_forces_balance_the_load(res):
    """Every slave node tied; the tie forces on the upper half (on its slave nodes) balance its load: 20 and 10 per
    unit length of its top (the tractions are per reference area), over a width of 1 and a unit thickness."""
    state = res.state.contact.passes[0]
    assert (state.facet >= 0).all()
    assert state.force[:, 0].sum() == pytest.approx(-20.0, rel=1e-6)
    assert state.force[:, 1].sum() == pytest.approx(-10.0, rel=1e-6)


def tubes_text(tied: bool) -> str:
    """An axisymmetric tube a = 1 < r < b = 2, axially held (plane strain in z), under an internal pressure 1: in one
    piece (quad8, 4 x 2 elements) or as two tubes 1 < r < 1.5 (2 x 2) and 1.5 < r < 2 (2 x 3) tied at r = 1.5."""
    head = '[problem]\nname = "tube"\n[steps]\ncount = 1\n'
    hold = "".join(f'\n[[dirichlet]]\nset = "{b}.{s}"\ncomponents = "y"\nvalue = 0.0\n'
                   for b in (("inner", "outer") if tied else ("inner",)) for s in ("ymin", "ymax"))
    load = '\n[[pressure]]\nset = "inner.xmin"\nvalue = 1.0\n'
    if not tied:
        return head + _body("inner", "axisymmetric", "quad8", 1.0, 0.5, 4, 2, 1.0, 0.0) + hold + load
    return (head + _body("inner", "axisymmetric", "quad8", 0.5, 0.5, 2, 2, 1.0, 0.0)
            + _body("outer", "axisymmetric", "quad8", 0.5, 0.5, 2, 3, 1.5, 0.0) + hold + load
            + '\n[[contact]]\nname = "glue"\nslave = "outer.xmin"\nmaster = "inner.xmax"\nlaw = "tied"\n'
              'penalty = "auto"\n')


def _inner_radial(res) -> float:
    blk = next(b for b in res.model.system.blocks if b.name == "inner")
    u = np.asarray(res.u).reshape(-1, 3)[blk.offset: blk.offset + blk.n_nodes]
    X = np.asarray(blk.solid.X)
    return float(u[np.isclose(X[:, 0], 1.0), 0].mean())


def test_tied_tubes_against_lame(tmp_path):
    """Two axisymmetric tubes tied into one (the tie weighted with 2 pi R, its forces the circumference's totals)
    under an internal pressure p: the radial displacement of the bore within 0.5 % of Lame's closed form for a long
    tube (plane strain along the axis), u(a) = (1 + nu) p a / E (1 - 2 nu + b^2 / a^2) a^2 / (b^2 - a^2), and within
    0.1 % of the tube in one piece; the pressure p E-small (1e-3), so the closed form of small strain holds to 1e-3."""
    a, b, p = 1.0, 2.0, 1.0
    lame = (1 + NU) * p * a / E * (1 - 2 * NU + b**2 / a**2) * a**2 / (b**2 - a**2)
    one = _inner_radial(_run(tmp_path, "one", tubes_text(False)))
    res = _run(tmp_path, "two", tubes_text(True))
    two = _inner_radial(res)
    assert two == pytest.approx(lame, rel=5e-3)
    assert two == pytest.approx(one, rel=1e-3)
    # the tie pushes the outer tube out with the radial stress at r = 1.5 over its bore (axial length 0.5, the whole
    # circumference): -2 pi R L sigma_r, Lame's sigma_r = -p a^2 (b^2 / r^2 - 1) / (b^2 - a^2)
    sr = -p * a**2 * (b**2 / 1.5**2 - 1) / (b**2 - a**2)
    state = res.state.contact.passes[0]
    assert (state.facet >= 0).all()
    assert state.force[:, 0].sum() == pytest.approx(-2 * math.pi * 1.5 * 0.5 * sr, rel=1e-3)


def test_tied_planar_tangent_against_differences(tmp_path):
    """The Newton tangent of the non-matching tied blocks (quad8) at the converged first step, every column against
    central differences of the residual: within 1e-6 (the tie's own blocks are exact and constant)."""
    prob = _load(tmp_path, "fd", blocks_text(True, "quad8", 3))
    rep = check_tangent(prob, step=1, columns=None)
    assert rep["converged"] and rep["relative_error"] <= 1e-6, rep["relative_error"]


def test_tie_to_a_rigid_line_refused(tmp_path):
    text = blocks_text(True).replace('master = "low.ymax"', 'master = "floor"') + """
[[rigid]]
name = "floor"
shape = "plane"
point = [0.0, 0.5, 0.0]
normal = [0.0, 1.0, 0.0]
"""
    with pytest.raises(Exception, match="bonds to a meshed surface"):
        _load(tmp_path, "bad", text)
