"""The deck run's .dat beyond U, RF, S and PEEQ (docs/input.md, "Abaqus and CalculiX decks"): *EL PRINT E, ENER, ELSE,
EVOL (with TOTALS), *CONTACT PRINT CDIS, CSTR, CELS, CNUM (node-to-surface and surface-to-surface pairs) and *SECTION
PRINT SOF/SOM in CalculiX's layout, against closed forms (a uniaxially stretched St. Venant-Kirchhoff bar, a punch
pressed rigidly into a much stiffer base) and against CalculiX itself (its .dat of the same decks, where ``ccx`` is
installed: the layout character for character with the numbers masked, and the values)."""

from __future__ import annotations

import importlib.util
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from covcontact.cli import main

from test_deck import _block_nodes, _elements, _lines, two_block_deck

T1 = "  0.1000000E+01"   # the time as CalculiX prints it after " and time" (after "time" in contact headers: one space)
NU, YOUNG, STRETCH = 0.3, 1000.0, 0.4   # the bar 2 x 1 x 1 stretched to 2.4


def _bar_deck(path: Path) -> Path:
    """Two C3D8 along x (elements 1, 2; x in [0, 2]), symmetry planes x = 0, y = 0, z = 0, the end x = 2 pulled to
    2.4 in two equal increments, NLGEOM; prints E, ENER, ELSE (TOTALS=YES), EVOL (TOTALS=ONLY), the end's total
    force and the section between the elements (element 1's face S4, x = 1)."""
    lab, X, els = _block_nodes(2, 1, 1, 2.0, 1.0, 1.0, [0.0, 0.0, 0.0], 1)
    sets = {name: ", ".join(map(str, lab[np.isclose(X[:, axis], value)]))
            for name, axis, value in (("X0", 0, 0.0), ("Y0", 1, 0.0), ("Z0", 2, 0.0), ("XEND", 0, 2.0))}
    path.write_text(f"""*NODE, NSET=NALL
{_lines(lab, X)}
*ELEMENT, TYPE=C3D8, ELSET=EALL
{_elements(1, els)}
""" + "".join(f"*NSET, NSET={name}\n{v}\n" for name, v in sets.items()) + f"""*ELSET, ELSET=E1
1
*SURFACE, NAME=MID
E1, S4
*MATERIAL, NAME=M
*ELASTIC
{YOUNG}, {NU}
*SOLID SECTION, ELSET=EALL, MATERIAL=M
*BOUNDARY
X0, 1, 1
Y0, 2, 2
Z0, 3, 3
*STEP, NLGEOM
*STATIC, DIRECT
0.5, 1.0
*BOUNDARY
XEND, 1, 1, {STRETCH}
*EL PRINT, ELSET=EALL
S, E, ENER
*EL PRINT, ELSET=EALL, TOTALS=YES
ELSE
*EL PRINT, ELSET=EALL, TOTALS=ONLY
EVOL
*NODE PRINT, NSET=XEND, TOTALS=ONLY
RF
*SECTION PRINT, SURFACE=MID, NAME=SP1
SOF, SOM
*END STEP
""")
    return path


DELTA, K, SIGMA_INF = 1e-3, 1e4, 0.01   # the punch's press, the law's slope and tension


MU, STICK, SLIDE = 0.2, 1e5, 1e-5   # friction: Coulomb's coefficient, the stick slope, the punch's slide along x


