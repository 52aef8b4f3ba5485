"""The pressure-overclosure laws on planar pairs (``law`` "exponential" in both forms, "arctan", "table" between edge
sets of planar bodies; docs/theory.md, "Pressure-overclosure laws" and section 28): the uniform overclosure of a
pressed interface against each curve's closed form, plane strain and axisymmetric; the tangent against central
differences, a pulling arctan slave included; a deck's EXPONENTIAL, TABULAR and node-to-face LINEAR on CPE4 and CAX4
elements."""

from __future__ import annotations

import math

import numpy as np
import pytest

from covcontact.io.loader import load_problem
from covcontact.tangent_check import check_tangent

from planar_blocks import two_blocks

E = 1000.0
Q = 1.0          # the pressure on the upper block's top

LAWS = {
    "table": 'law = "table"\ntable = [[0.0, 0.0], [1e-3, 0.5], [3e-3, 2.0]]\n',
    "calculix": 'law = "exponential"\nform = "calculix"\nclearance = 2e-3\npressure = 0.25\n',
    "abaqus": 'law = "exponential"\nclearance = 2e-3\npressure = 0.25\n',
    "arctan": 'law = "arctan"\npenalty = 500.0\ntension = 0.05\n',
}


def overclosure(law: str) -> float:
    """The overclosure d at which each curve's pressure is Q (closed forms; the arctan one by bisection of its
    closed form): the table's second segment, CalculiX's p0 exp(ln(100) d / c0), Abaqus' p0 t (e^t - 1) / (e - 1)
    with t = 1 + d / c0, and K d (1/2 + atan(d / e) / pi) with e = pi sigma_inf / K."""
    if law == "table":
        return 1e-3 + (Q - 0.5) / (2.0 - 0.5) * 2e-3
    if law == "calculix":
        return 2e-3 * math.log(Q / 0.25) / math.log(100.0)
    f = {"abaqus": lambda d: 0.25 * (1 + d / 2e-3) * (math.exp(1 + d / 2e-3) - 1) / (math.e - 1) - Q,
         "arctan": lambda d: 500.0 * d * (0.5 + math.atan(d / (math.pi * 0.05 / 500.0)) / math.pi) - Q}[law]
    lo, hi = 0.0, 1.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if f(mid) < 0 else (lo, mid)
    return 0.5 * (lo + hi)


def blocks(form: str, law: str, gap: float = 0.0, steps: int = 4, upper: str = "lx = 1.0, ly = 0.5, nx = 4") -> str:
    return two_blocks(form, '[[contact]]\nname = "c"\nslave = "up.ymin"\nmaster = "low.ymax"\nweighting = "area"\n'
                      + LAWS[law], material=f'model = "svk", E = {E}, nu = 0.3', upper=upper,
                      ox_up=0.05 if "0.9" in upper else 0.0, gap=gap, load=f'[[pressure]]\nset = "up.ymax"\nvalue = {Q}\n',
                      steps=steps, name="laws")


@pytest.mark.parametrize("form", ["plane_strain", "axisymmetric"])
@pytest.mark.parametrize("law", list(LAWS))
def test_pressed_interface_overclosure_is_the_curve_s(tmp_path, form, law):
    """Two blocks with matching edges, the upper one pressed by Q: the contact pressure is Q everywhere (the weights
    are the consistent loads of a uniform pressure over the thickness or the circumference), so every slave's
    overclosure is the curve's d(Q) (closed form, 1e-7 relative) and the contact forces sum to the load (1e-9)."""
    path = tmp_path / f"{law}_{form}.toml"
    path.write_text(blocks(form, law))
    res = load_problem(path).run(out=tmp_path / "o", quiet=True)
    assert res.exit_code == 0
    st = res.state.contact.passes[0]
    d = overclosure(law)
    np.testing.assert_allclose(-st.gap, d, rtol=1e-7)
    area = math.pi * (2.0 ** 2 - 1.0 ** 2) if form == "axisymmetric" else 1.0
    assert np.abs(st.force[:, 1]).sum() == pytest.approx(Q * area, rel=1e-9)


