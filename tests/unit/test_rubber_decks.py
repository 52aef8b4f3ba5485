"""*HYPERELASTIC in decks: the models and CalculiX's data-line order, a C3D8 cube stretched uniaxially against the
reaction CalculiX computed and against the closed form, the compressibility CalculiX substitutes for 0, one-line
errors."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from covcontact.io.deck import DeckError
from covcontact.io.deck_import import import_deck
from covcontact.io.loader import load_problem
from covcontact.materials.rubber import Rubber

CUBE = """*HEADING
Uniaxial stretch of a unit C3D8 cube, hyperelastic
*NODE, NSET=NALL
1, 0.0, 0.0, 0.0
2, 1.0, 0.0, 0.0
3, 1.0, 1.0, 0.0
4, 0.0, 1.0, 0.0
5, 0.0, 0.0, 1.0
6, 1.0, 0.0, 1.0
7, 1.0, 1.0, 1.0
8, 0.0, 1.0, 1.0
*ELEMENT, TYPE=C3D8, ELSET=EALL
1, 1, 2, 3, 4, 5, 6, 7, 8
*NSET, NSET=XMIN
1, 4, 5, 8
*NSET, NSET=XMAX
2, 3, 6, 7
*NSET, NSET=YMIN
1, 2, 5, 6
*NSET, NSET=ZMIN
1, 2, 3, 4
*MATERIAL, NAME=RUBBER
HYPERCARD
*SOLID SECTION, ELSET=EALL, MATERIAL=RUBBER
*BOUNDARY
XMIN, 1, 1
YMIN, 2, 2
ZMIN, 3, 3
*STEP, NLGEOM, INC=100
*STATIC
0.1, 1.0
*BOUNDARY
XMAX, 1, 1, 1.0
*NODE PRINT, NSET=XMAX, TOTALS=ONLY
RF
*END STEP
"""

#: (the *HYPERELASTIC card, the same model as covcontact's Rubber, CalculiX's total force on XMAX at the end): the
#: deck above run by CalculiX 2.20 (ccx -i), its .dat's "total force (fx,fy,fz) for set XMAX" at time 1 (the cube
#: stretched to twice its length), printed to 7 digits
CASES = {
    "mooney-rivlin": ("*HYPERELASTIC, MOONEY-RIVLIN\n0.4, 0.1, 0.05",
                      Rubber("mooney-rivlin", c=((1, 0, 0.4), (0, 1, 0.1)), d=(0.05,)), 1.545030),
    "neo-hooke": ("*HYPERELASTIC, NEO HOOKE\n0.5, 0.01", Rubber("neo-hooke", c=((1, 0, 0.5),), d=(0.01,)), 1.741860),
    "yeoh": ("*HYPERELASTIC, YEOH\n0.5, -0.02, 0.003, 0.02, 0.05, 0.1",
             Rubber("yeoh", c=((1, 0, 0.5), (2, 0, -0.02), (3, 0, 0.003)), d=(0.02, 0.05, 0.1)), 1.582973),
    "polynomial-2": ("*HYPERELASTIC, POLYNOMIAL, N=2\n0.4, 0.1, 0.02, -0.01, 0.005, 0.05, 0.1",
                     Rubber("polynomial", c=((1, 0, 0.4), (0, 1, 0.1), (2, 0, 0.02), (1, 1, -0.01), (0, 2, 0.005)),
                            d=(0.05, 0.1)), 1.752058),
    "reduced-polynomial-2": ("*HYPERELASTIC, REDUCED POLYNOMIAL, N=2\n0.4, -0.02, 0.05, 0.1",
                             Rubber("reduced-polynomial", c=((1, 0, 0.4), (2, 0, -0.02)), d=(0.05, 0.1)), 1.109525),
    "ogden-3": ("*HYPERELASTIC, OGDEN, N=3\n0.6, 1.3, 0.01, 5.0, -0.02, -2.0, 0.05, 0.02\n0.01",
                Rubber("ogden", mu=(0.6, 0.01, -0.02), alpha=(1.3, 5.0, -2.0), d=(0.05, 0.02, 0.01)), 0.8791161),
    "arruda-boyce": ("*HYPERELASTIC, ARRUDA-BOYCE\n0.8, 2.5, 0.05",
                     Rubber("arruda-boyce", mu=(0.8,), lambda_m=2.5, d=(0.05,)), 1.658712),
}


def _closed_form(mat: Rubber) -> float:
    """The compressible uniaxial force at stretch 2 (the lateral stretch t from dW/dlambda_2 (2, t, t) = 0), the
    manuals' W in the principal stretches differentiated by complex steps (tests/unit/test_rubber_models.py)."""
    from test_rubber_models import _dW

    t = brentq(lambda t: _dW(mat, [2.0, t, t], 1), 0.3, 1.2, xtol=1e-15)
    return _dW(mat, [2.0, t, t], 0)


