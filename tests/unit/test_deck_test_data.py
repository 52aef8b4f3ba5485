"""*HYPERELASTIC, ..., TEST DATA INPUT in decks (Abaqus's *UNIAXIAL, *BIAXIAL and *PLANAR TEST DATA): the constants
are fitted as a problem file's test_data (covcontact.materials.fit), POISSON= gives D1 = 3 (1 - 2 nu) / (mu0 (1 + nu))
from the fitted mu0 (K0 = 2 / D1), and what covcontact does not read is listed, one line each."""

from __future__ import annotations

import numpy as np
import pytest

from covcontact.io.deck import DeckError
from covcontact.io.deck_import import import_deck
from covcontact.io.loader import load_problem
from covcontact.materials.fit import nominal_stress
from covcontact.materials.rubber import Rubber

from test_rubber_decks import CASES, CUBE

#: the Mooney-Rivlin of tests/unit/test_rubber_decks.py (C10 = 0.4, C01 = 0.1, D1 = 0.05, CalculiX's reaction of the
#: stretched cube at the end): mu0 = 1, so POISSON = 2.95 / 6.05 gives D1 = 3 (1 - 2 nu) / (1 + nu) = 0.05
MR = Rubber("mooney-rivlin", c=((1, 0, 0.4), (0, 1, 0.1)), d=(0.05,))
NU = 2.95 / 6.05


def _lines(kind: str, strain) -> str:
    """Data lines 'nominal stress, nominal strain' of MR's incompressible closed form."""
    return "\n".join(f"{s:.17g}, {e:.17g}" for s, e in zip(nominal_stress(MR, kind, strain), strain))


UNI = np.array([-0.3, -0.15, 0.1, 0.25, 0.5, 0.8, 1.2, 1.6])
BI = np.array([0.05, 0.15, 0.3, 0.5, 0.8])
PLANAR = np.array([0.1, 0.3, 0.6, 1.0])
CARD = (f"*HYPERELASTIC, MOONEY-RIVLIN, TEST DATA INPUT, POISSON={NU!r}\n*UNIAXIAL TEST DATA\n{_lines('uniaxial', UNI)}\n"
        f"*BIAXIAL TEST DATA\n{_lines('equibiaxial', BI)}\n*PLANAR TEST DATA\n{_lines('planar', PLANAR)}")


def _import(tmp_path, card):
    deck = tmp_path / "cube.inp"
    deck.write_text(CUBE.replace("HYPERCARD", card))
    return import_deck(deck, tmp_path / "p.toml")


def test_fitted_deck_is_the_deck_of_its_constants(tmp_path):
    """Test data made from a Mooney-Rivlin's closed forms (uniaxial tension and compression, equibiaxial, planar)
    give back its constants (to 1e-12) and, with POISSON=, its D1; the stretched cube's reaction is then CalculiX's
    for the deck with those constants on the data line (1.545030, test_rubber_decks.py) to its 7 digits. The log
    says the fit."""
    imp = _import(tmp_path, CARD)
    assert imp.unsupported == []
    prob = load_problem(imp.problem)
    mat = prob.bodies[0].material
    assert mat.model == "mooney-rivlin"
    np.testing.assert_allclose(mat.params, MR.params, rtol=1e-12, atol=1e-14)
    assert mat.d == pytest.approx((0.05,), rel=1e-12) and mat.nu == pytest.approx(NU, rel=1e-12)
    res = prob.run(out=tmp_path / "out")
    assert res.exit_code == 0
    reaction = next(v for k, v in res.summary["steps"][-1]["reactions"].items() if k.upper().endswith("XMAX"))[0]
    assert reaction == pytest.approx(CASES["mooney-rivlin"][2], rel=1e-6)
    assert any("mooney-rivlin fitted to 3 tests" in line for line in mat.fitted)
    assert any("compressibility from Poisson's ratio" in line for line in mat.fitted)


def test_ogden_fit_of_a_deck_equals_the_problem_files(tmp_path):
    """Treloar's data as a deck's cards (Ogden, N=3, POISSON=0.4995) and as a problem file's test_data with poisson:
    the same constants and compressibility, bit for bit."""
    from test_rubber_fit import _treloar

    tests = _treloar()
    cards = "".join(f"*{ {'uniaxial': 'UNIAXIAL', 'equibiaxial': 'BIAXIAL', 'planar': 'PLANAR'}[t.kind]} TEST DATA\n"
                    + "\n".join(f"{s!r}, {e!r}" for s, e in zip(t.stress.tolist(), t.strain.tolist())) + "\n"
                    for t in tests)
    imp = _import(tmp_path, "*HYPERELASTIC, OGDEN, N=3, TEST DATA INPUT, POISSON=0.4995\n" + cards.rstrip())
    deck_mat = load_problem(imp.problem).bodies[0].material
    from covcontact.materials.fit import fitted_material

    data = [{"kind": t.kind, "strain": t.strain.tolist(), "stress": t.stress.tolist()} for t in tests]
    ref = fitted_material("ogden", {"test_data": data, "n": 3, "poisson": 0.4995}, tmp_path)
    assert deck_mat.mu == ref.mu and deck_mat.alpha == ref.alpha and deck_mat.d == ref.d
    assert ref.nu == pytest.approx(0.4995, rel=1e-12)


