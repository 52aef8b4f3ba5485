"""Abaqus / CalculiX decks (decks of our own, written here): the card reader (comments, continuations, *INCLUDE,
GENERATE, case), the mapping of each supported keyword onto covcontact's problem, a deck run against the same model
written as a problem file, the .dat table, the unsupported-keyword report, one-line errors naming the line, and the
linear multi-point constraints (*EQUATION / [[equation]]): exact closed form, tangent against differences, chains,
and their input errors."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from covcontact.io.deck import DeckError, read_deck
from covcontact.io.deck_import import import_deck
from covcontact.io.deck_model import read_model
from covcontact.io.loader import load_problem
from covcontact.io.validate import InputError

from reduced_fd import column_errors


def _block_nodes(nx, ny, nz, lx, ly, lz, origin, first_label):
    """Nodes (labels, xyz) and C3D8 elements (node labels) of a structured brick block."""
    i, j, k = np.meshgrid(np.arange(nx + 1), np.arange(ny + 1), np.arange(nz + 1), indexing="ij")
    X = np.column_stack([i.ravel() * lx / nx, j.ravel() * ly / ny, k.ravel() * lz / nz]) + origin
    lab = first_label + np.arange(len(X))
    idx = lab.reshape(nx + 1, ny + 1, nz + 1)
    els = [[idx[a, b, c], idx[a + 1, b, c], idx[a + 1, b + 1, c], idx[a, b + 1, c],
            idx[a, b, c + 1], idx[a + 1, b, c + 1], idx[a + 1, b + 1, c + 1], idx[a, b + 1, c + 1]]
           for a in range(nx) for b in range(ny) for c in range(nz)]
    return lab, X, np.array(els)


def _lines(labels, X):
    return "\n".join(f"{n}, {x:.12g}, {y:.12g}, {z:.12g}" for n, (x, y, z) in zip(labels, X))


def _elements(first, els):
    return "\n".join(", ".join(map(str, [first + e, *row])) for e, row in enumerate(els))


def two_block_deck(path: Path, *, extra_step: str = "", pair: str = "NODE TO SURFACE") -> Path:
    """A base 2 x 2 x 1 (labels from 1) and a punch 1 x 1 x 0.5 on top (labels from 1001), C3D8, SVK-like elastic,
    linear pressure-overclosure, the punch's top pushed down by 0.02 in two increments."""
    lb, Xb, eb = _block_nodes(2, 2, 1, 2.0, 2.0, 1.0, [0.0, 0.0, 0.0], 1)
    lp, Xp, ep = _block_nodes(2, 2, 1, 1.0, 1.0, 0.5, [0.5, 0.5, 1.0], 1001)
    bottom = lb[np.isclose(Xb[:, 2], 0.0)]
    top = lp[np.isclose(Xp[:, 2], 1.5)]
    slave = lp[np.isclose(Xp[:, 2], 1.0)]
    text = f"""**
** two blocks (a deck of the tests)
**
*Heading
two blocks
*NODE, NSET=NALL
{_lines(lb, Xb)}
{_lines(lp, Xp)}
*ELEMENT, TYPE=C3D8, ELSET=BASE
{_elements(1, eb)}
*Element, type=c3d8,
ELSET=PUNCH
{_elements(101, ep)}
*NSET, NSET=BOTTOM
{", ".join(map(str, bottom))}
*NSET, NSET=TOP
{", ".join(map(str, top))}
*NSET, NSET=NSLAVE
{", ".join(map(str, slave))}
*ELSET, ELSET=BASETOP, GENERATE
1, 4, 1
*SURFACE, NAME=SMAST, TYPE=ELEMENT
BASETOP, S2
*SURFACE, NAME=SSLAV, TYPE=NODE
NSLAVE
*MATERIAL, NAME=STEEL
*ELASTIC
1000.0, 0.3
*SOLID SECTION, ELSET=BASE, MATERIAL=STEEL
*SOLID SECTION, ELSET=PUNCH, MATERIAL=STEEL
*CONTACT PAIR, INTERACTION=SI1, TYPE={pair}
SSLAV, SMAST
*SURFACE INTERACTION, NAME=SI1
*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR
1.0e6
*BOUNDARY
BOTTOM, 1, 3
*STEP, NLGEOM
*STATIC
0.5, 1.0
*BOUNDARY
TOP, 1, 2
TOP, 3, 3, -0.02
*NODE PRINT, NSET=BOTTOM
U, RF
*END STEP
{extra_step}"""
    path.write_text(text)
    return path


TWO_BLOCKS_TOML = """
[problem]
name = "hand"
[[bodies]]
name = "base"
element = "hex8"
material = { model = "svk", E = 1000.0, nu = 0.3 }
mesh = { generator = "block", lx = 2.0, ly = 2.0, lz = 1.0, nx = 2, ny = 2, nz = 1 }
[[bodies]]
name = "punch"
element = "hex8"
material = { model = "svk", E = 1000.0, nu = 0.3 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 0.5, nx = 2, ny = 2, nz = 1, origin = [0.5, 0.5, 1.0] }
[[contact]]
slave = "punch.zmin"
master = "base.zmax"
law = "arctan"
penalty = 1.0e6
tension = 0.014285714285714285
weighting = "boundary"
[[dirichlet]]
set = "base.zmin"
components = "xyz"
[[dirichlet]]
set = "punch.zmax"
components = "xyz"
value = [0.0, 0.0, -0.02]
[steps]
initial = 0.5
"""


