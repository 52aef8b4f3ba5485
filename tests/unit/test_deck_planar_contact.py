"""*CONTACT PAIR of planar deck elements (CPE, CPS, CAX) as node-to-segment contact in the plane
(covcontact.io.deck_planar.planar_contact; docs/input.md, "Abaqus and CalculiX decks"): two blocks pressed together,
written here, against the closed form and against CalculiX's own numbers, and the pairs contact in the plane cannot
take (one line each, exit 2).

The stored CalculiX figures were produced by CalculiX 2.20 (``ccx -i DECK``) on exactly the decks ``_deck`` writes
(NLGEOM, the default arguments and the ones each test passes): its .dat at time 1."""

from __future__ import annotations

import re
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

E, P, K, H = 210000.0, 100.0, 1.0e6, 0.5

#: CalculiX 2.20, NLGEOM, the CPE4 deck (thickness 0.5) and the CAX4 deck (x0 = 1), face-to-face LINEAR K = 1e6:
#: u_y at time 1 (the same for both: nu = 0, the strain uniaxial) and the reactions of the base nodes 1, 2, 3 (CAX4:
#: those of CalculiX's 2 degree segment)
_CCX_UY = {4: -2.382655e-04, 11: -3.382655e-04, 14: -5.765310e-04}
_CCX_RF = {"CPE4": {1: 12.5, 2: 25.0, 3: 12.5}, "CAX4": {1: 1.017902, 2: 2.617462, 3: 1.599560}}


def _cli(*args) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "covcontact.cli", *map(str, args)], capture_output=True, text=True,
                          timeout=900)


def _deck(etype: str = "CPE4", kind: str = "SURFACE TO SURFACE", law: str = f"LINEAR\n{K!r}", t: float = 0.5,
          x0: float = 0.0, extra: str = "", pair: str = "", bottom: str | None = None, more: str = "") -> str:
    """Two blocks of 2 x 1 cells, [x0, x0 + 1] x [0, H] (nodes 1-6, elements 1, 2) and [x0, x0 + 1] x [H, 2 H] (nodes
    11-16, elements 11, 12), E = 210000, nu = 0 (uniaxial strain in y), the base held in y (and the left nodes in x
    when not axisymmetric), the pressure P on the top (P3 of the upper cells); the upper block's bottom (S1) is the slave
    surface on the lower block's top (S3)."""
    xs = [x0, x0 + 0.5, x0 + 1.0]
    nodes = [(b + 1 + i + 3 * j, x, y0 + H * j) for b, y0 in ((0, 0.0), (10, H)) for j in range(2)
             for i, x in enumerate(xs)]
    text = "*HEADING\ntwo blocks\n*NODE, NSET=NALL\n" + "".join(f"{n}, {x!r}, {y!r}, 0.\n" for n, x, y in nodes)
    text += f"*ELEMENT, TYPE={bottom or etype}, ELSET=LOW\n1, 1, 2, 5, 4\n2, 2, 3, 6, 5\n"
    text += f"*ELEMENT, TYPE={etype}, ELSET=UP\n11, 11, 12, 15, 14\n12, 12, 13, 16, 15\n" + more
    text += "*ELSET, ELSET=EALL\nLOW, UP\n*NSET, NSET=BASE\n1, 2, 3\n*NSET, NSET=LEFT\n1, 4, 11, 14\n"
    text += "*SURFACE, NAME=SLAVE\nUP, S1\n*SURFACE, NAME=MASTER\nLOW, S3\n"
    text += f"*MATERIAL, NAME=STEEL\n*ELASTIC\n{E}, 0.\n*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL\n{t}\n"
    text += f"*SURFACE INTERACTION, NAME=I1\n*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE={law}\n{extra}"
    text += pair or f"*CONTACT PAIR, INTERACTION=I1, TYPE={kind}\nSLAVE, MASTER\n"
    text += "*BOUNDARY\nBASE, 2\n" + ("LEFT, 1\n" if etype[:3] != "CAX" else "")
    return text + (f"*STEP, NLGEOM\n*STATIC\n0.5, 1.\n*DLOAD\nUP, P3, {P}\n*NODE PRINT, NSET=NALL, TOTALS=YES\nU, RF\n"
                   "*END STEP\n")


def _last(dat: Path, kind: str) -> dict[int, np.ndarray]:
    """The last block of ``kind`` ("displacements", "forces") of a .dat: label -> row."""
    out, cur = [], None
    for line in dat.read_text().splitlines():
        if re.match(r"\s*(displacements|forces|total)", line):
            cur = {} if line.split()[0] == kind else None
            if cur is not None:
                out.append(cur)
        elif cur is not None and len(line.split()) == 4:
            f = line.split()
            cur[int(f[0])] = np.array([float(v) for v in f[1:]])
    return out[-1]