@pytest.mark.parametrize("card, words", [
    (CARD.replace(f", POISSON={NU!r}", ""), "without POISSON= or *VOLUMETRIC TEST DATA the fitted material is "
                                           "incompressible"),
    (CARD.replace(f", POISSON={NU!r}", "") + "\n*VOLUMETRIC TEST DATA\n-1.0, 0.99", "*VOLUMETRIC TEST DATA ("),
    (CARD.replace("*PLANAR TEST DATA", "*PLANAR TEST DATA, SMOOTH=3"), "SMOOTH: the smoothing filter"),
    (CARD + "\n9.0, 2.0, 20.0", "test data at 2 temperatures"),
])
def test_what_is_not_read_is_listed(tmp_path, card, words):
    """A fit without compressibility (Abaqus/Standard: incompressible), volumetric test data, SMOOTH and several
    temperatures are listed as unsupported, one line each; with --ignore-unsupported POISSON=0.475, the data as given
    and the first temperature's points are used."""
    imp = _import(tmp_path, card)
    assert len(imp.unsupported) == 1 and words in imp.unsupported[0] and "cube.inp:" in imp.unsupported[0]
    mat = load_problem(imp.problem).bodies[0].material
    if "POISSON" not in card:
        assert mat.nu == pytest.approx(0.475, rel=1e-12)
    else:
        np.testing.assert_allclose(mat.params, MR.params, rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("card, words", [
    ("*HYPERELASTIC, MOONEY-RIVLIN, TEST DATA INPUT, POISSON=0.49", "without *UNIAXIAL, *BIAXIAL or *PLANAR TEST DATA"),
    ("*HYPERELASTIC, MOONEY-RIVLIN, TEST DATA INPUT, POISSON=0.5\n*UNIAXIAL TEST DATA\n0.1, 0.1", "POISSON=0.5"),
    ("*HYPERELASTIC, MOONEY-RIVLIN, TEST DATA INPUT, POISSON=0.49\n0.4, 0.1, 0.05", "not from data lines"),
    ("*HYPERELASTIC, MOONEY-RIVLIN, POISSON=0.49\n0.4, 0.1, 0.05", "POISSON= sets the compressibility"),
    ("*HYPERELASTIC, MOONEY-RIVLIN\n0.4, 0.1, 0.05\n*UNIAXIAL TEST DATA\n0.1, 0.1", "belongs after *HYPERELASTIC"),
    ("*HYPERELASTIC, MOONEY-RIVLIN, TEST DATA INPUT, POISSON=0.49\n*UNIAXIAL TEST DATA\n0.1, 0.1\n0.2, 0.1",
     "not monotone"),
    ("*HYPERELASTIC, MOONEY-RIVLIN, TEST DATA INPUT, POISSON=0.49\n*UNIAXIAL TEST DATA\n0.1", "'nominal stress, "
                                                                                            "nominal strain"),
])
def test_bad_test_data_is_one_line(tmp_path, card, words):
    with pytest.raises(DeckError) as err:
        _import(tmp_path, card)
    msg = str(err.value)
    assert "\n" not in msg and "cube.inp:" in msg and words in msg


@pytest.mark.parametrize("extra, words", [
    ({"poisson": 0.5}, "must be a number in (-1, 0.5)"),
    ({"poisson": True}, "must be a number in (-1, 0.5)"),
    ({"poisson": 0.49, "d1": 0.01}, "give the compressibility once"),
])
def test_problem_file_poisson_errors(tmp_path, extra, words):
    """A problem file's ``poisson`` (the compressibility of fitted constants, as POISSON=): bad values name the key."""
    from covcontact.materials.fit import FitError, fitted_material

    data = [{"kind": "uniaxial", "strain": UNI.tolist(), "stress": nominal_stress(MR, "uniaxial", UNI).tolist()}]
    with pytest.raises(FitError) as err:
        fitted_material("mooney-rivlin", {"test_data": data, **extra}, tmp_path)
    assert err.value.key == "poisson" and words in str(err.value)