def test_cards_comments_continuations_include_and_case(tmp_path):
    (tmp_path / "nodes.inc").write_text("*node, nset=n\n1, 0, 0, 0\n2, 1., 0., 0.\n")
    deck = tmp_path / "d.inp"
    deck.write_text("** a comment\n*HEADING\ntitle\n*INCLUDE, INPUT=nodes.inc\n*Nset, nset=TWO,\ngenerate\n1, 2, 1\n")
    cards = read_deck(deck)
    assert [c.name for c in cards] == ["HEADING", "NODE", "NSET"]
    assert cards[1].params == {"NSET": "n"} and cards[1].file.name == "nodes.inc" and cards[1].lines[1] == 3
    assert cards[2].params == {"NSET": "TWO", "GENERATE": ""}  # a keyword line continued after its comma
    m = read_model(deck)
    assert m.node_labels.tolist() == [1, 2] and m.nsets["TWO"].tolist() == [1, 2] and m.nsets["N"].tolist() == [1, 2]


def test_malformed_lines_are_named(tmp_path):
    """Each malformed deck is one line naming the file and line, what is wrong (and an input error: exit 2)."""
    deck = tmp_path / "bad.inp"
    base = "*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 1, 1, 0\n4, 0, 1, 0\n5, 0, 0, 1\n6, 1, 0, 1\n7, 1, 1, 1\n8, 0, 1, 1\n"
    model = "*MATERIAL, NAME=M\n*ELASTIC\n1, 0.3\n*SOLID SECTION, ELSET=EALL, MATERIAL=M\n"
    one = "*ELEMENT, TYPE=C3D8, ELSET=EALL\n1, 1, 2, 3, 4, 5, 6, 7, 8\n"
    cases = {
        base.replace("3, 1, 1, 0", "3, 1, x1, 0"): "bad.inp:4: *NODE: y must be a number, got 'x1' (field 3)",
        base + "*ELEMENT, TYPE=C3D8\n1, 1, 2, 3, 4, 5, 6, 7\n": "bad.inp:11: *ELEMENT: a C3D8 element (label and 8 "
                                                                "nodes): 8 fields where 9 are needed per entry",
        base + one + "*NSET, NSET=A\nB\n": "bad.inp:13: *NSET: 'B' is neither a label nor a NSET defined above",
        base + one.replace("7, 8", "7, 9") + model + "*STEP\n*STATIC\n*END STEP\n":
            "bad.inp:10: *ELEMENT: element 1 refers to node 9, which no *NODE defines",
        base + one + model + "*SURFACE, NAME=S\nEALL, S7\n*STEP\n*STATIC\n*END STEP\n":
            "bad.inp:17: S7: hex8 elements have the faces S1..S6",
        base + one + model + "*STEP\n*STATIC\n*DLOAD\nEALL, P2, x\n*END STEP\n":
            "bad.inp:19: *DLOAD: the magnitude must be a number, got 'x' (field 3)",
        base + one + model + "*BOUNDARY\nNOPE, 1, 3\n*STEP\n*STATIC\n*END STEP\n":
            "bad.inp:17: *BOUNDARY: 'NOPE' is neither a node label nor a *NSET defined above",
        base + "*BOUNDARY\n1, 1\n*STEP\n*STATIC\n": "bad.inp:12: *STEP without its *END STEP",
    }
    for text, words in cases.items():
        deck.write_text(text)
        with pytest.raises(DeckError) as err:
            import_deck(deck, tmp_path / "out.toml")
        msg = str(err.value)
        assert words in msg and "\n" not in msg, (words, msg)
        assert isinstance(err.value, InputError)  # (the command's exit code 2)


def test_mapping_of_the_keywords(tmp_path):
    """Each supported keyword lands where it should: two bodies (connected parts), their material, the contact pair
    and its law, the conditions (model data and step data), the increments, the node-print request."""
    imp = import_deck(two_block_deck(tmp_path / "tb.inp"), tmp_path / "tb.toml")
    assert imp.unsupported == []
    p = load_problem(imp.problem)
    assert [b.name for b in p.bodies] == ["BASE", "PUNCH"]  # named by their sections' element sets
    assert [b.mesh.n_cells for b in p.bodies] == [4, 4] and p.bodies[0].material.E == 1000.0
    c = p.contacts[0]
    assert c.slave == ("PUNCH", "SSLAV") and c.master == ("BASE", "SMAST") and c.penalty == 1.0e6
    assert c.weighting == "boundary"  # a node surface: the law per node area over the body's boundary faces
    assert {(d.body, d.set, d.components) for d in p.dirichlet} >= {("BASE", "BOTTOM", (0,)), ("PUNCH", "TOP", (2,))}
    assert [d.values for d in p.dirichlet if d.set == "TOP" and d.components == (2,)] == [(-0.02,)]
    assert p.steps.initial == 0.5
    assert p.bodies[1].mesh.face_sets == {} or "SMAST" not in p.bodies[1].mesh.face_sets
    assert p.bodies[0].mesh.face_sets["SMAST"].shape == (4, 4)


