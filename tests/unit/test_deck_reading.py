"""Decks read as CalculiX reads them (docs/input.md, "Abaqus and CalculiX decks"): *INCLUDE inside a keyword's data,
keyword lines continued only by parameter lines, single-temperature tables, print requests carried from step to step
(a bare *NODE PRINT stops them), TOTALS, and the laws of *SURFACE BEHAVIOR kept or refused with their lines."""

from __future__ import annotations

import json
from pathlib import Path
import subprocess
import sys

import numpy as np
import pytest

from covcontact.io.deck import DeckError, read_deck
from covcontact.io.deck_import import import_deck
from covcontact.io.deck_model import ELEMENTS, read_model
from covcontact.io.deck_planar import element_names
from covcontact.io.loader import load_problem

from test_deck import two_block_deck


def test_include_inside_data_keeps_file_and_line(tmp_path):
    """Data lines of an included file continue the card in force, and so do the lines after the *INCLUDE; an error
    names the included file's line; a missing include names the including line."""
    (tmp_path / "more.inc").write_text("2, 1, 0, 0\n3, 1, x, 0\n")
    deck = tmp_path / "d.inp"
    deck.write_text("*NODE\n1, 0, 0, 0\n*INCLUDE, INPUT=more.inc\n4, 0, 1, 0\n")
    (card,) = read_deck(deck)
    assert card.data == ["1, 0, 0, 0", "2, 1, 0, 0", "3, 1, x, 0", "4, 0, 1, 0"]
    assert [card.where(k).split("/")[-1] for k in range(4)] == ["d.inp:2", "more.inc:1", "more.inc:2", "d.inp:4"]
    with pytest.raises(DeckError, match=r"more\.inc:2: \*NODE: y must be a number"):
        read_model(deck)
    deck.write_text("*NODE\n1, 0, 0, 0\n*INCLUDE, INPUT=gone.inc\n")
    with pytest.raises(DeckError, match=r"d\.inp:3: \*INCLUDE, INPUT=gone\.inc: no such file"):
        read_deck(deck)


def test_keyword_continuation_by_dialect(tmp_path):
    """A keyword line ending with a comma continues on a parameter line (Abaqus), not on a data line (CalculiX's
    ``*NODE FILE,`` followed by ``U``)."""
    deck = tmp_path / "d.inp"
    deck.write_text("*NODE FILE,\nU\n*ELEMENT, TYPE=C3D8,\nELSET=E\n*NSET, NSET=A,\nGENERATE\n1, 4\n")
    a, b, c = read_deck(deck)
    assert (a.name, a.params, a.data) == ("NODE FILE", {}, ["U"])
    assert b.params == {"TYPE": "C3D8", "ELSET": "E"} and c.params == {"NSET": "A", "GENERATE": ""}


def test_single_temperature_tables_are_not_temperature_dependent(tmp_path):
    text = two_block_deck(tmp_path / "tb.inp").read_text()
    deck = tmp_path / "t.inp"
    deck.write_text(text.replace("1000.0, 0.3\n", "1000.0, 0.3, 20.\n*PLASTIC\n5.0, 0.0, 20.\n6.0, 0.1, 20.\n"))
    imp = import_deck(deck, tmp_path / "a" / "p.toml")
    assert imp.unsupported == []
    mat = load_problem(imp.problem).bodies[0].material
    assert mat.E == 1000.0 and tuple(mat.hardening.stress) == (5.0, 6.0)
    deck.write_text(text.replace("1000.0, 0.3\n", "1000.0, 0.3, 20.\n900.0, 0.3, 200.\n"))
    (line,) = import_deck(deck, tmp_path / "b" / "p.toml").unsupported
    assert "t.inp:" in line and "2 temperatures" in line and "first line's values are used" in line