@pytest.mark.parametrize("law", list(LAWS))
def test_tangent_against_differences(tmp_path, law):
    """The Newton tangent at the converged first step, every column against central differences of the residual:
    within 1e-6 (plane strain, the upper block 0.9 wide and shifted so that its slaves lie inside the master's
    segments; the arctan case with the blocks apart by 1e-4, inside its reach, where its tension pulls the
    slaves)."""
    gap = 1e-4 if law == "arctan" else 0.0
    text = blocks("plane_strain", law, gap, steps=4, upper="lx = 0.9, ly = 0.5, nx = 3")
    if law == "arctan":  # (the pull: reach 1 x sqrt(weight) so that the clearance is inside it, no pressure)
        text = text.replace("tension = 0.05\n", "tension = 0.05\nreach = 1.0\n").replace(f"value = {Q}\n", "value = 0.0\n")
        text = text.replace('[[dirichlet]]\nset = "low.ymin"', '[[dirichlet]]\nset = "up.ymax"\ncomponents = "y"\n'
                            'value = 0.0\n[[dirichlet]]\nset = "low.ymin"')
    path = tmp_path / f"fd_{law}.toml"
    path.write_text(text)
    prob = load_problem(path)
    rep = check_tangent(prob, step=1, columns=None)
    assert rep["converged"] and rep["relative_error"] <= 1e-6, rep["relative_error"]
    if law == "arctan":
        res = load_problem(path).run(out=tmp_path / "o", quiet=True)
        st = res.state.contact.passes[0]
        assert np.all(st.gap > 0.0) and np.all(st.force[:, 1] < 0.0)   # apart, and pulled down towards the master


def _deck(etype: str, behavior: str) -> str:
    """Two CPE4 or CAX4 blocks (1 x 0.5, 4 x 2 elements), the upper pressed onto the lower by Q, a NODE TO SURFACE
    pair with the *SURFACE BEHAVIOR line ``behavior`` (a step without NLGEOM: the pressure is the dead load of the
    problem-file case; with NLGEOM it would follow the top's current length)."""
    nodes, els = [], []
    ox = 1.0 if etype == "CAX4" else 0.0
    for b, oy in ((0, 0.0), (1, 0.5)):
        base = 15 * b
        for j in range(3):
            for i in range(5):
                nodes.append(f"{base + 5 * j + i + 1}, {ox + 0.25 * i}, {oy + 0.25 * j}, 0.")
        for j in range(2):
            for i in range(4):
                n1 = base + 5 * j + i + 1
                els.append(f"{8 * b + 4 * j + i + 1}, {n1}, {n1 + 1}, {n1 + 6}, {n1 + 5}")
    hold = "" if etype == "CAX4" else "1, 1\n6, 1\n11, 1\n16, 1\n21, 1\n26, 1\n"
    return ("*NODE\n" + "\n".join(nodes) + f"\n*ELEMENT, TYPE={etype}, ELSET=EL\n" + "\n".join(els[:8])
            + f"\n*ELEMENT, TYPE={etype}, ELSET=EU\n" + "\n".join(els[8:]) + "\n"
            + "*ELSET, ELSET=TOPL\n5, 6, 7, 8\n*ELSET, ELSET=BOTU\n9, 10, 11, 12\n*ELSET, ELSET=TOPU\n13, 14, 15, 16\n"
            + "*SURFACE, NAME=MAST\nTOPL, S3\n*SURFACE, NAME=SLAV\nBOTU, S1\n"
            + "*MATERIAL, NAME=M\n*ELASTIC\n1000., 0.3\n*SOLID SECTION, ELSET=EL, MATERIAL=M\n1.\n"
            + "*SOLID SECTION, ELSET=EU, MATERIAL=M\n1.\n*SURFACE INTERACTION, NAME=SI\n" + behavior
            + "*CONTACT PAIR, INTERACTION=SI, TYPE=NODE TO SURFACE\nSLAV, MAST\n"
            + "*BOUNDARY\n1, 2\n2, 2\n3, 2\n4, 2\n5, 2\n" + hold + "*NSET, NSET=NALL, GENERATE\n1, 30\n"
            + f"*STEP\n*STATIC\n0.25, 1.\n*DLOAD\nTOPU, P3, {Q}\n*NODE PRINT, NSET=NALL\nU\n*END STEP\n")


@pytest.mark.parametrize("etype", ["CPE4", "CAX4"])
@pytest.mark.parametrize("behavior,law", [
    ("*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=EXPONENTIAL\n2e-3, 0.25\n", "calculix"),
    ("*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=TABULAR\n0., 0.\n0.5, 1e-3\n2.0, 3e-3\n", "table"),
    ("*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n500., 0.05\n", "arctan")])
def test_deck_laws_on_planar_elements(tmp_path, etype, behavior, law):
    """A deck's EXPONENTIAL (CalculiX's curve), TABULAR and node-to-face LINEAR (the arctan curve with its tension)
    on CPE4 and CAX4 elements: read without a word of refusal, each slave's overclosure the curve's d(Q) as in
    the problem-file case (1e-6 relative: the law per area of CalculiX's expanded faces is the law per area here)."""
    from covcontact.io.deck_import import import_deck

    deck = tmp_path / "laws.inp"
    deck.write_text(_deck(etype, behavior))
    imp = import_deck(deck, tmp_path / "imp" / "laws.toml")
    assert not imp.unsupported, imp.unsupported
    res = load_problem(imp.problem).run(out=tmp_path / "o", quiet=True)
    assert res.exit_code == 0
    st = res.state.contact.passes[0]
    np.testing.assert_allclose(-st.gap, overclosure(law), rtol=1e-6)
