"""Plane strain (CPE), plane stress (CPS) and axisymmetric (CAX) elements in CalculiX/Abaqus decks
(covcontact.io.deck_planar; docs/input.md, "Abaqus and CalculiX decks"): small decks written here run by
``covcontact run DECK.inp`` and ``covcontact import``, their .dat U and RF against closed forms, and the one-line
refusals."""

from __future__ import annotations

import re
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

E, NU = 210000.0, 0.3


def _cli(*args, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "covcontact.cli", *map(str, args)], capture_output=True, text=True,
                          timeout=900, cwd=cwd)


def _run(deck: Path, tmp_path: Path) -> Path:
    proc = _cli("run", deck, "--out", tmp_path / "o", "--quiet")
    assert proc.returncode == 0, proc.stderr
    return tmp_path / "o" / f"{deck.stem}.dat"


def _blocks(dat: Path) -> list[tuple[str, float, dict[int, np.ndarray]]]:
    """(kind "displacements" | "forces" | "total", time, label -> row) of every block of a .dat."""
    out, cur = [], None
    for line in dat.read_text().splitlines():
        head = re.match(r"\s*(displacements|forces|total force)\b.*time\s+(\S+)", line)
        if head:
            cur = {}
            out.append((head.group(1).split()[0], float(head.group(2)), cur))
        elif cur is not None and line.strip():
            f = line.split()
            if head is None and len(f) == 4:
                cur[int(f[0])] = np.array([float(v) for v in f[1:]])
            elif len(f) == 3:
                cur[0] = np.array([float(v) for v in f])
    return out


def _last(dat: Path, kind: str) -> dict[int, np.ndarray]:
    return [b for k, _, b in _blocks(dat) if k == kind][-1]


def _grid(nx: int, ny: int, lx: float, ly: float, x0: float = 0.0, quadratic: bool = False):
    """Nodes (label, x, y) and counter-clockwise elements of an nx x ny grid of quad4 or quad8 cells."""
    if not quadratic:
        lab = lambda i, j: 1 + i + j * (nx + 1)  # noqa: E731
        nodes = [(lab(i, j), x0 + lx * i / nx, ly * j / ny) for j in range(ny + 1) for i in range(nx + 1)]
        els = [(1 + i + j * nx, lab(i, j), lab(i + 1, j), lab(i + 1, j + 1), lab(i, j + 1))
               for j in range(ny) for i in range(nx)]
        return nodes, els
    m = 2 * nx + 1
    lab = lambda i, j: 1 + i + j * m  # noqa: E731  (i, j on the half-step grid; centres left out)
    nodes = [(lab(i, j), x0 + lx * i / (2 * nx), ly * j / (2 * ny)) for j in range(2 * ny + 1) for i in range(m)
             if not (i % 2 and j % 2)]
    els = []
    for j in range(ny):
        for i in range(nx):
            a, b = 2 * i, 2 * j
            els.append((1 + i + j * nx, lab(a, b), lab(a + 2, b), lab(a + 2, b + 2), lab(a, b + 2), lab(a + 1, b),
                        lab(a + 2, b + 1), lab(a + 1, b + 2), lab(a, b + 1)))
    return nodes, els


def _deck(etype: str, nodes, els, section: str, body: str, step: str, nlgeom: bool = True) -> str:
    text = "*HEADING\nplanar deck\n*NODE, NSET=NALL\n" + "".join(f"{n}, {x!r}, {y!r}, 0.\n" for n, x, y in nodes)
    text += f"*ELEMENT, TYPE={etype}, ELSET=EALL\n" + "".join(", ".join(map(str, e)) + "\n" for e in els)
    text += body
    text += f"*MATERIAL, NAME=STEEL\n*ELASTIC\n{E}, {NU}\n*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL\n{section}"
    text += f"*STEP{', NLGEOM' if nlgeom else ''}\n*STATIC\n0.5, 1.\n{step}*NODE PRINT, NSET=NALL, TOTALS=YES\nU, RF\n"
    return text + "*END STEP\n"