def _stretch() -> float:
    """The stretch of a St. Venant-Kirchhoff column with nu = 0 under the dead pressure P: lam E (lam^2 - 1) / 2 = -P."""
    return brentq(lambda lam: lam * E * (lam * lam - 1.0) / 2.0 + P, 0.5, 1.5, xtol=1e-15)


def _run(text: str, tmp_path: Path, *flags) -> tuple[Path, subprocess.CompletedProcess]:
    deck = tmp_path / "blocks.inp"
    deck.write_text(text)
    proc = _cli("run", deck, "--out", tmp_path / "o", "--quiet", *flags)
    return tmp_path / "o" / "blocks.dat", proc


@pytest.mark.parametrize("etype, x0", [("CPE4", 0.0), ("CAX4", 1.0)])
def test_face_to_face_linear_penalty_is_calculix_law(tmp_path, etype, x0):
    """TYPE=SURFACE TO SURFACE, LINEAR K: segment-to-segment contact in the plane (the Gauss points of the slave
    edges, K per area), read without a word. The overclosure is P / K (CalculiX's K per area of its expanded face:
    per the thickness 0.5 of the CPE4 block, per 2 pi R of the CAX4 ring, the same at every radius), the blocks the
    uniaxial closed form; both equal CalculiX's .dat to its 7 digits. The base's reaction is P times the area: the
    thickness's (CPE4) or pi (R2^2 - R1^2) / 180, the .dat's 2 degree segment (CAX4; CalculiX's own is 2e-4 lower,
    its expanded segment's)."""
    text = _deck(etype, x0=x0)
    dat, proc = _run(text, tmp_path)
    assert proc.returncode == 0, proc.stderr
    entry = tomllib.loads((tmp_path / "o" / "deck" / "blocks.toml").read_text())["contact"][0]
    assert entry["penalty"] == K and entry["type"] == "sts"
    U, RF = _last(dat, "displacements"), _last(dat, "forces")
    d = (_stretch() - 1.0) * H
    expect = {1: 0.0, 2: 0.0, 3: 0.0, 4: d, 5: d, 6: d, 11: d - P / K, 12: d - P / K, 13: d - P / K,
              14: 2 * d - P / K, 15: 2 * d - P / K, 16: 2 * d - P / K}
    for n, uy in expect.items():
        assert U[n][1] == pytest.approx(uy, abs=1e-10), n  # (the .dat's 7 digits)
        assert abs(U[n][0]) < 1e-12
    for n, uy in _CCX_UY.items():
        assert U[n][1] == pytest.approx(uy, abs=1e-10)
    area = 1.0 * 0.5 if etype == "CPE4" else np.pi * (2.0 ** 2 - 1.0 ** 2) / 180.0
    assert sum(RF[n][1] for n in (1, 2, 3)) == pytest.approx(P * area, rel=1e-6)
    for n, f in _CCX_RF[etype].items():
        assert RF[n][1] == pytest.approx(f, rel=5e-4 if etype == "CAX4" else 1e-6)


def test_hard_node_to_surface_is_augmented_contact(tmp_path):
    """NODE TO SURFACE, HARD on element surfaces of CAX4 rings: mapped without a note (augmented Lagrange, the
    automatic penalty per area); the overclosure stays within the augmented tolerance (1e-3 of the master's edge) and
    the rest is the closed form; the base's reaction that of the pressure over the .dat's 2 degree segment."""
    dat, proc = _run(_deck("CAX4", kind="NODE TO SURFACE", law="HARD", x0=1.0), tmp_path)
    assert proc.returncode == 0, proc.stderr
    entry = tomllib.loads((tmp_path / "o" / "deck" / "blocks.toml").read_text())["contact"][0]
    assert (entry["penalty"], entry["method"], entry["weighting"]) == ("auto", "augmented", "area")
    U, RF = _last(dat, "displacements"), _last(dat, "forces")
    d = (_stretch() - 1.0) * H
    for n in (4, 5, 6):
        assert U[n][1] == pytest.approx(d, abs=1e-10)
        assert 0.0 <= U[n][1] - U[n + 7][1] <= 1e-3 * 0.5
        assert U[n + 10][1] - U[n + 7][1] == pytest.approx(d, abs=2e-10)
    assert sum(RF[n][1] for n in (1, 2, 3)) == pytest.approx(P * np.pi * 3.0 / 180.0, rel=1e-6)


