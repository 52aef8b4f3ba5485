"""Hyperelastic constants fitted to a deck's test data: *HYPERELASTIC, <model>, N=n, TEST DATA INPUT[, POISSON=nu]
with *UNIAXIAL TEST DATA, *BIAXIAL TEST DATA and *PLANAR TEST DATA (Abaqus's cards; data lines 'nominal stress,
nominal strain[, temperature]').

The material becomes a problem file's fitted material (``test_data``, ``n``, ``poisson``: covcontact.materials.fit,
docs/input.md "Fitting to test data"): the run fits the model to all tests together by least squares, as Abaqus does,
and its log says the constants, the errors and the stability verdict. What Abaqus reads and covcontact does not is
listed as unsupported (``--ignore-unsupported`` says what then happens): *VOLUMETRIC TEST DATA, SMOOTH=, several
temperatures, and a material without POISSON= (Abaqus/Standard's fully incompressible fit, which needs the hybrid
elements' mixed formulation covcontact does not have).
"""

from __future__ import annotations

import re
from pathlib import Path

from .deck import Card, DeckError

#: the cards read here (deck_model dispatches them)
TEST_DATA_CARDS = ("UNIAXIAL TEST DATA", "BIAXIAL TEST DATA", "PLANAR TEST DATA", "VOLUMETRIC TEST DATA")
#: the kind of covcontact.materials.fit each card gives
_KIND = {"UNIAXIAL TEST DATA": "uniaxial", "BIAXIAL TEST DATA": "equibiaxial", "PLANAR TEST DATA": "planar"}
#: the compressibility used with --ignore-unsupported where the deck gives none (Abaqus/Explicit's default)
DEFAULT_POISSON = 0.475


def is_test_data_input(c: Card) -> bool:
    """Whether a *HYPERELASTIC card has TEST DATA INPUT."""
    return any(" ".join(p.upper().split()) == "TEST DATA INPUT" for p in c.params)


def start_test_data(reader, c: Card, mat: dict, model: str, n: int) -> None:
    """*HYPERELASTIC, ..., TEST DATA INPUT: the material's fitted model, its tests to come on the cards that follow."""
    if c.rows():
        raise c.fail("TEST DATA INPUT takes its data from *UNIAXIAL, *BIAXIAL and *PLANAR TEST DATA, not from data "
                     "lines: remove the data line or the parameter", 0)
    out: dict = {"model": model, "test_data": []}
    if model in ("polynomial", "reduced-polynomial", "ogden"):
        out["n"] = n
    poisson = c.params.get("POISSON")
    if poisson is not None:
        try:
            nu = float(poisson)
        except ValueError:
            raise c.fail(f"POISSON={poisson}: Poisson's ratio must be a number, e.g. POISSON=0.495") from None
        if not -1.0 < nu < 0.5:
            raise c.fail(f"POISSON={poisson}: Poisson's ratio must lie in (-1, 0.5); 0.5 (incompressible) needs a "
                         f"mixed formulation covcontact does not have: give e.g. 0.495")
        out["poisson"] = nu
    mat["hyperelastic"] = out
    mat["hyperelastic_where"] = c.where()


def read_test_data_card(reader, c: Card) -> None:
    """A *UNIAXIAL, *BIAXIAL, *PLANAR or *VOLUMETRIC TEST DATA card of the current material."""
    if reader.material is None:
        raise c.fail("comes before any *MATERIAL")
    mat = reader.m.materials[reader.material]
    hyper = mat.get("hyperelastic")
    if hyper is None or "test_data" not in hyper:
        raise c.fail("belongs after *HYPERELASTIC, ..., TEST DATA INPUT in the same *MATERIAL (test data of a "
                     "material without it are not used)")
    for p in c.params:
        if p != "SMOOTH":
            reader.m.unsupported.append(f"{c.where()}: *{c.name}, {p} is not supported")
    if "SMOOTH" in c.params:
        reader.m.unsupported.append(f"{c.where()}: *{c.name}, SMOOTH: the smoothing filter is not supported; with "
                                    f"--ignore-unsupported the data are fitted as given")
    if c.name == "VOLUMETRIC TEST DATA":
        mat["volumetric_where"] = c.where()
        return
    rows = c.rows()
    if not rows:
        raise c.fail("needs data lines 'nominal stress, nominal strain'")
    points = []
    for k, row in enumerate(rows):
        if len(row) < 2:
            raise c.fail("a data line is 'nominal stress, nominal strain[, temperature]'", k)
        points.append((c.number(k, 0, row, "the nominal stress"), c.number(k, 1, row, "the nominal strain"),
                       c.number(k, 2, row, "the temperature", 0.0)))
    temps = list(dict.fromkeys(p[2] for p in points))
    if len(temps) > 1:
        reader.m.unsupported.append(f"{c.where()}: *{c.name}: test data at {len(temps)} temperatures are not "
                                    f"supported; with --ignore-unsupported those at {temps[0]:g} are fitted")
    points = sorted((p for p in points if p[2] == temps[0]), key=lambda p: p[1])
    hyper["test_data"].append({"kind": _KIND[c.name], "strain": [p[1] for p in points],
                               "stress": [p[0] for p in points], "where": c.where()})


def finish_test_data(m) -> None:
    """After the last card: each fitted material's tests and compressibility checked, its initial Young's modulus
    (``E0``, for the contact defaults) from the fit."""
    from ..materials.fit import FitError, fitted_material
    from ..materials.rubber import RubberError

    for mat in m.materials.values():
        hyper = mat.get("hyperelastic")
        if hyper is None or "test_data" not in hyper:
            continue
        where = mat["hyperelastic_where"]
        if not hyper["test_data"]:
            raise DeckError(f"{where}: *HYPERELASTIC, TEST DATA INPUT without *UNIAXIAL, *BIAXIAL or *PLANAR TEST DATA "
                            f"after it: give the tests (or the constants on a data line, without TEST DATA INPUT)")
        if "poisson" not in hyper:
            vol = mat.get("volumetric_where")
            what = (f"*VOLUMETRIC TEST DATA ({vol}) is not supported" if vol else
                    "without POISSON= or *VOLUMETRIC TEST DATA the fitted material is incompressible (Abaqus/Standard's"
                    " hybrid elements), which needs a mixed formulation covcontact does not have")
            m.unsupported.append(f"{where}: *HYPERELASTIC, TEST DATA INPUT: {what}; give POISSON= (e.g. 0.495); with "
                                 f"--ignore-unsupported POISSON={DEFAULT_POISSON} is used (Abaqus/Explicit's default)")
            hyper["poisson"] = DEFAULT_POISSON
        keys = {k: v for k, v in hyper.items() if k not in ("model", "test_data")}
        keys["test_data"] = [{k: v for k, v in t.items() if k != "where"} for t in hyper["test_data"]]
        try:
            mat["E0"] = fitted_material(hyper["model"], keys, Path(".")).E
        except (FitError, RubberError) as exc:
            k = re.match(r"test_data\[(\d+)\]", exc.key or "")
            at = hyper["test_data"][int(k.group(1))]["where"] if k else where
            raise DeckError(f"{at}: {exc}") from None
        hyper["test_data"] = keys["test_data"]