def _sets(nodes, **where) -> str:
    """*NSET cards of the nodes each predicate picks."""
    out = ""
    for name, pick in where.items():
        labs = [str(n) for n, x, y in nodes if pick(x, y)]
        out += f"*NSET, NSET={name}\n" + "".join(", ".join(labs[k: k + 12]) + "\n" for k in range(0, len(labs), 12))
    return out


# -- a CPE4 block under a pressure on its right edge -------------------------------------------------------------------
def _svk_plane_strain(p: float) -> tuple[float, float]:
    """Stretches (l1, l2) of a St. Venant-Kirchhoff block in plane strain under a pressure p on the current edge
    x = L (a deck's pressure with NLGEOM follows the edge: Cauchy sigma11 = -p, sigma22 = 0, so S11 = -p l2 / l1,
    S22 = 0 with S = lam tr(E) I + 2 mu E, E33 = 0)."""
    lam, mu = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))

    def stretches(l1):
        e11 = 0.5 * (l1 ** 2 - 1)
        e22 = -lam * e11 / (lam + 2 * mu)   # (S22 = 0)
        return e11, e22, np.sqrt(1 + 2 * e22)

    def resid(l1):
        e11, e22, l2 = stretches(l1)
        return lam * (e11 + e22) + 2 * mu * e11 + p * l2 / l1

    l1 = brentq(resid, 0.5, 1.5, xtol=1e-15)
    return l1, stretches(l1)[2]


def _cpe4_deck(tmp_path: Path, p: float = 100.0, t: float = 0.5) -> Path:
    nodes, els = _grid(2, 1, 2.0, 1.0)
    body = _sets(nodes, LEFT=lambda x, y: x == 0.0, BOTTOM=lambda x, y: y == 0.0)
    body += "*BOUNDARY\nLEFT, 1\nBOTTOM, 2\n"
    deck = tmp_path / "cpe4.inp"
    deck.write_text(_deck("CPE4", nodes, els, f"{t}\n", body, f"*DLOAD\n2, P2, {p}\n"))
    return deck


def test_cpe4_block_under_pressure_is_the_closed_form(tmp_path):
    """CPE4, thickness 0.5 on *SOLID SECTION, P2 on the right edge (NLGEOM: on the current edge): the uniform
    stretch of the plane strain block (St. Venant-Kirchhoff, Cauchy stress -p, to the .dat's 7 digits; the
    small-strain closed form u_x = -(1 - nu^2) p x / E, u_y = nu (1 + nu) p y / E within 1e-3 of the largest, the
    geometric nonlinearity); RF of the left edge p l2 L_y t in total (the current height's)."""
    p, t = 100.0, 0.5
    dat = _run(_cpe4_deck(tmp_path, p, t), tmp_path)
    U, RF = _last(dat, "displacements"), _last(dat, "forces")
    l1, l2 = _svk_plane_strain(p)
    for lab, (x, y) in {1: (0, 0), 2: (1, 0), 3: (2, 0), 4: (0, 1), 5: (1, 1), 6: (2, 1)}.items():
        assert U[lab][:2] == pytest.approx([(l1 - 1) * x, (l2 - 1) * y], abs=1e-9 * max(x, 1))
        assert U[lab][:2] == pytest.approx([-(1 - NU ** 2) * p * x / E, NU * (1 + NU) * p * y / E],
                                           abs=1e-3 * p / E * 2)
        assert U[lab][2] == 0.0
    assert RF[1][0] + RF[4][0] == pytest.approx(p * l2 * 1.0 * t, rel=1e-6)
    assert _last(dat, "total")[0][0] == pytest.approx(0.0, abs=1e-8)   # (all nodes: the loads balance)