_HEX = ("*NODE\n101, 5., 0., 0.\n102, 6., 0., 0.\n103, 6., 1., 0.\n104, 5., 1., 0.\n105, 5., 0., 1.\n106, 6., 0., 1.\n"
        "107, 6., 1., 1.\n108, 5., 1., 1.\n*ELEMENT, TYPE=C3D8, ELSET=HEX\n101, 101, 102, 103, 104, 105, 106, 107, 108\n"
        "*SOLID SECTION, ELSET=HEX, MATERIAL=STEEL\n*SURFACE, NAME=HEXS\nHEX, S1\n")


@pytest.mark.parametrize("kw, message", [
    ({"pair": "*SURFACE, NAME=NS, TYPE=NODE\n11\n12\n13\n*TIE, NAME=T\nNS, MASTER\n"},
     r"\*TIE with a node surface \(TYPE=NODE\) as the slave on CPE4 elements: a tie in the plane weights its slave "
     r"nodes by their edges"),
    ({"law": "HARD", "kind": "NODE TO SURFACE",
      "pair": "*SURFACE, NAME=NS, TYPE=NODE\n11\n12\n13\n*CONTACT PAIR, INTERACTION=I1, TYPE=NODE TO SURFACE\nNS, MASTER\n"},
     r"a node surface \(TYPE=NODE\) as the slave of a pair on CPE4 elements"),
    ({"law": "HARD", "kind": "NODE TO SURFACE", "bottom": "CPS4"},
     r"\*CONTACT PAIR between CPE4 \(plane_strain, body \w+\) and CPS4 \(plane_stress, body \w+\) elements: contact "
     r"in the plane joins bodies of one formulation"),
    ({"law": "HARD", "kind": "NODE TO SURFACE", "more": _HEX,
      "pair": "*CONTACT PAIR, INTERACTION=I1, TYPE=NODE TO SURFACE\nSLAVE, HEXS\n"},
     r"\*CONTACT PAIR between planar CPE4 elements \(body \w+\) and 3D elements \(body \w+\): contact in the plane "
     r"joins planar bodies only"),
    ({"law": "HARD", "pair": "*CONTACT PAIR, INTERACTION=I1, TYPE=NODE TO SURFACE, ADJUST=0.01\nSLAVE, MASTER\n"},
     r"ADJUST on CPE4 elements: not available in the plane"),
])
def test_what_contact_in_the_plane_lacks_is_listed(tmp_path, kw, message):
    """A tie of a node surface, node surfaces as slaves, two formulations, planar with 3D elements, ADJUST: one line each, listed as unsupported
    (exit 2 without --ignore-unsupported)."""
    _, proc = _run(_deck(**kw), tmp_path)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr
    lines = [ln for ln in proc.stderr.splitlines() if re.search(message, ln)]
    assert len(lines) == 1 and lines[0].startswith("covcontact: unsupported: "), proc.stderr


def test_friction_on_a_body_s_edges(tmp_path):
    """*FRICTION on a NODE TO SURFACE pair of CPE4 blocks: Coulomb friction along the master edges (mu and the stick
    slope as the tangential penalty per area, as in 3D). Pressed along y with nu = 0 nothing slides: the blocks take
    the uniaxial closed form, as without friction."""
    dat, proc = _run(_deck("CPE4", kind="NODE TO SURFACE", law="HARD", extra="*FRICTION\n0.2, 1.e6\n"), tmp_path)
    assert proc.returncode == 0, proc.stderr
    entry = tomllib.loads((tmp_path / "o" / "deck" / "blocks.toml").read_text())["contact"][0]
    assert (entry["friction"], entry["tangential_penalty"], entry["method"]) == (0.2, 1.0e6, "augmented")
    U = _last(dat, "displacements")
    d = (_stretch() - 1.0) * H
    for n in (4, 5, 6):
        assert U[n][1] == pytest.approx(d, abs=1e-10)
        assert U[n + 10][1] - U[n + 7][1] == pytest.approx(d, abs=2e-10)
        assert abs(U[n + 7][0] - U[n][0]) < 1e-12