@pytest.mark.parametrize("case", list(CASES))
def test_stretched_cube_against_calculix(tmp_path, case):
    """covcontact run of the deck: the material read is the model of the card (the same stress at a random F to
    1e-14), the reaction is CalculiX's to 1e-6 (CalculiX prints 7 digits) and the closed form's to 1e-10."""
    card, mat, ccx = CASES[case]
    deck = tmp_path / "cube.inp"
    deck.write_text(CUBE.replace("HYPERCARD", card))
    prob = load_problem(import_deck(deck, tmp_path / "p.toml").problem)
    read = prob.bodies[0].material
    assert isinstance(read, Rubber) and read.model == mat.model
    assert np.array_equal(read.params, mat.params)
    res = prob.run(out=tmp_path / "out")
    assert res.exit_code == 0
    reaction = next(v for k, v in res.summary["steps"][-1]["reactions"].items() if k.upper().endswith("XMAX"))[0]
    assert reaction == pytest.approx(ccx, rel=1e-6)
    assert reaction == pytest.approx(_closed_form(mat), rel=1e-10)


def test_zero_compressibility_takes_calculix_default(tmp_path):
    """D = 0 (incompressible, which needs hybrid elements) becomes CalculiX's D_i = (0.1 / mu0)^i (an initial Poisson's
    ratio of 0.475), said in a note; Ogden N=2's line is mu1, alpha1, mu2, alpha2, D1, D2."""
    deck = tmp_path / "cube.inp"
    deck.write_text(CUBE.replace("HYPERCARD", "*HYPERELASTIC, OGDEN, N=2\n0.5, 2.0, 0.1, -2.0, 0.0, 0.0"))
    imp = import_deck(deck, tmp_path / "p.toml")
    mat = load_problem(imp.problem).bodies[0].material
    assert mat.mu == (0.5, 0.1) and mat.alpha == (2.0, -2.0)
    assert mat.d == pytest.approx(((0.1 / 0.6), (0.1 / 0.6) ** 2), rel=1e-15)
    assert mat.nu == pytest.approx(0.475, abs=1e-3)
    assert sum("D1 = 0" in n for n in imp.notes) == 1 and sum("D2 = 0" in n for n in imp.notes) == 1


@pytest.mark.parametrize("card, words", [
    ("*HYPERELASTIC, MOONEY-RIVLIN\n-0.4, 0.1, 0.05", "c10: the initial shear modulus"),
    ("*HYPERELASTIC, NEO HOOKE\n0.4, -0.05", "d1: the initial bulk modulus"),
    ("*HYPERELASTIC, OGDEN, N=2\n0.5, 2.0, 0.1, 0.0, 0.01, 0.0", "alpha: alpha[1] = 0"),
    ("*HYPERELASTIC, POLYNOMIAL, N=7\n0.4", "N=7"),
    ("*HYPERELASTIC, YEOH, N=2\n0.4", "N=2 is for OGDEN"),
])
def test_bad_cards_are_one_line(tmp_path, card, words):
    deck = tmp_path / "cube.inp"
    deck.write_text(CUBE.replace("HYPERCARD", card))
    with pytest.raises(DeckError) as err:
        import_deck(deck, tmp_path / "p.toml")
    msg = str(err.value)
    assert "\n" not in msg and "*HYPERELASTIC" in msg and words in msg and "cube.inp:" in msg