def test_cpe4_deck_imports_as_a_plane_strain_body(tmp_path):
    """covcontact import: formulation = "plane_strain" with the section's thickness, the mesh file's quad4 cells and
    the pressure's edge surface; the problem file runs to the same displacements."""
    deck = _cpe4_deck(tmp_path)
    out = tmp_path / "imp" / "cpe4.toml"
    proc = _cli("import", deck, "--out", out)
    assert proc.returncode == 0, proc.stderr
    prob = tomllib.loads(out.read_text())
    (body,) = prob["bodies"]
    assert body["formulation"] == "plane_strain" and body["thickness"] == 0.5
    assert prob["pressure"][0]["value"] == 100.0
    mesh = (out.parent / body["mesh"]["file"]).read_text()
    assert "TYPE=CPS4" in mesh and re.search(r"\*SURFACE, NAME=\S+, TYPE=ELEMENT\n\S+, S2", mesh)
    proc = _cli("run", out, "--out", tmp_path / "o2", "--quiet")
    assert proc.returncode == 0, proc.stderr


# -- CPS8R: a plane stress plate ----------------------------------------------------------------------------------------
def test_cps8r_plate_under_pressure_is_uniaxial_stress(tmp_path):
    """CPS8R (quad8, reduced integration), thickness 0.2: uniaxial St. Venant-Kirchhoff stress under the pressure
    on the current edge (NLGEOM; its reference thickness: S11 = E E11 = -p l2 / l1, E22 = -nu E11), to the .dat's 7
    digits; RF p l2 L_y t; the import says plane_stress, reduced integration, and notes the thickness."""
    p, t = 150.0, 0.2
    nodes, els = _grid(2, 2, 2.0, 1.0, quadratic=True)
    body = _sets(nodes, LEFT=lambda x, y: x == 0.0, BOTTOM=lambda x, y: y == 0.0)
    body += "*ELSET, ELSET=RIGHT\n2, 4\n*BOUNDARY\nLEFT, 1\nBOTTOM, 2\n"
    deck = tmp_path / "cps8r.inp"
    deck.write_text(_deck("CPS8R", nodes, els, f"{t}\n", body, f"*DLOAD\nRIGHT, P2, {p}\n"))
    dat = _run(deck, tmp_path)
    U, RF = _last(dat, "displacements"), _last(dat, "forces")
    l1 = brentq(lambda l: E * 0.5 * (l * l - 1) + p * np.sqrt(1 - NU * (l * l - 1)) / l, 0.5, 1.5, xtol=1e-15)
    l2 = np.sqrt(1 - NU * (l1 * l1 - 1))
    for n, x, y in nodes:
        assert U[n][:2] == pytest.approx([(l1 - 1) * x, (l2 - 1) * y], abs=1e-9)
    left = [n for n, x, y in nodes if x == 0.0]
    assert sum(RF[n][0] for n in left) == pytest.approx(p * l2 * 1.0 * t, rel=1e-6)
    out = tmp_path / "imp" / "cps8r.toml"
    proc = _cli("import", deck, "--out", out)
    assert proc.returncode == 0 and "follows the plane stress edges on their reference thickness" in proc.stderr
    (b,) = tomllib.loads(out.read_text())["bodies"]
    assert (b["formulation"], b["thickness"], b["options"]) == ("plane_stress", 0.2, {"integration": "reduced"})