@pytest.mark.parametrize("etype, x0", [("CPE4", 0.0), ("CAX4", 1.0)])
def test_tie_is_a_tied_pair_in_the_plane(tmp_path, etype, x0):
    """*TIE of the upper block's bottom to the lower block's top, the top pulled (P3 = -P): a tied pair in the plane
    with the automatic tie penalty 100 E / h per area (h = 0.5, the edges' length); CalculiX writes equations (no
    opening), here the tie opens by P h / (100 E) and carries the tension; the blocks stretch as the uniaxial closed
    form (nu = 0) says, each by d."""
    text = _deck(etype, x0=x0, pair="*TIE, NAME=T\nSLAVE, MASTER\n").replace(f"UP, P3, {P}", f"UP, P3, {-P}")
    dat, proc = _run(text, tmp_path)
    assert proc.returncode == 0, proc.stderr
    entry = tomllib.loads((tmp_path / "o" / "deck" / "blocks.toml").read_text())["contact"][0]
    assert (entry["law"], entry["penalty"], entry["weighting"]) == ("tied", "auto", "area")
    U = _last(dat, "displacements")
    lam = brentq(lambda s: s * E * (s * s - 1.0) / 2.0 - P, 0.5, 1.5, xtol=1e-15)
    d, opening = (lam - 1.0) * H, P * 0.5 / (100.0 * E)
    for n in (4, 5, 6):
        assert U[n][1] == pytest.approx(d, abs=1e-10)
        assert U[n + 7][1] - U[n][1] == pytest.approx(opening, abs=2e-10)
        assert U[n + 10][1] - U[n + 7][1] == pytest.approx(d, abs=2e-10)