def _punch_deck(path: Path, pair: str, slide: bool = False) -> Path:
    """two_block_deck's punch (elements 101-104, its bottom the slave surface of element faces S1) pressed rigidly by
    DELTA into a base 1e7 times stiffer (every punch node prescribed), the LINEAR law (K, sigma_inf, c0) in one
    increment; prints CDIS, CSTR, CELS (TOTALS=YES), CNUM. ``slide``: with friction (MU, STICK), the punch moved by
    SLIDE along x too (it sticks: STICK SLIDE < MU K DELTA)."""
    text = two_block_deck(path, pair=pair).read_text()
    if slide:
        text = text.replace("LINEAR\n1.0e6\n", f"LINEAR\n1.0e6\n*FRICTION\n{MU}, {STICK}\n").replace(
            "TOP, 1, 2\n", f"TOP, 1, 1, {SLIDE}\nTOP, 2, 2\n")
    for old, new in (("*Element, type=c3d8,\nELSET=PUNCH", "*ELEMENT, TYPE=C3D8, ELSET=PUNCH"),
                     ("*SURFACE, NAME=SSLAV, TYPE=NODE\nNSLAVE",
                      "*ELSET, ELSET=PUNCHBOT\n101, 102, 103, 104\n*SURFACE, NAME=SSLAV\nPUNCHBOT, S1\n"
                      "*NSET, NSET=PUNCHN, GENERATE\n1001, 1018, 1"),
                     ("*SOLID SECTION, ELSET=BASE, MATERIAL=STEEL",
                      "*MATERIAL, NAME=HARD\n*ELASTIC\n1.0e10, 0.3\n*SOLID SECTION, ELSET=BASE, MATERIAL=HARD"),
                     ("LINEAR\n1.0e6", f"LINEAR\n{K}, {SIGMA_INF}, 1e-3"),
                     ("*STATIC\n0.5, 1.0", "*STATIC, DIRECT\n1.0, 1.0"),
                     ("TOP, 1, 2\nTOP, 3, 3, -0.02", f"PUNCHN, 1, 2\nPUNCHN, 3, 3, -{DELTA}"),
                     (f"TOP, 1, 1, {SLIDE}\nTOP, 2, 2\nTOP, 3, 3, -0.02",
                      f"PUNCHN, 1, 1, {SLIDE}\nPUNCHN, 2, 2\nPUNCHN, 3, 3, -{DELTA}"),
                     ("*NODE PRINT, NSET=BOTTOM\nU, RF",
                      "*NODE PRINT, NSET=BOTTOM, TOTALS=ONLY\nRF\n*CONTACT PRINT, TOTALS=YES\nCDIS, CSTR, CELS, CNUM")):
        if old in text or not (slide ^ old.startswith("TOP, 1, 1")):
            assert old in text, old
            text = text.replace(old, new)
    path.write_text(text)
    return path


def _run(deck: Path, out: Path) -> str:
    assert main(["run", str(deck), "--out", str(out), "--quiet"]) == 0
    return (out / f"{deck.stem}.dat").read_text()


@pytest.fixture(scope="module")
def bar(tmp_path_factory):
    d = tmp_path_factory.mktemp("bar")
    deck = _bar_deck(d / "bar.inp")
    return deck, _run(deck, d / "out")


@pytest.fixture(scope="module")
def punch(tmp_path_factory):
    d = tmp_path_factory.mktemp("punch")
    deck = _punch_deck(d / "punch.inp", "NODE TO SURFACE")
    return deck, _run(deck, d / "out")


@pytest.fixture(scope="module")
def punch_slide(tmp_path_factory):
    d = tmp_path_factory.mktemp("punch_slide")
    deck = _punch_deck(d / "slide.inp", "NODE TO SURFACE", slide=True)
    return deck, _run(deck, d / "out")


@pytest.fixture(scope="module")
def punch_sts(tmp_path_factory):
    d = tmp_path_factory.mktemp("punch_sts")
    deck = _punch_deck(d / "punchs.inp", "SURFACE TO SURFACE")
    return deck, _run(deck, d / "out")


def _block(lines: list[str], header: str) -> np.ndarray:
    """The numbers of the rows under ``header`` (up to the next blank line)."""
    at = lines.index(header)
    rows = []
    for ln in lines[at + 2:]:
        if not ln.strip():
            break
        rows.append([float(v) for v in ln.split()])
    return np.array(rows)