def test_mapping_of_laws_materials_and_loads(tmp_path):
    """The pressure-overclosure laws, friction, *PLASTIC (the table law; HARDENING=KINEMATIC with two points: linear
    kinematic hardening), *DENSITY, *DLOAD GRAV and CENTRIF, a *DLOAD face pressure, an element slave surface for
    surface-to-surface contact, *CONTACT PAIR ADJUST (a distance or a node set) and SMALL SLIDING."""
    text = two_block_deck(tmp_path / "tb.inp").read_text()
    variants = {
        "exponential": ("PRESSURE-OVERCLOSURE=LINEAR\n1.0e6", "PRESSURE-OVERCLOSURE=EXPONENTIAL\n0.001, 50.0"),
        "hard": ("PRESSURE-OVERCLOSURE=LINEAR\n1.0e6", "PRESSURE-OVERCLOSURE=HARD"),
        "tied": ("PRESSURE-OVERCLOSURE=LINEAR\n1.0e6", "PRESSURE-OVERCLOSURE=TIED\n2.0e5\n*FRICTION\n0.5, 2.0e5"),
        "tabular": ("PRESSURE-OVERCLOSURE=LINEAR\n1.0e6", "PRESSURE-OVERCLOSURE=TABULAR\n0., 0.\n5., 0.01, 0\n"
                    "40., 0.05, 0"),
        "linear": ("PRESSURE-OVERCLOSURE=LINEAR\n1.0e6", "PRESSURE-OVERCLOSURE=LINEAR\n1.0e6, 0.5, 2e-3"),
        "linear-default": ("PRESSURE-OVERCLOSURE=LINEAR\n1.0e6", "PRESSURE-OVERCLOSURE=LINEAR\n1.0e6"),
        "friction": ("1.0e6\n", "1.0e6\n*FRICTION\n0.2, 5.0e5\n"),
        "plastic": ("1000.0, 0.3\n", "1000.0, 0.3\n*PLASTIC\n5.0, 0.0\n6.0, 0.1\n*DENSITY\n2.0\n"),
        "kinematic": ("1000.0, 0.3\n", "1000.0, 0.3\n*PLASTIC, HARDENING=KINEMATIC\n5.0, 0.0\n6.0, 0.1\n"),
        "centrif": ("1000.0, 0.3\n", "1000.0, 0.3\n*DENSITY\n2.0\n"),
        "adjust": ("TYPE=NODE TO SURFACE\n", "TYPE=NODE TO SURFACE, ADJUST=0.01, SMALL SLIDING\n"),
        "adjust-set": ("TYPE=NODE TO SURFACE\n", "TYPE=NODE TO SURFACE, ADJUST=NSLAVE\n"),
        "tie": ("*CONTACT PAIR, INTERACTION=SI1, TYPE=NODE TO SURFACE\nSSLAV, SMAST",
                "*TIE, NAME=T1, POSITION TOLERANCE=0.01\nSSLAV, SMAST"),
        "sts-dload": ("*SURFACE, NAME=SSLAV, TYPE=NODE\nNSLAVE", "*ELSET, ELSET=PBOT\n101, 102, 103, 104\n"
                      "*SURFACE, NAME=SSLAV\nPBOT, S1"),
    }
    for name, (old, new) in variants.items():
        assert old in text, name
        body = text.replace(old, new)
        if name == "plastic":
            body = body.replace("*NODE PRINT", "*DLOAD\nBASE, GRAV, 9.81, 0., 0., -2.\n*NODE PRINT")
        if name == "centrif":
            body = body.replace("*NODE PRINT", "*DLOAD\nBASE, CENTRIF, 4.0, 1., 1., 0., 0., 0., 3.\n*NODE PRINT")
        if name == "sts-dload":
            body = body.replace("NODE TO SURFACE", "SURFACE TO SURFACE").replace(
                "*NODE PRINT", "*DLOAD\nPUNCH, P2, 0.5\n*NODE PRINT")
        if name == "tied":  # (CalculiX ties face-to-face pairs)
            body = body.replace("NODE TO SURFACE", "SURFACE TO SURFACE").replace(
                "*SURFACE, NAME=SSLAV, TYPE=NODE\nNSLAVE", "*ELSET, ELSET=PBOT\n101, 102, 103, 104\n"
                "*SURFACE, NAME=SSLAV\nPBOT, S1")
        deck = tmp_path / f"{name}.inp"
        deck.write_text(body)
        imp = import_deck(deck, tmp_path / name / "p.toml")
        assert imp.unsupported == [], (name, imp.unsupported)
        p = load_problem(imp.problem)
        c = p.contacts[0]
        if name == "exponential":  # a CalculiX deck: CalculiX's curve p0 exp(-ln(100) g / c0)
            assert (c.law, c.clearance, c.pressure, c.form) == ("exponential", 0.001, 50.0, "calculix")
            imp = import_deck(deck, tmp_path / name / "a.toml", dialect="abaqus")
            assert load_problem(imp.problem).contacts[0].form == "abaqus"
        elif name == "hard":  # node slaves: augmented Lagrange, 10 E h of the base (E = 1000, h = 1)
            assert c.method == "augmented" and c.penalty == pytest.approx(1.0e4)
        elif name == "tied":  # the slope K per area, the stick slope equal to it
            assert (c.law, c.penalty, c.weighting, c.type) == ("tied", 2.0e5, "area", "sts")
        elif name == "tabular":  # (pressure, overclosure) lines as [overclosure, pressure] pairs
            assert c.law == "table" and c.table == ((0.0, 0.0), (0.01, 5.0), (0.05, 40.0))
        elif name in ("linear", "linear-default"):  # node-to-face: K d (1/2 + atan(d / e) / pi), e = pi sigma_inf / K
            assert (c.law, c.penalty) == ("arctan", 1.0e6)
            if name == "linear":
                assert (c.tension, c.reach) == (0.5, 2e-3) and imp.notes == []
            else:  # CalculiX's default sigma_inf: E / 70000 of the first material, said in a note
                assert c.tension == pytest.approx(1000.0 / 70000.0) and c.reach is None
                assert len(imp.notes) == 1 and "default E / 70000" in imp.notes[0]
        elif name == "tie":
            assert c.law == "tied" and c.tie_tolerance == 0.01 and c.slave == ("PUNCH", "SSLAV")
        elif name == "friction":
            assert c.friction == 0.2 and c.tangential_penalty == 5.0e5
        elif name == "plastic":
            mat = p.bodies[0].material
            assert mat.kind == 2 and mat.density == 2.0
            assert tuple(mat.hardening.stress) == (5.0, 6.0) and tuple(mat.hardening.strain) == (0.0, 0.1)
            (g,) = p.body_forces  # GRAV: an acceleration on the element set (a unit direction times the magnitude)
            assert (g.body, g.cells, g.per_mass) == ("BASE", "BASE", True)
            assert g.value == pytest.approx((0.0, 0.0, -9.81))
        elif name == "centrif":  # omega^2 = 4 about the axis (0, 0, 1) through (1, 1, 0)
            (g,) = p.body_forces
            assert (g.body, g.cells, g.per_mass) == ("BASE", "BASE", True)
            assert g.value == pytest.approx((4.0, 0.0, 0.0)) and g.axis == pytest.approx((0.0, 0.0, 1.0))
            assert g.center == pytest.approx((1.0, 1.0, 0.0))
        elif name == "adjust":  # (SMALL SLIDING: read as the finite sliding covcontact always does)
            assert c.adjust == 0.01
        elif name == "adjust-set":
            assert c.adjust == "NSLAVE"
        elif name == "kinematic":  # linear (Prager) kinematic hardening, slope (6 - 5) / 0.1, no isotropic part
            mat = p.bodies[0].material
            assert mat.kind == 2 and mat.yield_stress == 5.0 and mat.kinematic_modulus == pytest.approx(10.0)
            assert mat.hardening.law == "linear" and mat.hardening.modulus == 0.0
        else:
            assert c.slave == ("PUNCH", "SSLAV") and c.type == "sts" and c.weighting == "area"
            assert p.bodies[1].mesh.face_sets["SSLAV"].shape == (4, 4)
            (pr,) = p.pressures
            assert pr.value == 0.5 and p.bodies[1].mesh.face_sets[pr.set].shape == (4, 4)  # the punch's top faces
            assert np.allclose(p.bodies[1].mesh.points[np.unique(p.bodies[1].mesh.face_sets[pr.set]), 2], 1.5)