# -- CAX8: Lame's thick cylinder ----------------------------------------------------------------------------------------
def test_cax8_thick_cylinder_against_lame(tmp_path):
    """CAX8 tube a = 1, b = 2 under an internal pressure (P4 on the bore), the bottom held axially, the top free (open
    ends, sigma_z = 0): the radial displacement against Lame's (Timoshenko & Goodier), u(r) = p a^2 ((1 - nu) r +
    (1 + nu) b^2 / r) / (E (b^2 - a^2)), within 0.5 % at every node; the axial strain -2 nu p a^2 / (E (b^2 - a^2))
    within 3 % (four CAX8 across the wall: CalculiX's linear run of this deck is 2 % off at the bore too).
    The .dat's RF is CalculiX's 2 degree segment: the bottom's axial reactions sum to zero, the import says
    axisymmetric without a thickness (the section's value has no effect, a note)."""
    a, b, h, p = 1.0, 2.0, 0.25, 100.0
    nodes, els = _grid(4, 1, b - a, h, x0=a, quadratic=True)
    body = _sets(nodes, BOTTOM=lambda x, y: y == 0.0) + "*BOUNDARY\nBOTTOM, 2\n"
    deck = tmp_path / "cax8.inp"
    deck.write_text(_deck("CAX8", nodes, els, "1.\n", body, f"*DLOAD\n1, P4, {p}\n"))
    dat = _run(deck, tmp_path)
    U, RF = _last(dat, "displacements"), _last(dat, "forces")
    c = p * a * a / (E * (b * b - a * a))
    for n, x, y in nodes:
        assert U[n][0] == pytest.approx(c * ((1 - NU) * x + (1 + NU) * b * b / x), rel=5e-3)
        assert U[n][1] == pytest.approx(-2 * NU * c * y, abs=3e-2 * 2 * NU * c * h)
    assert abs(sum(RF[n][1] for n, x, y in nodes if y == 0.0)) < 1e-6 * p * a * h
    out = tmp_path / "imp" / "cax8.toml"
    proc = _cli("import", deck, "--out", out)
    assert proc.returncode == 0, proc.stderr
    (bd,) = tomllib.loads(out.read_text())["bodies"]
    assert bd["formulation"] == "axisymmetric" and "thickness" not in bd


#: produced by running CalculiX 2.20 (Debian's ccx, "ccx -i cax4") on the deck test_cax4_point_loads_are_for_the_full_
#: circumference writes (its *STEP has NLGEOM): the .dat's displacements of nodes 1-4 at the step's end and the forces
#: of the bottom nodes 1, 2 along dof 2
_CCX_CAX4_U = {1: (-1.271068e-04, 0.0), 2: (-2.092580e-04, 0.0), 3: (-1.627888e-04, 2.526201e-04),
               4: (-7.142236e-05, 3.661376e-04)}
_CCX_CAX4_RF = {1: -1.640335, 2: -1.692998}


def test_cax4_point_loads_are_for_the_full_circumference(tmp_path):
    """CAX4 ring (R 1..2, height 1) pulled axially by *CLOAD 300 at each top node, the bottom held axially: CalculiX's
    manual gives point loads of axisymmetric elements for the complete circumference, and its .dat prints the forces of
    its expanded 2 degree segment (300 / 180 at the loaded nodes, the bottom's reactions summing to -600 / 180). The
    same here; displacements and reactions against CalculiX's (NLGEOM) within 1e-3."""
    nodes = [(1, 1.0, 0.0), (2, 2.0, 0.0), (3, 2.0, 1.0), (4, 1.0, 1.0)]
    body = "*NSET, NSET=BOT\n1, 2\n*BOUNDARY\nBOT, 2\n"
    deck = tmp_path / "cax4.inp"
    deck.write_text(_deck("CAX4", nodes, [(1, 1, 2, 3, 4)], "", body, "*CLOAD\n3, 2, 300.\n4, 2, 300.\n"))
    dat = _run(deck, tmp_path)
    U, RF = _last(dat, "displacements"), _last(dat, "forces")
    assert RF[3][1] == pytest.approx(300.0 / 180.0, rel=1e-6) and RF[4][1] == pytest.approx(300.0 / 180.0, rel=1e-6)
    assert RF[1][1] + RF[2][1] == pytest.approx(-600.0 / 180.0, rel=1e-6)
    scale = max(abs(v) for uv in _CCX_CAX4_U.values() for v in uv)
    for n, uv in _CCX_CAX4_U.items():
        assert U[n][:2] == pytest.approx(uv, abs=1e-3 * scale)
    for n, f in _CCX_CAX4_RF.items():
        assert RF[n][1] == pytest.approx(f, abs=1e-3 * 1.7)