def test_el_print_strain_energy_and_volume_of_a_stretched_bar(bar):
    """E is the Green-Lagrange strain with tensor shear: uniaxial stretch l gives E11 = (l^2 - 1)/2 and E22 = E33 =
    -nu E11 (St. Venant-Kirchhoff, free sides) at every Gauss point, no shear; ENER the energy density Young E11^2 / 2;
    ELSE that times the element's reference volume (with its total); EVOL (TOTALS=ONLY: the total alone) the reference
    volume, as CalculiX prints it also with NLGEOM; each block where the deck's cards put it."""
    lines = bar[1].splitlines()
    for time, l in (("  0.5000000E+00", 1.1), (T1, 1.2)):
        e11 = 0.5 * (l * l - 1.0)
        E = _block(lines, f" strains (elem, integ.pnt.,exx,eyy,ezz,exy,exz,eyz) for set EALL and time{time}")
        assert E[:, :2].tolist() == [[e, g] for e in (1, 2) for g in range(1, 9)]
        np.testing.assert_allclose(E[:, 2:], np.tile([e11, -NU * e11, -NU * e11, 0, 0, 0], (16, 1)), atol=1e-12)
        W = _block(lines, f" internal energy density (elem, integ.pnt.,energy) for set EALL and time{time}")
        np.testing.assert_allclose(W[:, 2], 0.5 * YOUNG * e11 ** 2, rtol=1e-10)
        el = _block(lines, f" internal energy (element, energy) for set EALL and time{time}")
        assert el[:, 0].tolist() == [1, 2]
        np.testing.assert_allclose(el[:, 1], 0.5 * YOUNG * e11 ** 2, rtol=1e-10)   # (reference volume 1 each)
        total = _block(lines, f" total internal energy for set EALL and time{time}")
        np.testing.assert_allclose(total[0, 0], YOUNG * e11 ** 2, rtol=1e-10)
        assert f" volume (element, volume) for set EALL and time{time}" not in lines   # (TOTALS=ONLY)
        assert _block(lines, f" total volume for set EALL and time{time}")[0, 0] == pytest.approx(2.0, rel=1e-12)
    heads = [ln for ln in lines if " for set " in ln and T1 in ln]
    assert [h.split(" for set")[0].split("(")[0].strip() for h in heads] == [
        "stresses", "strains", "internal energy density", "internal energy", "total internal energy", "total volume",
        "total force"]