def test_print_requests_carry_over_and_totals(tmp_path):
    """Step 2 does not restate *NODE PRINT: it prints what step 1 asked (CalculiX's rule); step 3's bare *NODE PRINT
    stops it. TOTALS=ONLY prints the sum of the forces and not the nodes; the sum is the support's reaction."""
    step = "*STEP\n*STATIC\n1.0, 1.0\n*BOUNDARY\nTOP, 3, 3, -0.02\n{}*END STEP\n"
    deck = two_block_deck(tmp_path / "tb.inp", extra_step=step.format("") + step.format("*NODE PRINT\n"))
    deck.write_text(deck.read_text().replace("*NODE PRINT, NSET=BOTTOM", "*NODE PRINT, NSET=BOTTOM, TOTALS=ONLY"))
    m = read_model(deck)
    assert [len(st.node_print) for st in m.steps] == [1, 1, 0]
    proc = subprocess.run([sys.executable, "-m", "covcontact.cli", "run", str(deck), "--out", str(tmp_path / "out"),
                           "--quiet"], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    dat = (tmp_path / "out" / "tb.dat").read_text()
    heads = [ln for ln in dat.splitlines() if "for set" in ln]  # (every increment of steps 1 and 2, none of 3)
    n = len(heads) // 2
    assert n >= 3 and [h.split(" for set")[0].strip() for h in heads] == ["displacements (vx,vy,vz)",
                                                                          "total force (fx,fy,fz)"] * n
    times = [float(h.split("time")[1]) for h in heads[1::2]]
    assert times == sorted(times) and 1.0 in times and times[-1] == 2.0
    lines = dat.splitlines()
    total = [float(v) for v in lines[lines.index(heads[-1]) + 2].split()]
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    step2 = [s for s in summary["steps"] if s.get("stage") == "step2"][-1]
    fz = sum(v[2] for k, v in step2["reactions"].items() if k.startswith("BASE.BOTTOM"))
    assert total[2] == pytest.approx(fz, rel=1e-6) and abs(fz) > 1.0
    assert summary["deck"]["file"] == "tb.inp" and summary["deck"]["ignored"] == []


def test_time_points_and_frequency(tmp_path):
    """*TIME POINTS: the step cut at its points and printed exactly there and at the step's end; FREQUENCY=2: every
    second increment and the step's end."""
    text = two_block_deck(tmp_path / "tb.inp").read_text()
    deck = tmp_path / "t.inp"
    deck.write_text(text.replace("*STEP, NLGEOM", "*TIME POINTS, NAME=TP, GENERATE\n0.3, 0.7, 0.4\n*STEP, NLGEOM")
                    .replace("*NODE PRINT, NSET=BOTTOM", "*NODE PRINT, NSET=BOTTOM, TIME POINTS=TP"))
    assert subprocess.run([sys.executable, "-m", "covcontact.cli", "run", str(deck), "--out", str(tmp_path / "a"),
                           "--quiet"], capture_output=True, timeout=600).returncode == 0
    times = [ln[-14:] for ln in (tmp_path / "a" / "t.dat").read_text().splitlines() if ln.startswith(" displacements")]
    assert times == [" 0.3000000E+00", " 0.7000000E+00", " 0.1000000E+01"]
    deck.write_text(text.replace("*STATIC\n0.5, 1.0\n", "*STATIC, DIRECT\n0.2, 1.0\n")
                    .replace("*NODE PRINT, NSET=BOTTOM", "*NODE PRINT, NSET=BOTTOM, FREQUENCY=2"))
    assert subprocess.run([sys.executable, "-m", "covcontact.cli", "run", str(deck), "--out", str(tmp_path / "b"),
                           "--quiet"], capture_output=True, timeout=600).returncode == 0
    times = [ln[-14:] for ln in (tmp_path / "b" / "t.dat").read_text().splitlines() if ln.startswith(" displacements")]
    assert times == [" 0.4000000E+00", " 0.8000000E+00", " 0.1000000E+01"]


def test_laws_kept_or_refused(tmp_path):
    """Every pressure-overclosure law is kept (its values in the problem) or refused with its line; with
    --ignore-unsupported the substitution is said, and summary.json keeps it."""
    text = two_block_deck(tmp_path / "tb.inp").read_text()
    deck = tmp_path / "x.inp"
    deck.write_text(text.replace("PRESSURE-OVERCLOSURE=LINEAR\n1.0e6", "PRESSURE-OVERCLOSURE=WAVY"))
    with pytest.raises(DeckError, match=r"x\.inp:\d+: \*SURFACE BEHAVIOR: PRESSURE-OVERCLOSURE=WAVY is not a"):
        import_deck(deck, tmp_path / "w" / "p.toml")
    deck.write_text(text.replace("PRESSURE-OVERCLOSURE=LINEAR\n1.0e6", "PRESSURE-OVERCLOSURE=TIED\n1.0e5"))
    proc = subprocess.run([sys.executable, "-m", "covcontact.cli", "run", str(deck), "--out", str(tmp_path / "o")],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 2 and "TIED on a NODE TO SURFACE pair" in proc.stderr
    deck.write_text(text.replace("PRESSURE-OVERCLOSURE=LINEAR\n1.0e6", "PRESSURE-OVERCLOSURE=LINEAR"))
    imp = import_deck(deck, tmp_path / "d" / "p.toml")
    c = load_problem(imp.problem).contacts[0]
    assert (c.law, c.penalty) == ("arctan", 50.0 * 1000.0)  # CalculiX's defaults: 50 E, E / 70000
    assert len(imp.notes) == 2 and all("CalculiX's default" in n for n in imp.notes)


def test_pairs_on_elements_not_read_are_listed_not_crashed(tmp_path):
    """A slave node surface of membrane (M3D4) nodes and a master SPOS face of a membrane: the pairs cannot be built,
    so they are listed with their lines (before: an IndexError); with --ignore-unsupported the rest runs. (Shells are
    read: tests/unit/test_deck_shells.py.)"""
    text = two_block_deck(tmp_path / "tb.inp").read_text()
    text = text.replace("*NODE, NSET=NALL\n", "*NODE, NSET=NALL\n9101, 0.,0.,3.\n9102, 1.,0.,3.\n9103, 1.,1.,3.\n"
                        "9104, 0.,1.,3.\n")
    text = text.replace("*ELEMENT, TYPE=C3D8, ELSET=BASE", "*ELEMENT, TYPE=M3D4, ELSET=PLATE\n9001, 9101, 9102, 9103, "
                        "9104\n*ELEMENT, TYPE=C3D8, ELSET=BASE")
    deck = tmp_path / "s4.inp"
    deck.write_text(text.replace("*NSET, NSET=NSLAVE\n", "*NSET, NSET=NSLAVE\n9101, 9102, 9103, 9104\n*NSET, NSET=X\n"))
    lines = import_deck(deck, tmp_path / "a" / "p.toml").unsupported
    assert any("TYPE=M3D4 is not supported" in ln for ln in lines)
    assert any("SSLAV's nodes belong to elements covcontact does not read" in ln for ln in lines)
    deck.write_text(text.replace("BASETOP, S2", "9001, SPOS"))
    lines = import_deck(deck, tmp_path / "b" / "p.toml").unsupported
    assert any("SPOS on element 9001, an M3D4" in ln for ln in lines)
    assert any("the surface SMAST has no faces" in ln for ln in lines)
    proc = subprocess.run([sys.executable, "-m", "covcontact.cli", "run", str(deck), "--out", str(tmp_path / "o"),
                           "--ignore-unsupported", "--quiet"], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert json.loads((tmp_path / "o" / "summary.json").read_text())["status"] == "completed"


def test_controls_raise_the_iteration_limits(tmp_path):
    """*CONTROLS, PARAMETERS=TIME INCREMENTATION: I_C (4th value) and I_A (8th) above covcontact's limits become
    [solver] max_iterations and max_cutbacks; below them covcontact's are kept (said); FIELD is a note."""
    text = two_block_deck(tmp_path / "tb.inp").read_text()
    deck = tmp_path / "c.inp"
    deck.write_text(text.replace("*STATIC\n", "*CONTROLS, PARAMETERS=TIME INCREMENTATION\n4, 8, 9, 60, 10, 4, 0, "
                                 "12, 5, 3\n*CONTROLS, PARAMETERS=FIELD\n0.01\n*STATIC\n"))
    imp = import_deck(deck, tmp_path / "a" / "p.toml")
    s = load_problem(imp.problem).solver
    assert (s.max_iterations, s.max_cutbacks) == (60, 12)
    assert any("PARAMETERS=FIELD" in n for n in imp.notes)
    deck.write_text(text.replace("*STATIC\n", "*CONTROLS, PARAMETERS=TIME INCREMENTATION\n4, 8, 9, 16, 10, 4, 0, "
                                 "5\n*STATIC\n"))
    imp = import_deck(deck, tmp_path / "b" / "p.toml")
    s = load_problem(imp.problem).solver
    assert (s.max_iterations, s.max_cutbacks) == (25, 6) and sum("is below covcontact's" in n for n in imp.notes) == 2


def test_surface_to_surface_decks_search_along_newton_corrections(tmp_path):
    """CalculiX searches along its Newton corrections in static face-to-face penalty contact: a deck with a surface-
    to-surface pair gets [solver] line_search; the example deck (a punch pressed and dragged with friction, the
    frictional contact sticking from touchdown) runs to the end."""
    for pair, expect in (("SURFACE TO SURFACE", True), ("NODE TO SURFACE", False)):
        imp = import_deck(two_block_deck(tmp_path / f"{expect}.inp", pair=pair), tmp_path / f"{expect}" / "p.toml")
        assert load_problem(imp.problem).solver.line_search is expect
    example = Path(__file__).resolve().parents[2] / "examples" / "decks" / "punch_slide.inp"
    proc = subprocess.run([sys.executable, "-m", "covcontact.cli", "run", str(example), "--out", str(tmp_path / "o"),
                           "--quiet"], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    s = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert s["status"] == "completed" and sum(st["cutbacks"] for st in s["steps"]) == 0


def test_blanks_calculix_ignores_and_c3d8i_lines_with_more_nodes(tmp_path):
    """CalculiX drops the blanks of keyword lines: *NODEPRINT is *NODE PRINT and TIMEPOINTS= is TIME POINTS=; a C3D8I
    line with more than its eight nodes (as CalculiX writes the nodes of its incompatible modes) takes the first
    eight."""
    text = two_block_deck(tmp_path / "tb.inp").read_text()
    deck = tmp_path / "b.inp"
    deck.write_text(text.replace("*STEP, NLGEOM", "*TIMEPOINTS, NAME=TP\n0.4\n*STEP, NLGEOM")
                    .replace("*NODE PRINT, NSET=BOTTOM", "*NODEPRINT, NSET=BOTTOM, TIMEPOINTS=TP"))
    m = read_model(deck)
    assert m.steps[0].time_points == "TP" and m.steps[0].node_print[0][0] == "BOTTOM" and m.unsupported == []
    lines = text.split("*ELEMENT, TYPE=C3D8, ELSET=BASE\n")[1].split("*")[0].strip().splitlines()
    extra = "\n".join(ln + ", 1, 2, 3, " for ln in lines)
    deck.write_text(text.replace("*ELEMENT, TYPE=C3D8, ELSET=BASE\n" + "\n".join(lines),
                                 "*ELEMENT, TYPE=C3D8I, ELSET=BASE\n" + extra))
    m = read_model(deck)
    ref = read_model(two_block_deck(tmp_path / "tb.inp"))
    assert m.blocks[0][0] == "C3D8I" and np.array_equal(m.blocks[0][3], ref.blocks[0][3])


# ------------------------------------------------------------------------------------- elements not read, named

_QUAD = "*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 1, 1, 0\n4, 0, 1, 0\n9, 2, 0, 0\n"


def _run(deck: Path, tmp_path: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "covcontact.cli", "run", str(deck), "--out", str(tmp_path / "o"),
                           "--quiet"], capture_output=True, text=True, timeout=600)


@pytest.mark.parametrize("etype", ["M3D4", "DC2D4"])
def test_a_deck_without_solids_names_its_element_types_and_lines(tmp_path, etype):
    """A deck whose only elements are of a type covcontact does not read, with a GRAV load on their ELSET=: one
    line naming the *ELEMENT line and the type (not the *DLOAD's set as undefined), exit 2."""
    deck = tmp_path / "d.inp"
    deck.write_text(_QUAD + f"*ELEMENT, TYPE={etype}, ELSET=Eall\n1, 1, 2, 3, 4\n*MATERIAL, NAME=steel\n*ELASTIC\n"
                    "210000, 0.3\n*DENSITY\n7.85e-9\n*STEP\n*STATIC\n*DLOAD\nEall, GRAV, 9810., 0., -1., 0.\n"
                    "*END STEP\n")
    proc = _run(deck, tmp_path)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    (line,) = [ln for ln in proc.stderr.splitlines() if "error" in ln]
    assert line == (f"covcontact: error: {deck}:7: no solid elements: the deck's elements are {etype} ({deck}:7); "
                    f"covcontact reads {element_names(ELEMENTS)}")


def test_a_coupling_on_elements_not_read_names_their_type_and_line(tmp_path):
    deck = tmp_path / "d.inp"
    deck.write_text(_QUAD + "*ELEMENT, TYPE=DC2D6, ELSET=Eall\n48, 1, 2, 3, 4\n*SURFACE, NAME=Sload\n48, S2\n"
                    "*COUPLING, SURFACE=Sload, REF NODE=9, CONSTRAINT NAME=load\n*KINEMATIC\n1, 3\n*MATERIAL, "
                    "NAME=steel\n*ELASTIC\n210000, 0.3\n*STEP\n*STATIC\n*CLOAD\n9, 1, 1.\n*END STEP\n")
    proc = _run(deck, tmp_path)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    (line,) = [ln for ln in proc.stderr.splitlines() if "error" in ln]
    assert line.startswith(f"covcontact: error: {deck}:10: *SURFACE SLOAD: element 48 is a DC2D6 (*ELEMENT, TYPE=DC2D6 "
                           f"at {deck}:7), a type covcontact does not read (it reads C3D8, ")
    assert line.endswith(f"the surface of *COUPLING LOAD at {deck}:11")
    deck.write_text(deck.read_text().replace("48, S2", "47, S2"))  # (an element no line defines)
    with pytest.raises(DeckError, match=r"d\.inp:10: \*SURFACE SLOAD: element 47 is not defined, the surface of"):
        read_model(deck)


def test_loads_on_elements_not_read_are_listed_with_their_type(tmp_path):
    """GRAV on a set with membrane elements (M3D4; shells are read: tests/unit/test_deck_shells.py; made by ELSET=
    of their *ELEMENT line, or by an *ELSET that names that
    set): listed as unsupported with the element's type and *ELEMENT line, the solids keep their weight with
    --ignore-unsupported; a face load on them is listed with its line; an element no line defines is an error."""
    text = two_block_deck(tmp_path / "tb.inp").read_text()
    text = text.replace("*NSET, NSET=BOTTOM", "*ELEMENT, TYPE=M3D4, ELSET=SKIN\n9001, 1, 2, 5, 4\n*NSET, NSET=BOTTOM", 1)
    text = text.replace("*ELSET, ELSET=BASETOP", "*ELSET, ELSET=ALL\nBASE, SKIN\n*ELSET, ELSET=BASETOP", 1)
    text = text.replace("1000.0, 0.3\n", "1000.0, 0.3\n*DENSITY\n1.0\n")
    shell = text.splitlines().index("*ELEMENT, TYPE=M3D4, ELSET=SKIN") + 1
    deck = tmp_path / "m.inp"
    for k, (load, said) in enumerate([
            ("SKIN, GRAV, 9.81, 0, 0, -1", "*DLOAD GRAV on SKIN: element 9001 is an M3D4 (*ELEMENT, TYPE=M3D4 at "
             f"{deck}:{shell}), a type covcontact does not read; with --ignore-unsupported the load acts on no "
             "element (left out)"),
            ("ALL, GRAV, 9.81, 0, 0, -1", "*DLOAD GRAV on ALL: element 9001 is an M3D4 (*ELEMENT, TYPE=M3D4 at "
             f"{deck}:{shell}), a type covcontact does not read; with --ignore-unsupported the load acts on the "
             "set's other elements alone"),
            ("SKIN, P1, 1.0", f"P1 on element 9001, a M3D4 (not read), from *ELEMENT, TYPE=M3D4 at {deck}:{shell}")]):
        deck.write_text(text.replace("*NODE PRINT", f"*DLOAD\n{load}\n*NODE PRINT"))
        at = deck.read_text().splitlines().index(load) + 1
        imp = import_deck(deck, tmp_path / f"i{k}" / "p.toml")
        assert imp.unsupported[-1] == f"{deck}:{at}: {said}"
        if "ALL" in load:  # (the solids' weight is kept)
            assert 'cells = "ALL"' in imp.problem.read_text()
    deck.write_text(text.replace("*NODE PRINT", "*DLOAD\n9002, GRAV, 9.81, 0, 0, -1\n*NODE PRINT"))
    with pytest.raises(DeckError, match=r"m\.inp:\d+: \*DLOAD: element 9002 is not defined"):
        import_deck(deck, tmp_path / "x" / "p.toml")


def test_surface_through_a_body_refused_in_one_line(tmp_path, capsys):
    """A *SURFACE whose faces lie inside a body: named only by an unsupported *PRE-TENSION SECTION, the run lists
    that keyword and stops (exit 2); used as a contact surface, one line names the deck, the body and the surface.
    Neither is an internal error (exit 3, CalculiX's pret2.inp was)."""
    from covcontact.cli import main

    deck = two_block_deck(tmp_path / "cut.inp")
    text = deck.read_text()
    step = text.index("*STEP")
    cut = "*SURFACE, NAME=CUT, TYPE=ELEMENT\n1, S4\n*PRE-TENSION SECTION, SURFACE=CUT, NODE=1\n"
    deck.write_text(text[:step] + cut + text[step:])
    assert main(["run", str(deck), "--out", str(tmp_path / "a"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "*PRE-TENSION SECTION is not supported" in err and "internal error" not in err
    assert "BASETOP, S2" in text
    deck.write_text(text.replace("BASETOP, S2", "1, S4"))
    assert main(["run", str(deck), "--out", str(tmp_path / "b"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "cut.inp: body" in err[0] and "*SURFACE SMAST: 1 of its faces are not on the boundary" \
        in err[0]


def test_load_on_the_reference_node_of_an_unsupported_keyword_is_listed(tmp_path):
    """A *CLOAD on the reference node of a *PRE-TENSION SECTION (CalculiX's pret1.inp: a node of no element) is listed
    with the keyword it belongs to, among the unsupported features, not refused as a load on nothing; a *CLOAD on
    another node of no element still is."""
    deck = two_block_deck(tmp_path / "pret.inp")
    text = deck.read_text()
    step = text.index("*STEP")
    cut = ("*NODE\n9999, 0., 0., 0.\n*SURFACE, NAME=CUT, TYPE=ELEMENT\n1, S4\n"
           "*PRE-TENSION SECTION, SURFACE=CUT, NODE=9999\n1., 0., 0.\n")
    assert "*NODE PRINT" in text
    deck.write_text(text[:step] + cut + text[step:].replace("*NODE PRINT", "*CLOAD\n9999, 1, -10.\n*NODE PRINT"))
    lines = deck.read_text().splitlines()
    at, pre = lines.index("9999, 1, -10.") + 1, lines.index("*PRE-TENSION SECTION, SURFACE=CUT, NODE=9999") + 1
    imp = import_deck(deck, tmp_path / "a" / "p.toml")
    assert f"{deck}:{pre}: *PRE-TENSION SECTION is not supported" in imp.unsupported
    assert imp.unsupported[-1] == (f"{deck}:{at}: *CLOAD on 9999, the reference node of {deck}:{pre}: *PRE-TENSION "
                                   "SECTION; with --ignore-unsupported the load is left out")
    deck.write_text(deck.read_text().replace("9999, 1, -10.", "9998, 1, -10.").replace("9999, 0., 0., 0.",
                                                                                      "9999, 0., 0., 0.\n9998, 1., 0., 0."))
    with pytest.raises(DeckError, match=r"pret\.inp:\d+: \*CLOAD on nodes of no element \(9998\)"):
        import_deck(deck, tmp_path / "b" / "p.toml")


def test_node_line_without_coordinates_is_at_the_origin(tmp_path):
    """A *NODE line of its label alone (CalculiX's planestress3.inp) or with fewer than three coordinates: the rest
    are 0, as CalculiX's reader (nodes.f) sets them."""
    deck = tmp_path / "n.inp"
    deck.write_text("*NODE, NSET=NALL\n1\n2, 10.\n3 ,10,5\n4, 1, 2, 3\n")
    m = read_model(deck)
    assert m.node_labels.tolist() == [1, 2, 3, 4]
    np.testing.assert_array_equal(m.X, [[0, 0, 0], [10, 0, 0], [10, 5, 0], [1, 2, 3]])


def test_dsload_is_the_pressure_on_the_surface_faces(tmp_path):
    """*DSLOAD 'surface, P, magnitude' (CalculiX's pressure on an element surface) loads the surface's faces as *DLOAD
    Pn on them does: the same displacements (CPE4 blocks pressed together; the surface's faces on four lines of one
    face number, which an early version lost but the last of); a load type other than P is listed as unsupported, a
    node surface is one line (exit 2)."""
    from test_planar_laws import _deck

    base = _deck("CPE4", "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n500., 0.05\n")
    ds = base.replace("*DLOAD\nTOPU, P3, 1.0", "*DSLOAD\nTOPS, P, 1.0").replace(
        "*SURFACE, NAME=MAST", "*SURFACE, NAME=TOPS\n13, S3\n14, S3\n15, S3\n16, S3\n*SURFACE, NAME=MAST")
    assert ds != base
    u = []
    for name, text in (("dload", base), ("dsload", ds)):
        deck = tmp_path / f"{name}.inp"
        deck.write_text(text)
        imp = import_deck(deck, tmp_path / name / "p.toml")
        assert not imp.unsupported
        res = load_problem(imp.problem).run(out=tmp_path / f"o_{name}", quiet=True)
        assert res.exit_code == 0
        u.append(np.asarray(res.u))
    np.testing.assert_allclose(u[1], u[0], rtol=0, atol=1e-14)
    deck = tmp_path / "bad.inp"
    deck.write_text(ds.replace("TOPS, P, 1.0", "TOPS, TRVEC, 1.0, 0., 1., 0."))
    assert "*DSLOAD type TRVEC" in " ".join(import_deck(deck, tmp_path / "bad" / "p.toml").unsupported)
    deck.write_text(ds.replace("*SURFACE, NAME=TOPS\n13, S3\n14, S3\n15, S3\n16, S3",
                               "*SURFACE, NAME=TOPS, TYPE=NODE\n26"))
    with pytest.raises(DeckError, match=r"bad\.inp:\d+: \*DSLOAD: the surface TOPS is a node surface"):
        import_deck(deck, tmp_path / "bad2" / "p.toml")


def test_a_node_defined_again_takes_its_last_place(tmp_path):
    """A *NODE card that defines a node again (cgx's mean-rotation files do): the last coordinates hold, as in
    CalculiX, said in a note; a *SECTION PRINT on a surface no *SURFACE defines prints nothing, said in a note (CalculiX
    warns and goes on)."""
    from test_planar_laws import _deck

    base = _deck("CPE4", "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n500., 0.05\n")
    text = base.replace("*ELEMENT, TYPE=CPE4, ELSET=EL", "*NODE\n30, 9., 9., 0.\n30, 1., 1., 0.\n"
                        "*ELEMENT, TYPE=CPE4, ELSET=EL", 1).replace(
        "*END STEP", "*SECTION PRINT, SURFACE=NOPE, NAME=S1\nSOF\n*END STEP")
    deck = tmp_path / "again.inp"
    deck.write_text(text)
    imp = import_deck(deck, tmp_path / "a" / "p.toml")
    assert not imp.unsupported
    assert any("node(s) defined again (the first 30" in n and "the last definition holds" in n for n in imp.notes)
    assert any("*SECTION PRINT names the surface 'NOPE'" in n for n in imp.notes)
    mesh = load_problem(imp.problem).bodies[1].mesh
    np.testing.assert_allclose(mesh.points.min(axis=0)[:2], [0.0, 0.5])
    np.testing.assert_allclose(mesh.points.max(axis=0)[:2], [1.0, 1.0])
