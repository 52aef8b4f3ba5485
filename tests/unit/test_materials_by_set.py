"""Several materials in one body by element set (``materials = { SET = {...} }``, ``[bodies.cells]``): a bar of
three materials in series against its closed form, the exact tangent with a plastic part next to elastic ones, the
composite body's history and fields, and bad input (docs/input.md, docs/theory.md section 18)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from covcontact.elements.composite import CompositeBody
from covcontact.io.loader import load_problem
from covcontact.io.validate import InputError
from covcontact.tangent_check import check_tangent

BAR = """
[problem]
name = "three-materials"
[[bodies]]
name = "bar"
element = "CELL"
MATERIAL
materials = { soft = { model = "svk", E = 100.0, nu = 0.3 }, hard = HARD }
mesh = { generator = "block", lx = 3.0, ly = 1.0, lz = 1.0, nx = 6, ny = 2, nz = 2 }
[bodies.cells]
soft = { box = [[1.0, -1.0, -1.0], [2.0, 2.0, 2.0]] }
hard = { box = [[2.0, -1.0, -1.0], [3.0, 2.0, 2.0]] }
[[dirichlet]]
set = "bar.xmin"
components = "x"
[[dirichlet]]
set = "bar.ymin"
components = "y"
[[dirichlet]]
set = "bar.zmin"
components = "z"
[[dirichlet]]
set = "bar.xmax"
components = "x"
value = 0.15
[steps]
count = 3
"""
ELASTIC_HARD = '{ model = "svk", E = 400.0, nu = 0.3 }'
PLASTIC_HARD = ('{ model = "j2", E = 400.0, nu = 0.3, yield_stress = 2.0, hardening = { law = "linear", '
                'modulus = 40.0 } }')


def _problem(tmp_path, hard=ELASTIC_HARD, material='material = { model = "svk", E = 200.0, nu = 0.3 }',
             cell="hex8", extra=""):
    path = tmp_path / "bar.toml"
    path.write_text(BAR.replace("CELL", cell).replace("MATERIAL", material).replace("HARD", hard) + extra)
    return load_problem(path)


@pytest.mark.parametrize("cell", ["hex8", "tet10"])
def test_bar_in_series_against_closed_form(tmp_path, cell):
    """St. Venant-Kirchhoff segments of E = 200, 100, 400 (unit lengths, unit section, nu = 0, so that the segments'
    sections stay equal and the state is uniaxial everywhere) stretched by 5 %: each carries the same force
    F = A lambda_i E (lambda_i^2 - 1) / 2 (S = E E_11) and the stretches add up to the imposed elongation. The reaction
    and each segment's stretch equal the closed form to 1e-8."""
    text = BAR.replace("CELL", cell).replace("MATERIAL", 'material = { model = "svk", E = 200.0, nu = 0.0 }')
    text = text.replace("HARD", ELASTIC_HARD).replace("nu = 0.3", "nu = 0.0")
    path = tmp_path / "bar.toml"
    path.write_text(text)
    res = load_problem(path).run(out=tmp_path / "out")
    assert res.exit_code == 0
    E = np.array([200.0, 100.0, 400.0])

    def stretch(F, e):
        return brentq(lambda lam: lam * e * (lam * lam - 1.0) / 2.0 - F, 0.5, 2.0, xtol=1e-15)

    F = brentq(lambda F: sum(stretch(F, e) - 1.0 for e in E) - 0.15, 1e-6, 100.0, xtol=1e-14)
    reaction = res.summary["steps"][-1]["reactions"]["bar.xmax"][0]
    assert reaction == pytest.approx(F, rel=1e-8)
    x = res.model.positions(res.u)
    X = res.model.system.X
    for k, e in enumerate(E):  # the nodes at x = k + 1 moved by the sum of the stretches up to there
        at = np.abs(X[:, 0] - (k + 1.0)) < 1e-9
        expected = sum(stretch(F, E[j]) for j in range(k + 1)) - (k + 1.0)
        np.testing.assert_allclose(x[at, 0] - X[at, 0], expected, rtol=0, atol=1e-9)


def test_plastic_part_next_to_elastic_ones(tmp_path):
    """A J2 segment (yielding) between elastic ones: the exact tangent matches central differences to 1e-6 at a
    plastic step; the body is a CompositeBody whose history array is the plastic part's width, zero in the elastic
    cells, and whose plastic fields are zero there."""
    prob = _problem(tmp_path, hard=PLASTIC_HARD)
    rep = check_tangent(prob, step=3, columns=None)
    assert rep["converged"] and rep["relative_error"] <= 1e-6, rep["relative_error"]
    res = prob.run(out=tmp_path / "out")
    assert res.exit_code == 0
    solid = res.model.system.blocks[0].solid
    assert isinstance(solid, CompositeBody) and len(solid.parts) == 3
    hist = res.state.elements[0]["hist"]
    mesh = prob.bodies[0].mesh
    hard = mesh.element_sets["hard"]
    elastic = np.setdiff1d(np.arange(mesh.n_cells), hard)
    assert hist.shape[0] == mesh.n_cells and hist.shape[2] > 0
    assert np.abs(hist[elastic]).max() == 0.0 and np.abs(hist[hard]).max() > 0.0
    fields = solid.plastic_fields(res.state.elements[0])
    assert np.all(fields["equivalent_plastic_strain"][hard] > 0.0)
    assert np.all(fields["equivalent_plastic_strain"][elastic] == 0.0)
    # the same force through every segment: the element stresses S_xx (F over the reference section) agree
    pk2 = solid.stress(res.u.reshape(-1, 3)[: mesh.n_nodes], res.state.elements[0]).pk2
    assert np.all(pk2[hard, 0] > 2.0)  # beyond the yield stress


def test_every_cell_in_a_set(tmp_path):
    """Without ``material`` every cell must lie in a set; with sets that cover the body, the run needs no default."""
    text = BAR.replace("MATERIAL", "").replace("CELL", "hex8").replace("HARD", ELASTIC_HARD)
    path = tmp_path / "bar.toml"
    path.write_text(text)
    with pytest.raises(InputError) as err:
        load_problem(path)
    assert "bodies[0].materials" in str(err.value) and "8 of 24 cells lie in none" in str(err.value)
    text = text.replace("soft = { box = [[1.0, -1.0, -1.0]", "soft = { box = [[-1.0, -1.0, -1.0]")
    path.write_text(text)
    prob = load_problem(path)
    assert prob.bodies[0].materials.keys() == {"soft", "hard"}


@pytest.mark.parametrize("change, message", [
    (("hard = { box = [[2.0,", "hard = { box = [[1.5,"), "element set 'hard' shares 4 cells with 'soft'"),
    (("materials = { soft =", "materials = { sfot ="), "no element set 'sfot'"),
    (("hard = { box = [[2.0, -1.0, -1.0], [3.0, 2.0, 2.0]] }", "hard = { box = [[5.0, 5.0, 5.0], [6.0, 6.0, 6.0]] }"),
     "no cell centroid lies inside this box"),
])
def test_bad_input(tmp_path, change, message):
    path = tmp_path / "bar.toml"
    text = BAR.replace("CELL", "hex8").replace("MATERIAL", 'material = { model = "svk", E = 200.0, nu = 0.3 }')
    path.write_text(text.replace("HARD", ELASTIC_HARD).replace(*change))
    with pytest.raises(InputError) as err:
        load_problem(path)
    assert message in str(err.value) and "\n" not in str(err.value)