def test_dynamic_steps(tmp_path):
    """*DYNAMIC (ALPHA, increment, period) becomes a dynamic stage with HHT, rho_inf = (1 + alpha) / (1 - alpha) and
    CalculiX's consistent mass of implicit dynamics (its manual: lumped only with EXPLICIT); a deck without *DENSITY
    is then refused naming the density."""
    text = two_block_deck(tmp_path / "tb.inp").read_text().replace("*STATIC\n0.5, 1.0\n",
                                                                    "*DYNAMIC, ALPHA=-0.1\n0.05, 0.5, 0.01, 0.1\n")
    deck = tmp_path / "dyn.inp"
    deck.write_text(text.replace("1000.0, 0.3\n", "1000.0, 0.3\n*DENSITY\n1.0\n"))
    p = load_problem(import_deck(deck, tmp_path / "d" / "p.toml").problem)
    d = p.dynamics
    assert (d.method, d.dt, d.t_end, d.dt_min, d.dt_max, d.mass) == ("hht", 0.05, 0.5, 0.01, 0.1, "consistent")
    assert d.rho_inf == pytest.approx(0.9 / 1.1)
    deck.write_text(text)
    with pytest.raises(InputError, match="density"):
        load_problem(import_deck(deck, tmp_path / "e" / "p.toml").problem)
    deck.write_text(text.replace("ALPHA=-0.1", "ALPHA=-0.5"))
    with pytest.raises(DeckError, match=r"ALPHA must lie in \[-1/3, 0\], got -0.5"):
        import_deck(deck, tmp_path / "f" / "p.toml")


def test_amplitudes_cut_a_step_into_stages(tmp_path):
    """A *CLOAD with a tabular amplitude 0 -> 1 -> 0.5 at step times 0, 0.4, 1 (period 1): two stages, the force
    reaching a(0.4) F at the first cut and a(1) F at the end; the punch's prescribed motion (no amplitude) ramped
    over the step: 0.4 and 1 of it; the requests printed at the step's end only; an unknown amplitude is one line;
    TIME DELAY shifts the table."""
    text = two_block_deck(tmp_path / "tb.inp").read_text()
    text = text.replace("*STEP, NLGEOM", "*AMPLITUDE, NAME=A1\n0., 0., 0.4, 1.0, 1.0, 0.5\n*STEP, NLGEOM")
    text = text.replace("*NODE PRINT", "*CLOAD, AMPLITUDE=A1\n1001, 1, 2.0\n*NODE PRINT")
    deck = tmp_path / "amp.inp"
    deck.write_text(text)
    imp = import_deck(deck, tmp_path / "a" / "p.toml")
    assert imp.unsupported == []
    p = load_problem(imp.problem)
    (force,) = p.forces
    assert force.value == pytest.approx((2.0, 0.0, 0.0))          # a(0.4) F at the end of the first stage
    (st,) = p.stages
    assert st.targets[force.name] == pytest.approx([1.0, 0.0, 0.0])  # a(1) F
    moved = next(d for d in p.dirichlet if d.set == "TOP" and d.components == (2,))
    assert moved.values == pytest.approx((-0.02 * 0.4,)) and st.targets[moved.name] == pytest.approx([-0.02])
    import json

    info = json.loads(imp.labels.read_text())
    assert info["periods"] == pytest.approx([0.4, 0.6])  # printed at every increment and at the step's end only
    assert info["print_every"] == [1, 1] and info["print_end"] == [False, True]
    deck.write_text(text.replace("AMPLITUDE=A1", "AMPLITUDE=A2"))
    with pytest.raises(DeckError, match="AMPLITUDE=A2: no \\*AMPLITUDE of that name .defined: A1."):
        import_deck(deck, tmp_path / "b" / "p.toml")
    # TIME DELAY 0.2: the table read at t - 0.2, its points at 0.2, 0.6 (and 1.2, past the step): the first value (0)
    # until 0.2, 1.0 F at the cut 0.6, a(1 - 0.2) F = (2/3) F at the end
    deck.write_text(text.replace("AMPLITUDE=A1", "AMPLITUDE=A1, TIME DELAY=0.2"))
    p = load_problem(import_deck(deck, tmp_path / "c" / "p.toml").problem)
    (force,) = p.forces
    assert force.value == pytest.approx((0.0, 0.0, 0.0))
    assert [st.targets[force.name] for st in p.stages] == [pytest.approx([2.0, 0.0, 0.0]),
                                                            pytest.approx([4.0 / 3.0, 0.0, 0.0])]
    deck.write_text(text.replace("*CLOAD, AMPLITUDE=A1", "*CLOAD, TIME DELAY=0.2"))
    with pytest.raises(DeckError, match="TIME DELAY shifts an amplitude: it needs AMPLITUDE= as well"):
        import_deck(deck, tmp_path / "d" / "p.toml")