def test_contact_print_of_face_to_face_planar_pairs_is_said_not_left_empty(tmp_path):
    """*CONTACT PRINT on a deck whose planar pair is face-to-face (CalculiX prints its expanded faces' points, which
    contact in the plane does not have): the .dat has no table of it, and the run says so in a note naming the card and
    the pair (the VTU has their gap and pressure), instead of printing nothing."""
    text = _deck("CPE4").replace("*END STEP\n", "*CONTACT PRINT\nCSTR, CDIS\n*END STEP\n")
    dat, proc = _run(text, tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert re.search(r"blocks\.inp:\d+: \*CONTACT PRINT: the pairs on planar elements \(pair1: face-to-face",
                     proc.stderr), proc.stderr


def _contact_tables(dat: Path) -> dict[str, dict[int, list[float]]]:
    """The last contact stress, relative displacement and energy tables of a .dat, and its total energy."""
    out, cur = {}, None
    for line in dat.read_text().splitlines():
        head = re.match(r"\s*(contact stress|relative contact displacement|contact print energy|total contact spring)",
                        line)
        if head:
            cur = out[head.group(1)] = {}
        elif line.split() and not re.match(r"\s*[-\d]", line):
            cur = None
        elif cur is not None and line.split():
            f = line.split()
            cur[int(f[0]) if len(f) > 1 else 0] = [float(v) for v in f[1:] or f]
    return out


#: CalculiX 2.20 (``ccx -i``) on _deck(etype, "NODE TO SURFACE", x0) with "*CONTACT PRINT, TOTALS=YES / CSTR, CDIS,
#: CELS": its slave rows at time 1, under the labels of its expanded nodes (the deck's largest label 16 + 3 j + 1 and
#: + 3, j the slave's place among the planar elements' nodes in label order: 11 -> 35, 37; 12 -> 38, 40; 13 -> 41, 43)
_CCX_CONTACT = {"CPE4": {"press": {35: 100.0, 38: 100.0, 41: 100.0}, "gap": {35: -1.029917e-04, 38: -1.029917e-04},
                         "energy": {35: 3.218490e-04, 38: 6.436979e-04, 41: 3.218490e-04}, "total": 2.574792e-03},
                "CAX4": {"press": {35: 93.45488, 38: 99.94163, 41: 104.7762},
                         "energy": {35: 2.457490e-05, 38: 6.731658e-05, 41: 4.310142e-05}, "total": 2.699858e-04}}


@pytest.mark.parametrize("etype, x0", [("CPE4", 0.0), ("CAX4", 1.0)])
def test_contact_print_of_planar_pairs_as_calculix_prints_its_expansion(tmp_path, etype, x0):
    """Node-to-surface pairs on linear planar edges tabulated as CalculiX tabulates its expanded model: each slave
    node's two face nodes under CalculiX's labels, the 2D node's gap, pressure and half its energy (CAX4: of the 2
    degree segment). CPE4 equals CalculiX's .dat to its 7 digits. CAX4: the pressure is 100 at every slave (a uniform
    load, covcontact's consistent edge weights), where CalculiX's expanded wedge gives 93.5 .. 104.8 (its gaps vary
    likewise); the energies agree within 7 % at the ends (as the pressures differ), 0.3 % in the middle and 0.2 % in
    total."""
    text = _deck(etype, kind="NODE TO SURFACE", x0=x0).replace(
        "*END STEP\n", "*CONTACT PRINT, TOTALS=YES\nCSTR, CDIS, CELS\n*END STEP\n")
    dat, proc = _run(text, tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert "*CONTACT PRINT" not in proc.stderr
    tables = _contact_tables(dat)
    press, gap = tables["contact stress"], tables["relative contact displacement"]
    energy, total = tables["contact print energy"], tables["total contact spring"][0][0]
    assert sorted(press) == sorted(gap) == sorted(energy) == [35, 37, 38, 40, 41, 43]
    ref = _CCX_CONTACT[etype]
    for lab in press:
        assert press[lab][1:] == [0.0, 0.0] and gap[lab][1:] == [0.0, 0.0]
        assert energy[lab] == energy[lab + 2 if lab in (35, 38, 41) else lab - 2]
    if etype == "CPE4":
        for lab in press:
            assert press[lab][0] == pytest.approx(100.0, rel=1e-6)
            assert gap[lab][0] == pytest.approx(-1.029917e-04, rel=1e-6)
            assert energy[lab][0] == pytest.approx(ref["energy"][lab - (lab - 35) % 3], rel=1e-6)
        assert total == pytest.approx(ref["total"], rel=1e-6)
    else:
        for lab, p in ref["press"].items():
            assert press[lab][0] == pytest.approx(100.0, rel=1e-6)
            assert abs(p / 100.0 - 1.0) < 0.07
            assert energy[lab][0] == pytest.approx(ref["energy"][lab], rel=0.08)
        assert energy[38][0] == pytest.approx(ref["energy"][38], rel=3e-3)
        assert total == pytest.approx(ref["total"], rel=2e-3)

#: CalculiX 2.20 (``ccx -i``) on the frictional deck of the test below, at time 1.25 (a quarter into the sliding
#: step; CalculiX's own run diverges later in that step): per slave row (pressure, shear t1, gap, slip t1)
_CCX_FRICTION = {35: (60.32215, 12.06443, -6.330027e-05, 2.293813e-04),
                 38: (102.0288, 20.40576, -1.050208e-04, 7.156238e-05),
                 41: (135.6159, 22.33596, -1.386113e-04, 2.233596e-05)}


def test_contact_print_of_a_sliding_planar_pair_against_calculix(tmp_path):
    """The CPE4 node-to-surface deck with *FRICTION (mu 0.2, stick slope 1e6), the upper block's top pushed sideways
    by 0.002 in a second step (DIRECT, 4 increments): at time 1.25 the slave rows' pressure, shear, gap and slip equal
    CalculiX's to 1e-3 of each column's largest value (measured 2e-4): nodes 35 and 38 slip (shear = 0.2 pressure),
    node 41 sticks. (The energies differ by the stick spring's, which CalculiX 2.20 prints twice: docs/input.md.)"""
    text = _deck("CPE4", kind="NODE TO SURFACE", extra="*FRICTION\n0.2, 1e6\n")
    text = text.replace("*NSET, NSET=LEFT\n1, 4, 11, 14\n", "*NSET, NSET=LEFT\n1, 4\n*NSET, NSET=TOPN\n14, 15, 16\n")
    text = text.replace("*STATIC\n0.5, 1.\n", "*STATIC, DIRECT\n0.25, 1.\n")
    text = text.replace("*END STEP\n", "*CONTACT PRINT\nCSTR, CDIS\n*END STEP\n*STEP, NLGEOM\n*STATIC, DIRECT\n0.25, 1.\n"
                        "*BOUNDARY\nTOPN, 1, 1, 0.002\n*CONTACT PRINT\nCSTR, CDIS\n*END STEP\n")
    dat, proc = _run(text, tmp_path)
    assert proc.returncode == 0, proc.stderr
    blocks: dict = {}
    cur = None
    for line in dat.read_text().splitlines():
        head = re.match(r"\s*(contact stress|relative contact displacement).*time\s+(\S+)", line)
        if head:
            cur = blocks.setdefault(float(head.group(2)), {}).setdefault(head.group(1), {}) if \
                abs(float(head.group(2)) - 1.25) < 1e-9 else None
        elif cur is not None and len(line.split()) == 4:
            f = line.split()
            cur[int(f[0])] = [float(v) for v in f[1:]]
    press, gap = blocks[1.25]["contact stress"], blocks[1.25]["relative contact displacement"]
    ref = np.array([_CCX_FRICTION[k] for k in sorted(_CCX_FRICTION)])
    got = np.array([[press[k][0], press[k][1], gap[k][0], gap[k][1]] for k in sorted(_CCX_FRICTION)])
    assert np.all(np.abs(got - ref) <= 1e-3 * np.abs(ref).max(axis=0)), got - ref
    assert press[35][1] == pytest.approx(0.2 * press[35][0], rel=1e-6) and press[41][1] < 0.2 * press[41][0]