# -- refusals -----------------------------------------------------------------------------------------------------------
_QUAD = "*NODE\n1, 0., 0., 0.\n2, 1., 0., 0.\n3, 1., 1., 0.\n4, 0., 1., 0.\n5, 2., 0., 0.\n6, 2., 1., 0.\n"
_TAIL = ("*MATERIAL, NAME=STEEL\n*ELASTIC\n210000., 0.3\n*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL\n{t}\n*BOUNDARY\n"
         "1, 1, 2\n4, 1\n*STEP\n*STATIC\n*CLOAD\n3, 1, 1.\n*END STEP\n")


@pytest.mark.parametrize("elements, tail, message", [
    ("*ELEMENT, TYPE=CPE4, ELSET=EALL\n1, 1, 2, 3, 4\n*ELEMENT, TYPE=CPS4, ELSET=EALL\n2, 2, 5, 6, 3\n", "",
     r"d\.inp:10: body EALL joins CPE4 \(plane_strain\) and CPS4 \(plane_stress\) elements through shared nodes"),
    ("*ELEMENT, TYPE=CPE4, ELSET=EALL\n1, 1, 4, 3, 2\n", "",
     r"d\.inp:8: element 1 \(CPE4\) is clockwise or of no area in the x-y plane"),
    ("*ELEMENT, TYPE=CAX4, ELSET=EALL\n1, 1, 2, 3, 4\n", "*NODE\n1, -0.5, 0., 0.\n",
     r"d\.inp:8: node 1 of the CAX4 elements has x = -0\.5: x is the radius"),
    ("*ELEMENT, TYPE=CPS4, ELSET=EALL\n1, 1, 2, 3, 4\n", "*NODE\n3, 1., 1., 0.25\n",
     r"d\.inp:8: node 3 of the CPS4 elements has z = 0\.25: .* lie in the x-y plane"),
])
def test_planar_refusals_are_one_line(tmp_path, elements, tail, message):
    """Two formulations in one body, a clockwise element, a negative radius, a node off the x-y plane: one line naming
    the deck line, exit 2 (contact pairs: test_deck_planar_contact.py)."""
    deck = tmp_path / "d.inp"
    nodes = _QUAD
    if tail:  # (a node moved: its line replaced)
        lab = tail.split("\n")[1].split(",")[0]
        nodes = "\n".join(ln for ln in _QUAD.splitlines() if not ln.startswith(f"{lab},")) + "\n" + tail.split("\n", 1)[1]
        nodes = "*NODE\n" + "".join(sorted((ln + "\n" for ln in nodes.splitlines() if ln and not ln.startswith("*")),
                                           key=lambda s: int(s.split(",")[0])))
    deck.write_text(nodes + elements + _TAIL.format(t="1."))
    proc = _cli("run", deck, "--out", tmp_path / "o", "--quiet")
    assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr
    (line,) = [ln for ln in proc.stderr.splitlines() if "error" in ln]
    assert re.search(message, line), line


def test_two_thicknesses_in_one_planar_body_are_refused(tmp_path):
    deck = tmp_path / "d.inp"
    deck.write_text(_QUAD + "*ELEMENT, TYPE=CPS4, ELSET=E1\n1, 1, 2, 3, 4\n*ELEMENT, TYPE=CPS4, ELSET=E2\n"
                    "2, 2, 5, 6, 3\n*MATERIAL, NAME=STEEL\n*ELASTIC\n210000., 0.3\n*SOLID SECTION, ELSET=E1, "
                    "MATERIAL=STEEL\n0.1\n*SOLID SECTION, ELSET=E2, MATERIAL=STEEL\n0.2\n*BOUNDARY\n1, 1, 2\n4, 1\n"
                    "*STEP\n*STATIC\n*CLOAD\n3, 1, 1.\n*END STEP\n")
    proc = _cli("run", deck, "--out", tmp_path / "o", "--quiet")
    assert proc.returncode == 2
    (line,) = [ln for ln in proc.stderr.splitlines() if "error" in ln]
    assert "d.inp:17: body PART1 has *SOLID SECTIONs of thicknesses 0.1, 0.2: a planar body has one thickness" in line