def test_deck_run_equals_the_problem_file_and_writes_the_dat_table(tmp_path):
    """The deck and the same model as a problem file (generated meshes) give the same reactions; the .dat table prints
    the deck's labels with U and RF, and the forces on the support sum to the reaction."""
    deck = two_block_deck(tmp_path / "tb.inp")
    proc = subprocess.run([sys.executable, "-m", "covcontact.cli", "run", str(deck), "--out", str(tmp_path / "out"),
                           "--quiet"], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    hand = tmp_path / "hand.toml"
    hand.write_text(TWO_BLOCKS_TOML)
    ref = load_problem(hand).run(out=tmp_path / "hand", quiet=True)
    import json

    ours = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert [s["iterations"] for s in ours["steps"]] == [s["iterations"] for s in ref.summary["steps"]]
    fz = ref.summary["steps"][-1]["reactions"]["base.zmin"][2]
    got = [v for k, v in ours["steps"][-1]["reactions"].items() if k.startswith("BASE.BOTTOM")]
    assert sum(v[2] for v in got) == pytest.approx(fz, rel=1e-9)
    dat = (tmp_path / "out" / "tb.dat").read_text().splitlines()
    assert dat[1] == " displacements (vx,vy,vz) for set BOTTOM and time  0.5000000E+00"  # every increment
    assert " displacements (vx,vy,vz) for set BOTTOM and time  0.1000000E+01" in dat
    rf_at = dat.index(" forces (fx,fy,fz) for set BOTTOM and time  0.1000000E+01")
    rows = [ln.split() for ln in dat[rf_at + 2:] if ln.strip()]
    assert [int(r[0]) for r in rows] == [1, 3, 5, 7, 9, 11, 13, 15, 17]  # the deck's labels of the bottom nodes
    assert sum(float(r[3]) for r in rows) == pytest.approx(fz, rel=1e-6)


def test_steps_become_stages(tmp_path):
    """A second step with *BOUNDARY, OP=NEW that restates the support and moves the punch on: a stage whose targets
    hold the new value; a *CLOAD that appears there is declared at zero and given its target."""
    step2 = ("*STEP\n*STATIC\n0.5, 1.0\n*BOUNDARY, OP=NEW\nBOTTOM, 1, 3\nTOP, 1, 2\nTOP, 3, 3, -0.03\n*CLOAD\n1001, 1, "
             "0.5\n*END STEP\n")
    imp = import_deck(two_block_deck(tmp_path / "tb.inp", extra_step=step2), tmp_path / "tb.toml")
    assert imp.unsupported == []
    p = load_problem(imp.problem)
    assert len(p.stages) == 1
    st = p.stages[0]
    moved = [d.name for d in p.dirichlet if d.set == "TOP" and d.components == (2,)]
    assert st.targets[moved[0]] == pytest.approx([-0.03])
    force = [f for f in p.forces if f.set == "_N1001"][0]
    assert force.value == (0.0, 0.0, 0.0) and st.targets[force.name] == pytest.approx([0.5, 0.0, 0.0])


def test_change_friction_becomes_a_stage_coefficient(tmp_path):
    step2 = "*STEP\n*STATIC\n0.5, 1.0\n*CHANGE FRICTION, INTERACTION=SI1\n*FRICTION\n0.1, 5.0e5\n*END STEP\n"
    text = two_block_deck(tmp_path / "tb.inp", extra_step=step2).read_text().replace("1.0e6\n", "1.0e6\n*FRICTION\n"
                                                                                     "0.3, 5.0e5\n", 1)
    deck = tmp_path / "cf.inp"
    deck.write_text(text)
    p = load_problem(import_deck(deck, tmp_path / "cf" / "p.toml").problem)
    assert p.contacts[0].friction == 0.3 and p.stages[0].friction == {"pair1": 0.1}


def test_unsupported_keywords_are_listed_with_their_lines(tmp_path):
    deck = two_block_deck(tmp_path / "tb.inp")
    text = deck.read_text().replace("*STEP, NLGEOM", "*ORIENTATION, NAME=OR1\n1, 0, 0, 0, 1, 0\n*STEP, NLGEOM")
    text = text.replace("*STATIC\n", "*STATIC, SOLVER=SPOOLES, TIME RESET\n")
    deck.write_text(text)
    proc = subprocess.run([sys.executable, "-m", "covcontact.cli", "run", str(deck), "--out", str(tmp_path / "o"),
                           "--quiet"], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.splitlines()
    orient = text.splitlines().index("*ORIENTATION, NAME=OR1") + 1
    assert f"covcontact: unsupported: {deck}:{orient}: *ORIENTATION is not supported" in lines
    assert any("*STATIC, TIME RESET is not supported" in ln for ln in lines)
    assert lines[-1].startswith(f"covcontact: error: {deck}: 2 unsupported") and "Traceback" not in proc.stderr
    out = tmp_path / "imported.toml"
    proc = subprocess.run([sys.executable, "-m", "covcontact.cli", "import", str(deck), "--out", str(out)],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 2 and not out.exists()
    proc = subprocess.run([sys.executable, "-m", "covcontact.cli", "import", str(deck), "--out", str(out),
                           "--ignore-unsupported"], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0 and out.exists() and "covcontact: ignored:" in proc.stderr


# ------------------------------------------------------------------------------------------------ equations

EQUATION = """
[problem]
name = "mpc"
[[bodies]]
name = "bar"
element = "hex8"
material = { model = "svk", E = 100.0, nu = 0.0 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 2.0, nx = 2, ny = 2, nz = 3 }
[bodies.sets]
corner = { closest = [0.0, 0.0, 2.0] }
EQUATIONS
[[dirichlet]]
set = "bar.zmin"
components = "z"
[[dirichlet]]
set = "bar.xmin"
components = "x"
[[dirichlet]]
set = "bar.ymin"
components = "y"
[[force]]
set = "bar.corner"
value = [0.0, 0.0, 12.0]
[steps]
count = 2
"""


def _top_nodes():
    from covcontact.mesh.generators import block

    m = block(1.0, 1.0, 2.0, 2, 2, 3, "hex8")
    top = np.flatnonzero(np.isclose(m.points[:, 2], 2.0))
    corner = int(np.flatnonzero(np.all(np.isclose(m.points, [0.0, 0.0, 2.0]), axis=1))[0])
    return m, top, corner


def _equation_problem(tmp_path: Path, chain: bool = False) -> Path:
    """Every top node's u_z equal to the corner's (a rigid, free-to-stretch top), the force on the corner alone; with
    ``chain`` each node is tied to the one before it instead (eliminated dofs among other equations' terms)."""
    m, top, corner = _top_nodes()
    others = [int(n) for n in top if n != corner]
    sets = "".join(f"n{n} = {{ nodes = [{n}] }}\n" for n in [corner, *others])
    eqs = []
    for k, n in enumerate(others):
        ref = corner if not chain or k == 0 else others[k - 1]
        eqs.append(f'[[equation]]\nterms = [["bar.n{n}", "z", 2.0], ["bar.n{ref}", "z", -2.0]]\n')
    text = EQUATION.replace("corner = { closest = [0.0, 0.0, 2.0] }\n", "corner = { closest = [0.0, 0.0, 2.0] }\n"
                            + sets).replace("EQUATIONS", "".join(eqs[::-1] if chain else eqs))
    path = tmp_path / "mpc.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize("chain", [False, True], ids=["star", "chain"])
def test_equations_make_a_flat_top_exactly(tmp_path, chain):
    """A bar (nu = 0) pulled by a force on one corner of its top, the top's u_z tied to that corner's: a homogeneous
    stretch, St. Venant-Kirchhoff's uniaxial closed form F / A = E lambda (lambda^2 - 1) / 2 to 1e-8, the support's
    reaction F, every top node at the same height."""
    res = load_problem(_equation_problem(tmp_path, chain)).run(out=tmp_path / "o", quiet=True)
    assert res.exit_code == 0
    _, top, _ = _top_nodes()
    uz = res.u.reshape(-1, 3)[top, 2]
    np.testing.assert_allclose(uz, uz[0], rtol=1e-12)
    lam = np.roots([50.0, 0.0, -50.0, -12.0])  # E/2 (l^3 - l) = F / A, E = 100, F = 12, A = 1
    lam = float(lam[np.isreal(lam) & (lam.real > 1)].real[0])
    assert uz[0] == pytest.approx(2.0 * (lam - 1.0), rel=1e-8)  # (Newton tolerance)
    assert res.summary["steps"][-1]["reactions"]["bar.zmin"][2] == pytest.approx(-12.0, rel=1e-8)


def test_equation_tangent_matches_differences(tmp_path):
    """The reduced tangent T^T K T against central differences of the reduced residual T^T R in the independent dofs
    (the dependent ones follow), at a deformed state."""
    from covcontact.solvers.model import Model

    model = Model(load_problem(_equation_problem(tmp_path, chain=True)))
    committed = model.initial_state()
    rng = np.random.default_rng(0)
    u = 0.02 * rng.standard_normal(model.n_dofs)
    R, K, _ = model.evaluate(u, 0.5, committed)
    K = K.toarray()
    dep = model.constraints.mask
    errors = column_errors(model, u, 0.5, committed, K, rng.choice(np.flatnonzero(~dep), 15, replace=False))
    assert max(errors.values()) <= 1e-6 * np.abs(K).max()
    assert np.all(R[dep] == 0.0) and np.allclose(K[np.ix_(dep, ~dep)], 0.0)


def test_equation_input_errors(tmp_path):
    path = _equation_problem(tmp_path)
    text = path.read_text()
    _, top, corner = _top_nodes()
    n = int([t for t in top if t != corner][0])
    cases = {
        text + f'[[equation]]\nterms = [["bar.n{n}", "z", 1.0], ["bar.n{corner}", "x", 1.0]]\n':
            "is the eliminated (first) term of equation[0] already",
        text + f'[[equation]]\nterms = [["bar.n{corner}", "z", 1.0], ["bar.n{n}", "z", 1.0]]\n':
            "eliminate each other's dofs in a cycle",
        text + '[[equation]]\nterms = [["bar.zmax", "z", 1.0]]\n': "holds 9 nodes; each term names a set of one node",
        text + f'[[equation]]\nterms = [["bar.n{corner}", "w", 1.0]]\n': "must be [\"body.set\"",
        text.replace('[[dirichlet]]\nset = "bar.zmin"', f'[[dirichlet]]\nset = "bar.n{n}"'):
            "is the eliminated (first) term of equation",
    }
    for bad, words in cases.items():
        path.write_text(bad)
        with pytest.raises(InputError) as err:
            load_problem(path)
        assert words in str(err.value) and "\n" not in str(err.value), (words, str(err.value))


def test_imported_meshes_equal_their_files(tmp_path):
    """The meshes an import builds while writing its mesh files (what `covcontact run DECK.inp` hands the loader)
    equal those files read back: nodes, blocks, node, element and face sets."""
    from covcontact.mesh import read_mesh

    text = two_block_deck(tmp_path / "tb.inp").read_text().replace("*SURFACE, NAME=SSLAV, TYPE=NODE\nNSLAVE",
                                                                    "*ELSET, ELSET=PBOT\n101, 102, 103, 104\n"
                                                                    "*SURFACE, NAME=SSLAV\nPBOT, S1")
    deck = tmp_path / "sts.inp"
    deck.write_text(text.replace("*NODE PRINT", "*DLOAD\nPUNCH, P2, 0.5\n*NODE PRINT"))
    imp = import_deck(deck, tmp_path / "m" / "p.toml")
    assert sorted(imp.read) == sorted(imp.meshes) and len(imp.meshes) == 2
    for path, mesh in imp.read.items():
        ref = read_mesh(path)
        np.testing.assert_array_equal(mesh.points, ref.points)
        assert [(b.cell_type, b.cells.tolist()) for b in mesh.blocks] == [(b.cell_type, b.cells.tolist())
                                                                           for b in ref.blocks]
        for ours, theirs in ((mesh.node_sets, ref.node_sets), (mesh.element_sets, ref.element_sets),
                             (mesh.face_sets, ref.face_sets)):
            assert sorted(ours) == sorted(theirs)
            for k in ours:
                np.testing.assert_array_equal(ours[k], theirs[k])
    assert imp.read[imp.meshes[1]].face_sets["SSLAV"].shape == (4, 4)


def test_contact_print_tabulates_contact_stresses(tmp_path):
    """*CONTACT PRINT CSTRESS: a block per step end with every active slave node (the deck's labels of the punch's
    bottom nodes), the pressure positive, and times each node's area (a node slave surface: its area over the punch's
    boundary faces, as CalculiX takes it: 3/16, 4/16 and 4/16 (quarters of 0.5 x 0.5 faces) at a corner, an edge and the centre
    of the bottom) summing to the support's reaction (to the tilt of the deformed surface), the tangential tractions
    zero without friction (1e-9 of the pressure: the normal is the gap vector's direction, also at edge and vertex
    points)."""
    deck = two_block_deck(tmp_path / "tb.inp")
    deck.write_text(deck.read_text().replace("*NODE PRINT", "*CONTACT PRINT\nCSTRESS\n*NODE PRINT"))
    proc = subprocess.run([sys.executable, "-m", "covcontact.cli", "run", str(deck), "--out", str(tmp_path / "out"),
                           "--quiet"], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    lines = (tmp_path / "out" / "tb.dat").read_text().splitlines()
    at = lines.index(" contact stress (slave node,press,tang1,tang2) for all contact elements and time 0.1000000E+01")
    rows = []
    for ln in lines[at + 2:]:
        if not ln.strip():
            break
        rows.append([float(v) for v in ln.split()])
    rows = np.array(rows)
    assert rows[:, 0].astype(int).tolist() == list(range(1001, 1018, 2))   # the punch's bottom nodes
    import json

    fz = json.loads((tmp_path / "out" / "summary.json").read_text())["steps"][-1]["reactions"]
    support = sum(v[2] for k, v in fz.items() if k.startswith("BASE.BOTTOM"))
    # (the pressures act along the deformed surface's normals, tilted by about 1e-2: their sum is the vertical
    # reaction to 1e-4)
    lp, Xp, _ = _block_nodes(2, 2, 1, 1.0, 1.0, 0.5, [0.5, 0.5, 1.0], 1001)
    xy = dict(zip(lp.tolist(), Xp[:, :2].tolist()))
    rim = [sum(np.isclose(v, 0.5) or np.isclose(v, 1.5) for v in xy[int(lab)]) for lab in rows[:, 0]]
    area = np.array([{2: 3.0, 1: 4.0, 0: 4.0}[r] / 16.0 for r in rim])  # (a quarter of each 0.25 face)
    assert np.all(rows[:, 1] > 0.0) and (rows[:, 1] * area).sum() == pytest.approx(support, rel=1e-4)
    assert np.abs(rows[:, 2:]).max() < 1e-9 * rows[:, 1].max()


# ------------------------------------------------------------------------------------------------ removed equations

STACK = """
[problem]
name = "stack"
procedure = "dynamic"
dt = 0.01
t_end = 0.1
method = "newmark"
ramp = false
[[bodies]]
name = "low"
element = "hex8"
material = { model = "svk", E = 1.0e4, nu = 0.3, density = 1.0 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 1.0, nx = 1, ny = 1, nz = 1 }
[bodies.sets]
a = { closest = [0.0, 0.0, 1.0] }
b = { closest = [1.0, 0.0, 1.0] }
c = { closest = [1.0, 1.0, 1.0] }
d = { closest = [0.0, 1.0, 1.0] }
[[bodies]]
name = "up"
element = "hex8"
material = { model = "svk", E = 1.0e4, nu = 0.3, density = 1.0 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 1.0, nx = 1, ny = 1, nz = 1, origin = [0.0, 0.0, 1.0] }
[bodies.sets]
a = { closest = [0.0, 0.0, 1.0] }
b = { closest = [1.0, 0.0, 1.0] }
c = { closest = [1.0, 1.0, 1.0] }
d = { closest = [0.0, 1.0, 1.0] }
[[dirichlet]]
set = "low.zmin"
[[body_force]]
body = "up"
value = [0.0, 0.0, 50.0]
EQUATIONS
[[stages]]
name = "free"
procedure = "dynamic"
dt = 0.01
t_end = 0.05
method = "newmark"
remove = REMOVED
"""


def _stack(tmp_path, removed: str) -> Path:
    eqs = "".join(f'[[equation]]\nname = "{n}{c}"\nterms = [["up.{n}", "{c}", 1.0], ["low.{n}", "{c}", -1.0]]\n'
                  for n in "abcd" for c in "xyz")
    path = tmp_path / "stack.toml"
    path.write_text(STACK.replace("EQUATIONS", eqs).replace("REMOVED", removed))
    return path


def test_equations_removed_in_a_later_stage(tmp_path):
    """Two bricks stacked, the upper one's bottom corners tied to the lower one's top corners by equations (x, y, z),
    pulled up by a body force applied at once: they vibrate as one column; a later stage removes the equations (a
    deck's *EQUATION, REMOVE ALL) and the upper brick flies off: its momentum grows by F dt in every step exactly
    (1e-10; the stage starts from the equilibrium acceleration of the freed brick, not the one the constraint forces
    were in, which would miss by dt/2 times the tie's force), its bottom leaves the lower brick's top. Removing an
    equation twice, or one no [[equation]] names, is one line."""
    from covcontact.solvers.model import Model

    path = _stack(tmp_path, str([f"{n}{c}" for n in "abcd" for c in "xyz"]).replace("'", '"'))
    problem = load_problem(path)
    res = problem.run(out=tmp_path / "out", quiet=True)
    assert res.exit_code == 0
    model = Model(load_problem(path))
    M = model.system.mass()
    up = slice(3 * model.system.offset("up"), 3 * (model.system.offset("up") + 8))
    steps = [s for s in res.summary["steps"] if s["stage"] == "free"]
    assert len(steps) == 5
    # the momentum of the upper brick: p(t_end) - p(removal) = F (t_end - t_removal), F = b V = 50
    v_end = res.state.dynamics["v"]
    p_end = float((M @ v_end)[up][2::3].sum())
    # the momentum at the removal: the first stage alone, run again
    first = load_problem(path)
    first.stages = []
    first_res = first.run(out=tmp_path / "first", quiet=True)
    p0 = float((M @ first_res.state.dynamics["v"])[up][2::3].sum())
    assert p_end - p0 == pytest.approx(50.0 * 0.05, rel=1e-10)
    u = res.u.reshape(-1, 3)
    lo, hi = model.system.offset("low"), model.system.offset("up")
    gap = u[hi + np.flatnonzero(np.isclose(model.system.X[hi:hi + 8, 2], 1.0)), 2].mean() - \
        u[lo + np.flatnonzero(np.isclose(model.system.X[lo:lo + 8, 2], 1.0)), 2].mean()
    assert gap > 1e-3
    for removed, words in (('["ax", "ax"]', "was removed in an earlier stage"),
                           ('["ax", "qx"]', "no load or equation named 'qx'")):
        text = _stack(tmp_path, removed).read_text()
        if removed == '["ax", "ax"]':
            text = text.replace('remove = ["ax", "ax"]', 'remove = ["ax"]') + (
                '[[stages]]\nname = "again"\nprocedure = "dynamic"\ndt = 0.01\nt_end = 0.01\nremove = ["ax"]\n')
        path.write_text(text)
        with pytest.raises(InputError) as err:
            load_problem(path)
        assert words in str(err.value) and "\n" not in str(err.value), (words, str(err.value))


def test_equation_remove_becomes_a_stage_removal(tmp_path):
    """*EQUATION (model data, named eq1, eq2 in order) and *EQUATION, REMOVE in a later step: the stage removes the
    equations whose dependent (first) node and dof the lines name (a node label or a set); REMOVE ALL removes every
    one; a new *EQUATION inside a step is one line."""
    eqs = "*EQUATION\n2\n1001, 3, 1.0, 1003, 3, -1.0\n*EQUATION\n2\n1005, 3, 1.0, 1003, 3, -1.0\n*STEP"
    step2 = "*STEP\n*STATIC\n0.5, 1.0\n*EQUATION, REMOVE\nREMOVED\n*END STEP\n"
    for removed, names in (("1005, 3", ["eq2"]), ("NSLAVE, 3", ["eq1", "eq2"])):
        deck = two_block_deck(tmp_path / "eq.inp", extra_step=step2.replace("REMOVED", removed))
        deck.write_text(deck.read_text().replace("*STEP", eqs, 1))
        imp = import_deck(deck, tmp_path / removed.split(",")[0] / "p.toml")
        assert imp.unsupported == []
        p = load_problem(imp.problem)
        assert [e.name for e in p.equations] == ["eq1", "eq2"] and list(p.stages[0].remove) == names
    deck.write_text(deck.read_text().replace("*EQUATION, REMOVE\nNSLAVE, 3", "*EQUATION, REMOVE ALL"))
    assert list(load_problem(import_deck(deck, tmp_path / "all" / "p.toml").problem).stages[0].remove) == ["eq1", "eq2"]
    deck.write_text(deck.read_text().replace("*EQUATION, REMOVE ALL", "*EQUATION\n2\n1001, 1, 1.0, 1003, 1, -1.0"))
    with pytest.raises(DeckError, match="new equations belong to the model data, before the first"):
        import_deck(deck, tmp_path / "new" / "p.toml")


@pytest.mark.parametrize("line, isotropic", [("*ELASTIC, TYPE = ISOTROPIC", True), ("*ELASTIC, TYPE=ISO", True),
                                             ("*ELASTIC, TYPE=ORTHO", False)])
def test_elastic_type_read_by_its_first_letters(tmp_path, line, isotropic):
    """CalculiX reads *ELASTIC's TYPE by its first letters (elastics.f compares 'ISO'): Abaqus's TYPE=ISOTROPIC
    (with blanks round '=', as CalculiX's thread.inp writes it) is isotropic elasticity; ORTHO stays unsupported."""
    deck = two_block_deck(tmp_path / "tb.inp")
    deck.write_text(deck.read_text().replace("*ELASTIC\n", line + "\n"))
    if isotropic:
        p = load_problem(import_deck(deck, tmp_path / "i" / "p.toml").problem)
        assert p.bodies[0].material.E == 1000.0
    else:
        with pytest.raises(DeckError, match="TYPE=ORTHO is not supported"):
            import_deck(deck, tmp_path / "i" / "p.toml")