def test_section_print_of_the_bar(bar):
    """SOF/SOM on the section between the elements (x = 1): the force the far half exerts, l Young E11 A0 (uniaxial
    St. Venant-Kirchhoff), equal to the pulled end's total force; about the origin the moment c x F; the deformed
    section's area (1 + 2 E22) A0, centre (1 + u, sqrt(1 + 2 E22) / 2, ...) and normal x; no shear, torque, bending."""
    lines = bar[1].splitlines()
    at = lines.index(f" statistics for surface set MID and time{T1}")
    assert lines[at - 3: at] == ["", "", ""]
    assert lines[at + 2] == "   total surface force (fx,fy,fz) and moment about the origin(mx,my,mz)"
    assert lines[at + 6] == "   center of gravity and mean normal"
    assert lines[at + 10] == "   moment about the center of gravity(mx,my,mz)"
    assert lines[at + 14] == ("   area, normal force (+ = tension), shear force (size), torque and bending moment "
                              "(size)")
    fm, cn, mcg, scal = (np.array([float(v) for v in lines[at + k].split()]) for k in (4, 8, 12, 16))
    e11 = 0.5 * (1.2 ** 2 - 1.0)
    lt = np.sqrt(1.0 - 2.0 * NU * e11)
    force = 1.2 * YOUNG * e11
    np.testing.assert_allclose(fm[:3], [force, 0.0, 0.0], atol=1e-9 * force)
    end = _block(lines, f" total force (fx,fy,fz) for set XEND and time{T1}")[0]
    assert fm[0] == pytest.approx(end[0], rel=1e-9)
    centre = np.array([1.2, 0.5 * lt, 0.5 * lt])
    np.testing.assert_allclose(cn, [*centre, 1.0, 0.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(fm[3:], np.cross(centre, fm[:3]), atol=1e-9 * force)
    np.testing.assert_allclose(mcg, 0.0, atol=1e-9 * force)
    np.testing.assert_allclose(scal, [lt * lt, force, 0.0, 0.0, 0.0], atol=1e-9 * force)


def test_contact_print_of_a_rigidly_pressed_punch(punch):
    """Node-to-surface, the punch's nine bottom nodes pressed by DELTA into a base 1e7 times stiffer: CNUM 9; CDIS the
    overclosure -DELTA (to the base's give), no tangential displacement (frictionless); CSTR the LINEAR law's pressure
    K d (1/2 + atan(d / e) / pi), e = pi sigma_inf / K, no shear; CELS each node's force times DELTA / 2, their total
    the pressure times the punch's area (1) times DELTA / 2; the headers CalculiX's (one space before its time)."""
    lines = punch[1].splitlines()
    cdis = _block(lines, " relative contact displacement (slave node,normal,tang1,tang2) for all contact elements and "
                         "time 0.1000000E+01")
    assert cdis[:, 0].astype(int).tolist() == list(range(1001, 1018, 2))
    np.testing.assert_allclose(cdis[:, 1], -DELTA, rtol=1e-5)
    assert np.all(cdis[:, 2:] == 0.0)
    e = np.pi * SIGMA_INF / K
    p = K * DELTA * (0.5 + np.arctan(DELTA / e) / np.pi)
    cstr = _block(lines, " contact stress (slave node,press,tang1,tang2) for all contact elements and time "
                         "0.1000000E+01")
    assert cstr[:, 0].tolist() == cdis[:, 0].tolist()
    np.testing.assert_allclose(cstr[:, 1], p, rtol=1e-5)
    assert np.abs(cstr[:, 2:]).max() < 1e-9 * p
    cels = _block(lines, " contact print energy (slave node,energy) forall contact elements and time 0.1000000E+01")
    areas = np.array([1, 2, 1, 2, 4, 2, 1, 2, 1]) / 16.0   # (the nodes' shares of the punch's 1 x 1 bottom)
    np.testing.assert_allclose(cels[:, 1], areas * p * DELTA / 2.0, rtol=1e-5)
    total = _block(lines, f" total contact spring energy for time{T1}")
    np.testing.assert_allclose(total[0, 0], p * DELTA / 2.0, rtol=1e-5)
    assert _block(lines, f" total number of contact elements for time{T1}")[0, 0] == 9
    reaction = _block(lines, f" total force (fx,fy,fz) for set BOTTOM and time{T1}")[0]
    assert reaction[2] == pytest.approx(p, rel=1e-5)   # (the pressures sum to the support's reaction)


def test_contact_print_with_sticking_friction(punch_slide):
    """The punch pressed and slid by SLIDE along x with friction, sticking (STICK SLIDE < MU p): CDIS's tangential
    displacement the slide along tang1 (CalculiX's first tangential axis of the normal z: x), CSTR's shear stress
    STICK SLIDE along the slide (CalculiX's sign), CELS the normal part plus the stick spring's (STICK SLIDE)^2 area /
    (2 STICK)."""
    lines = punch_slide[1].splitlines()
    cdis = _block(lines, " relative contact displacement (slave node,normal,tang1,tang2) for all contact elements and "
                         "time 0.1000000E+01")
    # (to the stiff base's give, 1e-5 of the slide)
    np.testing.assert_allclose(cdis[:, 1:], np.tile([-DELTA, SLIDE, 0.0], (9, 1)), rtol=5e-5, atol=1e-4 * SLIDE)
    e = np.pi * SIGMA_INF / K
    p = K * DELTA * (0.5 + np.arctan(DELTA / e) / np.pi)
    cstr = _block(lines, " contact stress (slave node,press,tang1,tang2) for all contact elements and time "
                         "0.1000000E+01")
    np.testing.assert_allclose(cstr[:, 1:], np.tile([p, STICK * SLIDE, 0.0], (9, 1)), rtol=5e-5, atol=1e-6 * p)
    cels = _block(lines, " contact print energy (slave node,energy) forall contact elements and time 0.1000000E+01")
    areas = np.array([1, 2, 1, 2, 4, 2, 1, 2, 1]) / 16.0
    np.testing.assert_allclose(cels[:, 1], areas * (p * DELTA + STICK * SLIDE ** 2) / 2.0, rtol=1e-5)


def test_contact_print_surface_to_surface(punch_sts):
    """Surface-to-surface: the slave faces' Gauss points are the slaves, labelled by their element and face (2 x 2 on
    each of the four faces S1: CNUM 16), the linear face-to-face law's pressure K DELTA, energy (weight) K DELTA^2 / 2
    summing to K DELTA^2 A / 2."""
    lines = punch_sts[1].splitlines()
    assert not any("(slave node," in ln for ln in lines)
    cdis = _block(lines, " relative contact displacement (slave element+face,normal,tang1,tang2) for all contact "
                         "elements and time 0.1000000E+01")
    assert cdis[:, :2].astype(int).tolist() == [[e, 1] for e in (101, 102, 103, 104) for _ in range(4)]
    np.testing.assert_allclose(cdis[:, 2], -DELTA, rtol=1e-5)
    cstr = _block(lines, " contact stress (slave element+face,press,tang1,tang2) for all contact elements and time "
                         "0.1000000E+01")
    np.testing.assert_allclose(cstr[:, 2], K * DELTA, rtol=1e-5)
    cels = _block(lines, " contact print energy (slave element+face,energy)for all contact elements and time "
                         "0.1000000E+01")
    np.testing.assert_allclose(cels[:, 2], K * DELTA ** 2 / 2.0 / 16.0, rtol=1e-5)   # (each point's weight 1/16)
    assert _block(lines, f" total number of contact elements for time{T1}")[0, 0] == 16


def _survey():
    """benchmarks/ccx_decks.py (its .dat parser and comparison)."""
    path = Path(__file__).resolve().parents[2] / "benchmarks" / "ccx_decks.py"
    spec = importlib.util.spec_from_file_location("ccx_decks", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _mask(text: str, faces: bool = False) -> str:
    """The .dat with every number replaced by a mark of its width (the sign's column kept blank or minus alike);
    ``faces``: each slave face's rows once and CNUM's count masked (each code's own integration points)."""
    text = re.sub(r"[ -]\d\.\d{6}E[-+]\d\d", " #.######E+##", text)
    if faces:
        text = re.sub(r"(\n( +\d+ +\d+(?: +#\.######E\+##)+\n))\2+", r"\1", text)
        text = re.sub(r"(total number of contact elements for time .*\n\n) +\d+\n", r"\1#\n", text)
    return text


@pytest.mark.skipif(shutil.which("ccx") is None, reason="CalculiX (ccx) is not installed")
def test_against_calculix(bar, punch, punch_slide, punch_sts, tmp_path):
    """CalculiX runs the same decks: its .dat has the same lines (headers, blank lines, columns; numbers masked; the
    surface-to-surface rows of a face taken once, as the codes' integration points differ) and the same values: the
    bar's S, E, ENER, ELSE, EVOL to 1e-6, its section force and moment to 1e-3 (CalculiX integrates its stresses
    extrapolated to the nodes over the face), the node-to-surface punch's CDIS, CSTR, CELS, CNUM to 1e-4, the sliding
    one's tangential displacements and shear stresses (signs and axes) to 1e-6 and its CELS but for the stick spring's
    energy, which CalculiX 2.20 prints twice over (its source halves it: covcontact prints the spring's energy); the
    surface-to-surface punch's clearance, pressure and energy per slave face to 1e-6 (CalculiX's 112 integration points
    against covcontact's 16: CNUM differs)."""
    survey = _survey()
    contact = {"contact": 1e-4, "clearance": 1e-4, "contact energy": 1e-4, "total contact energy": 1e-4,
               "contact elements": 0.0}
    for (deck, ours), tol in ((bar, {"stresses": 1e-6, "strains": 1e-6, "energy density": 1e-6, "internal energy": 1e-6,
                                     "total internal energy": 1e-6, "total volume": 1e-12, "section force": 1e-3,
                                     "section moment": 1e-3, "section area": 1e-9, "section centre": 1e-9}),
                              (punch, contact),
                              (punch_slide, {"contact": 1e-6, "clearance": 1e-6, "tangential": 1e-6, "slip": 1e-6,
                                             "contact elements": 0.0}),
                              (punch_sts, {"contact": 1e-6, "clearance": 1e-6, "contact energy": 1e-6,
                                           "total contact energy": 1e-6})):
        work = tmp_path / deck.stem
        work.mkdir()
        shutil.copy(deck, work / deck.name)
        proc = subprocess.run(["ccx", "-i", deck.stem], cwd=work, capture_output=True, text=True, timeout=300)
        assert proc.returncode == 0, proc.stdout[-2000:]
        theirs = (work / f"{deck.stem}.dat").read_text()
        assert _mask(ours, deck is punch_sts[0]) == _mask(theirs, deck is punch_sts[0])
        rows = {r["kind"]: r for r in survey.compare(ours, theirs) if r["time"] == 1.0}
        for kind, limit in tol.items():
            assert kind in rows, (kind, sorted(rows))
            assert rows[kind]["rel_diff"] <= limit, rows[kind]
        if deck is punch_slide[0]:
            a, b = survey.dat_blocks(ours), survey.dat_blocks(theirs)
            key = ("contact energy", "ALL", 1.0)
            areas = np.array([1, 2, 1, 2, 4, 2, 1, 2, 1]) / 16.0
            twice = np.array([b[key][n][0] - a[key][n][0] for n in range(1001, 1018, 2)])
            np.testing.assert_allclose(twice, areas * STICK * SLIDE ** 2 / 2.0, rtol=1e-3)


def test_print_cards_read_as_calculix_reads_them(tmp_path):
    """*SECTION PRINT and *CONTACT PRINT requests carry over to a step without their own card (as the others do), a
    step's first card replaces them; contact variables are read by their first four letters (CDISP, CSTRESS), section
    variables SOF, SOM, SOAREA; what is not tabulated is a note; *SECTION PRINT needs NAME=; TOTALS must be NO, YES or
    ONLY. The labels file carries each request's place among the cards and the surfaces' faces."""
    import json

    from covcontact.io.deck import DeckError
    from covcontact.io.deck_import import import_deck
    from covcontact.io.deck_model import read_model

    text = _bar_deck(tmp_path / "bar.inp").read_text()
    step2 = ("*STEP, NLGEOM\n*STATIC\n0.5, 1.0\n*CONTACT PRINT\nCSTRESS, CFN\n*END STEP\n"
             "*STEP, NLGEOM\n*STATIC\n0.5, 1.0\n*SECTION PRINT, SURFACE=MID, NAME=SP2\nSOAREA, DRAG\n*END STEP\n")
    deck = tmp_path / "two.inp"
    deck.write_text(text.replace("SOF, SOM\n*END STEP\n", "SOF, SOM\n*CONTACT PRINT, TOTALS=YES\nCDISP, CELS\n"
                                 "*END STEP\n" + step2))
    m = read_model(deck)
    assert [[s[:3] for s in st.section_print] for st in m.steps] == [
        [("MID", "SP1", ("SOF", "SOM"))], [("MID", "SP1", ("SOF", "SOM"))], [("MID", "SP2", ("SOAREA", "DRAG"))]]
    assert [st.contact_print for st in m.steps] == [("CDISP", "CELS"), ("CSTRESS", "CFN"), ("CSTRESS", "CFN")]
    assert [st.contact_card[1] for st in m.steps] == ["YES", "NO", "NO"]
    notes = [n.split(": ", 1)[1] for n in m.notes if "not printed in the .dat" in n]
    assert notes == ["*CONTACT PRINT CFN: not printed in the .dat (covcontact tabulates CSTR, CDIS, CELS, CNUM there)",
                     "*SECTION PRINT DRAG: not printed in the .dat (covcontact tabulates SOF, SOM, SOAREA there)"]
    imp = import_deck(deck, tmp_path / "d" / "two.toml")
    info = json.loads(imp.labels.read_text())
    assert info["surfaces"] == {"MID": [[1, 4]]}
    orders = [[p[3] for p in info["el_print"][0]], [p[3] for p in info["node_print"][0]],
              [p[3] for p in info["section_print"][0]], info["contact_card"][0][1]]
    assert orders == [[1, 2, 3], [4], [5], 6]   # (the deck's order of the step's cards)
    for bad, match in (("NAME=SP1", "missing parameter NAME="), ("TOTALS=ONLY\nRF", "TOTALS must be NO, YES or ONLY")):
        deck.write_text(text.replace(bad, "TOTALS=ALL\nRF" if "TOTALS" in bad else "X=1"))
        with pytest.raises(DeckError, match=match):
            read_model(deck)
