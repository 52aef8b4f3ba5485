"""Shell elements of decks made into solid-shells (io/deck_shells.py; docs/input.md, "Abaqus and CalculiX decks"):
an S4 plate cantilever against the plate generator's solid-shells and the closed form, S8R, *NODAL THICKNESS, a
pinned edge against a clamp, an SPOS contact surface, and the refusals (one line, exit 2)."""

from __future__ import annotations

import contextlib
import io
from pathlib import Path
from types import SimpleNamespace

import tomllib

import numpy as np
import pytest

from covcontact.cli import main
from covcontact.io.deck import DeckError
from covcontact.io.deck_import import import_deck
from covcontact.io.loader import load_problem

E, NU = 210000.0, 0.3


def plate_deck(kind="S4", nx=10, ny=4, L=10.0, B=8.0, t=0.1, P=1e-4, fix="1, 6", section=None, extra="",
               loads=True, both_ends=False) -> str:
    """A cantilever plate [0, L] x [0, B] of S4 (or S8R, S8; or S6: each square of the quadratic grid two triangles
    across its diagonal) elements clamped at x = 0 (FIX, dofs ``fix``), a total force P along z on the edge x = L
    (TIP) as consistent nodal loads; ``both_ends``: the edge x = L held alike and the force on the line x = L / 2
    instead (nx even)."""
    quad8 = kind.startswith("S8") or kind == "S6"
    mx, my = (2 * nx, 2 * ny) if quad8 else (nx, ny)

    def lab(i, j):
        return 1 + i + j * (mx + 1)

    used, els = set(), []
    for j in range(ny):
        for i in range(nx):
            if kind == "S6":
                a, b = 2 * i, 2 * j
                for n in ([lab(a, b), lab(a + 2, b), lab(a + 2, b + 2), lab(a + 1, b), lab(a + 2, b + 1),
                           lab(a + 1, b + 1)],
                          [lab(a, b), lab(a + 2, b + 2), lab(a, b + 2), lab(a + 1, b + 1), lab(a + 1, b + 2),
                           lab(a, b + 1)]):
                    used.update(n)
                    els.append(n)
                continue
            if quad8:
                a, b = 2 * i, 2 * j
                n = [lab(a, b), lab(a + 2, b), lab(a + 2, b + 2), lab(a, b + 2), lab(a + 1, b), lab(a + 2, b + 1),
                     lab(a + 1, b + 2), lab(a, b + 1)]
            else:
                n = [lab(i, j), lab(i + 1, j), lab(i + 1, j + 1), lab(i, j + 1)]
            used.update(n)
            els.append(n)
    lines = ["*NODE, NSET=NALL"]
    lines += [f"{lab(i, j)}, {L * i / mx!r}, {B * j / my!r}, 0.0" for j in range(my + 1) for i in range(mx + 1)
              if lab(i, j) in used]
    lines.append(f"*ELEMENT, TYPE={kind}, ELSET=PLATE")
    lines += [", ".join(map(str, [k + 1, *n])) for k, n in enumerate(els)]
    fixn = [lab(0, j) for j in range(my + 1) if lab(0, j) in used]
    tipn = [lab(mx, j) for j in range(my + 1) if lab(mx, j) in used]
    if both_ends:
        fixn += tipn
        tipn = [lab(mx // 2, j) for j in range(my + 1) if lab(mx // 2, j) in used]
    lines += ["*NSET, NSET=FIX", ", ".join(map(str, fixn)), "*NSET, NSET=TIP", ", ".join(map(str, tipn))]
    lines += ["*MATERIAL, NAME=STEEL", "*ELASTIC", f"{E}, {NU}",
              section or f"*SHELL SECTION, ELSET=PLATE, MATERIAL=STEEL\n{t}", extra,
              "*STEP", "*STATIC", "*BOUNDARY", f"FIX, {fix}"]
    if loads:
        w: dict[int, float] = {}
        for k in range(ny):
            nodes = tipn[2 * k: 2 * k + 3] if quad8 else tipn[k: k + 2]
            for n, s in zip(nodes, (1 / 6, 2 / 3, 1 / 6) if quad8 else (0.5, 0.5), strict=True):
                w[n] = w.get(n, 0.0) + s * P / ny
        lines += ["*CLOAD"] + [f"{n}, 3, {v!r}" for n, v in w.items()]
    lines += ["*NODE PRINT, NSET=TIP", "U", "*NODE PRINT, NSET=FIX", "RF", "*END STEP"]
    return "\n".join(x for x in lines if x) + "\n"


def _cli(args: list[str]) -> SimpleNamespace:
    """``covcontact ARGS`` in this process (a subprocess would pay the interpreter's and the kernels' start each
    time): its exit code and what it wrote to standard error."""
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        code = main([str(a) for a in args])
    return SimpleNamespace(returncode=code, stderr=err.getvalue())


def _run_deck(tmp_path: Path, text: str, name: str = "p") -> tuple[Path, SimpleNamespace]:
    deck = tmp_path / f"{name}.inp"
    deck.write_text(text)
    proc = _cli(["run", deck, "--out", tmp_path / name, "--quiet"])
    return tmp_path / name / f"{name}.dat", proc


def _dat(path: Path) -> dict[str, dict[int, np.ndarray]]:
    out: dict[str, dict[int, np.ndarray]] = {}
    cur = None
    for line in path.read_text().splitlines():
        if "displacements" in line or "forces" in line:
            cur = "U" if "displacements" in line else "RF"
            continue
        f = line.split()
        if cur and len(f) == 4 and f[0].isdigit():
            out.setdefault(cur, {})[int(f[0])] = np.array([float(x) for x in f[1:]])
    return out


def _generator_problem(tmp_path: Path, nx, ny, L, B, t, P) -> Path:
    """The same plate from the plate generator as solid-shells, with the deck's clamp as the import maps it (x, y of
    both layers held, u_z bottom + u_z top = 0) and the tip force shared by the layers."""
    from covcontact.mesh.generators import plate

    mesh = plate(L, B, t, nx, ny, "hex8", origin=(0.0, 0.0, -t / 2))
    X = mesh.points
    clamp = np.flatnonzero(np.isclose(X[:, 0], 0.0))
    tip = np.flatnonzero(np.isclose(X[:, 0], L))
    bottom = clamp[X[clamp, 2] < 0.0]
    top = [int(clamp[(X[clamp, 2] > 0.0) & np.isclose(X[clamp, 1], X[b, 1])][0]) for b in bottom]
    sets = {f"b{k}": {"nodes": [int(b)]} for k, b in enumerate(bottom)}
    sets |= {f"t{k}": {"nodes": [t_]} for k, t_ in enumerate(top)}
    sets |= {f"f{k}": {"nodes": [int(n)]} for k, n in enumerate(tip)}
    text = ["[problem]", 'name = "gen"', "[[bodies]]", 'name = "p"',
            f'mesh = {{ generator = "plate", lx = {L}, ly = {B}, t = {t}, nx = {nx}, ny = {ny}, '
            f"origin = [0.0, 0.0, {-t / 2!r}] }}", 'formulation = "solid-shell"',
            f'material = {{ model = "svk", E = {E}, nu = {NU} }}',
            "sets = { " + ", ".join(f'{k} = {{ nodes = {v["nodes"]} }}' for k, v in sets.items()) + " }",
            "[[dirichlet]]", 'set = "p.xmin"', 'components = "xy"', "value = 0.0"]
    for k in range(len(bottom)):
        text += ["[[equation]]", f'terms = [["p.t{k}", "z", 1.0], ["p.b{k}", "z", 1.0]]']
    for k, n in enumerate(tip):
        y = X[n, 1]
        share = 0.5 if np.isclose(y, 0.0) or np.isclose(y, B) else 1.0
        text += ["[[force]]", f'set = "p.f{k}"', f"value = [0.0, 0.0, {share * P / ny / 2!r}]"]
    text += ["[steps]", "initial = 1.0", "[output]", "vtu = false"]
    path = tmp_path / "gen.toml"
    path.write_text("\n".join(text) + "\n")
    return path


def test_s4_cantilever_against_the_plate_generator_and_the_closed_form(tmp_path):
    """An S4 plate clamped (1-6) at one edge with a tip force: its import (mesh built in memory, and read back from
    the surface file) gives the plate generator's solid-shell result to 1e-10 with the clamp as CalculiX expands it;
    the tip deflection is within 5 % of Euler-Bernoulli's with the plate modulus E / (1 - nu^2) (a wide plate:
    B = 0.8 L); U of a shell node is the mean of its two layers, RF the sum (the clamp's reactions balance P)."""
    nx, ny, L, B, t, P = 10, 4, 10.0, 8.0, 0.1, 1e-4
    dat, proc = _run_deck(tmp_path, plate_deck(nx=nx, ny=ny, L=L, B=B, t=t, P=P))
    assert proc.returncode == 0, proc.stderr
    assert "drilling rotation" in proc.stderr  # (dof 6 of a flat shell in the x-y plane: dropped, said)
    got = _dat(dat)
    w_deck = np.mean([u[2] for u in got["U"].values()])
    assert sum(r[2] for r in got["RF"].values()) == pytest.approx(-P, rel=1e-6)
    ref = load_problem(_generator_problem(tmp_path, nx, ny, L, B, t, P)).run(out=tmp_path / "gen", quiet=True)
    U = ref.u.reshape(-1, 3)
    from covcontact.mesh.generators import plate

    X = plate(L, B, t, nx, ny, "hex8", origin=(0.0, 0.0, -t / 2)).points
    w_gen = U[np.isclose(X[:, 0], L), 2].mean()
    assert w_deck == pytest.approx(w_gen, rel=1e-6)  # (the .dat's seven digits)
    imp = import_deck(tmp_path / "p.inp", tmp_path / "imp" / "p.toml")
    alone = load_problem(imp.problem).run(out=tmp_path / "alone", quiet=True)  # (the surface file read back)
    (mesh,) = imp.read.values()
    np.testing.assert_allclose(mesh.points, X, rtol=0, atol=1e-14)  # (the generator's nodes, in its order)
    np.testing.assert_allclose(alone.u, ref.u, rtol=0, atol=1e-10 * np.abs(ref.u).max())
    closed = P * L ** 3 / (3.0 * E / (1.0 - NU ** 2) * B * t ** 3 / 12.0)
    assert w_deck == pytest.approx(closed, rel=0.05)


def test_s8r_and_a_pinned_edge_against_a_clamp(tmp_path):
    """S8R plates (quad8 -> hex18 with the centre node): a cantilever against the closed form; a strip supported at
    both ends under a centre line force, pinned (1-3: the mid-surface held, u_bottom + u_top = 0 per component) and
    clamped (1-6), against F L^3 / (48 E' I) and a quarter of it."""
    clamp, proc = _run_deck(tmp_path, plate_deck("S8R", nx=4, ny=1, B=2.0, P=1e-4), "clamp")
    assert proc.returncode == 0, proc.stderr
    w_clamp = np.mean([u[2] for u in _dat(clamp)["U"].values()])
    Ep, I = E / (1 - NU ** 2), 2.0 * 0.1 ** 3 / 12.0
    assert 1e-4 * 1e3 / (3.0 * Ep * I) < w_clamp < 1e-4 * 1e3 / (3.0 * E * I) * 1.01  # (a strip: E' < . < E)
    res = {}
    for name, dofs in (("pinned", "1, 3"), ("clamped", "1, 6")):
        dat, proc = _run_deck(tmp_path, plate_deck("S8R", nx=8, ny=1, B=2.0, P=1e-4, fix=dofs, both_ends=True), name)
        assert proc.returncode == 0, proc.stderr
        res[name] = np.mean([u[2] for u in _dat(dat)["U"].values()])
    pinned = 1e-4 * 1e3 / (48 * Ep * I)
    assert res["pinned"] == pytest.approx(pinned, rel=0.1)
    assert res["clamped"] == pytest.approx(pinned / 4.0, rel=0.1)


def test_nodal_thickness(tmp_path):
    """*SHELL SECTION, NODAL THICKNESS with *NODAL THICKNESS: the thickness per node (a uniform one gives the
    section's result exactly); without the parameter the section's thickness holds (a note), as in CalculiX."""
    base = plate_deck(nx=4, ny=1, B=2.0)
    nodal = base.replace("*SHELL SECTION, ELSET=PLATE, MATERIAL=STEEL\n0.1",
                         "*SHELL SECTION, ELSET=PLATE, MATERIAL=STEEL, NODAL THICKNESS\n*NODAL THICKNESS\nNALL, 0.1")
    a = import_deck(_write(tmp_path / "a.inp", base), tmp_path / "a" / "a.toml")
    b = import_deck(_write(tmp_path / "b.inp", nodal), tmp_path / "b" / "b.toml")
    (ma,), (mb,) = a.read.values(), b.read.values()
    np.testing.assert_array_equal(ma.points, mb.points)
    thick = nodal.replace("NALL, 0.1", "NALL, 0.1\nTIP, 0.2")
    c = import_deck(_write(tmp_path / "c.inp", thick), tmp_path / "c" / "c.toml")
    (mc,) = c.read.values()
    n = mc.points.shape[0] // 2
    t = np.linalg.norm(mc.points[n:] - mc.points[:n], axis=1)
    assert sorted(set(np.round(t, 12))) == [0.1, 0.2]
    assert "thickness = [" in c.problem.read_text()
    ignored = base.replace("*STEP", "*NODAL THICKNESS\nTIP, 0.2\n*STEP")
    d = import_deck(_write(tmp_path / "d.inp", ignored), tmp_path / "d" / "d.toml")
    (md,) = d.read.values()
    np.testing.assert_array_equal(md.points, ma.points)
    assert any("no NODAL THICKNESS parameter" in note for note in d.notes)


def _write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


def test_spos_contact_surface_and_cload_split(tmp_path):
    """*SURFACE with SPOS (and S2 of a shell, CalculiX's name) is the top face set of those elements' solid-shells,
    usable in *CONTACT PAIR; a *CLOAD on a shell node is split equally between its two layers."""
    text = plate_deck(nx=2, ny=1, B=2.0)
    text = text.replace("*MATERIAL", "*SURFACE, NAME=UP\nPLATE, SPOS\n*SURFACE, NAME=DOWN\nPLATE, S1\n*MATERIAL")
    imp = import_deck(_write(tmp_path / "s.inp", text), tmp_path / "s" / "s.toml")
    (mesh,) = imp.read.values()
    n = mesh.points.shape[0] // 2
    assert np.all(mesh.face_sets["UP"] >= n) and mesh.face_sets["UP"].shape == (2, 4)
    assert np.all(mesh.face_sets["DOWN"] < n) and mesh.face_sets["DOWN"].shape == (2, 4)
    up = mesh.points[mesh.face_sets["UP"]]  # (outward: along +z, the elements' normal)
    normal = np.cross(up[:, 1] - up[:, 0], up[:, 3] - up[:, 0])
    assert np.all(normal[:, 2] > 0)
    toml = imp.problem.read_text()
    assert 'faces = { UP = [["__UP_1", "top"]], DOWN = [["__DOWN_1", "bottom"]] }' in toml
    assert ", 3, 5e-05" in text and "value = [0.0, 0.0, 2.5e-05]" in toml  # (half on each layer)


def test_sts_contact_of_a_block_on_a_shell(tmp_path):
    """A C3D8 block pressed onto an S4 plate's SPOS face (surface-to-surface): the contact force balances the push."""
    plate = plate_deck(nx=4, ny=2, L=4.0, B=4.0, t=0.2, loads=False, fix="1, 3")
    plate = plate.replace("*NSET, NSET=FIX\n", "*NSET, NSET=FIX\n").replace("*MATERIAL", """*NODE
1001, 1.5, 1.5, 0.1
1002, 2.5, 1.5, 0.1
1003, 2.5, 2.5, 0.1
1004, 1.5, 2.5, 0.1
1005, 1.5, 1.5, 1.1
1006, 2.5, 1.5, 1.1
1007, 2.5, 2.5, 1.1
1008, 1.5, 2.5, 1.1
*ELEMENT, TYPE=C3D8, ELSET=BLOCK
1001, 1001, 1002, 1003, 1004, 1005, 1006, 1007, 1008
*NSET, NSET=BTOP
1005, 1006, 1007, 1008
*SURFACE, NAME=UP
PLATE, SPOS
*SURFACE, NAME=BBOT
BLOCK, S1
*SOLID SECTION, ELSET=BLOCK, MATERIAL=STEEL
*SURFACE INTERACTION, NAME=SI
*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR
1.0e6
*CONTACT PAIR, INTERACTION=SI, TYPE=SURFACE TO SURFACE
BBOT, UP
*MATERIAL""")
    plate = plate.replace("*BOUNDARY\nFIX, 1, 3", "*BOUNDARY\nFIX, 1, 3\nNALL, 1, 2\nBTOP, 1, 2\nBTOP, 3, 3, -1e-3")
    plate = plate.replace("*NODE PRINT, NSET=TIP\nU\n", "")
    plate = plate.replace("*NODE PRINT, NSET=FIX\nRF", "*NODE PRINT, NSET=FIX, TOTALS=ONLY\nRF\n"
                                                       "*NODE PRINT, NSET=BTOP, TOTALS=ONLY\nRF")
    dat, proc = _run_deck(tmp_path, plate, "sts")
    assert proc.returncode == 0, proc.stderr
    totals = [ln for ln in dat.read_text().splitlines() if ln.startswith("      ") and ln.strip()]
    fix, top = (np.array([float(v) for v in ln.split()]) for ln in totals[-2:])
    assert top[2] < 0 and fix[2] == pytest.approx(-top[2], rel=1e-4)


#: produced by running CalculiX 2.20 (Debian's ccx) on plate_deck("S6", nx=10, ny=4) (its CLOAD values written with
#: ten digits, which ccx's card reader needs): the mean tip deflection over the nine tip nodes
_CCX_S6_TIP = 2.190617e-04


def test_s6_plate_is_the_s8r_plate(tmp_path):
    """S6 (six-node triangles, each split into three quad4 solid-shells at the point of its quadratic surface at the
    centroid): the cantilever plate of 80 S6 gives the tip deflection of the same plate of 40 S8R within 0.5 %
    (measured 0.10 %) and CalculiX's S6 run within 3 % (measured 2.6 %, where covcontact's S8R is 1.7 % above
    CalculiX's S8R); the reactions balance the load. Imported, the surface file has S6 cells and reads back to the
    same result (written as STRI65, the same six-node triangle)."""
    s6, proc = _run_deck(tmp_path, plate_deck("S6", nx=10, ny=4), "s6")
    assert proc.returncode == 0, proc.stderr
    s8, proc = _run_deck(tmp_path, plate_deck("S8R", nx=10, ny=4), "s8")
    assert proc.returncode == 0, proc.stderr
    tip = [21 * k for k in range(1, 10)]
    w6, w8 = (np.mean([_dat(d)["U"][n][2] for n in tip]) for d in (s6, s8))
    assert w6 == pytest.approx(w8, rel=5e-3)
    assert w6 == pytest.approx(_CCX_S6_TIP, rel=3e-2)
    assert sum(r[2] for r in _dat(s6)["RF"].values()) == pytest.approx(-1e-4, rel=1e-6)
    imp = import_deck(tmp_path / "s6.inp", tmp_path / "imp" / "s6.toml")
    assert "*ELEMENT, TYPE=STRI65" in next(iter(imp.read)).read_text()
    res = load_problem(imp.problem).run(out=tmp_path / "alone", quiet=True)
    assert res.exit_code == 0
    (mesh,) = imp.read.values()
    X = mesh.points
    w = res.u.reshape(-1, 3)[np.isclose(X[:, 0], 10.0), 2].mean()
    assert w == pytest.approx(w6, rel=1e-5)


#: produced by running CalculiX 2.20 (Debian's ccx) on the deck of test_prescribed_translation_of_free_shell_nodes's
#: first step: the clamp's total force along z
_CCX_TIP_CLAMP_Z = -4.573211e-04


def test_prescribed_translation_of_free_shell_nodes(tmp_path):
    """A non-zero *BOUNDARY on dof 3 of the tip nodes of the S4 cantilever plate, their rotations free: CalculiX
    prescribes the mean of each node's expansion, here the equation u_b + u_t = 2 v (a right-hand side that follows
    the steps: 0.001, then 0.002 in a second step). The tip's mean deflection is v exactly at both step ends; the
    clamp's force is within 3 % of CalculiX's (measured 2.1 %, the plate's stiffness as in the tip-load comparison
    above) and doubles with v."""
    text = plate_deck("S4", nx=10, ny=4, loads=False).replace("*BOUNDARY\nFIX, 1, 6",
                                                               "*BOUNDARY\nFIX, 1, 6\nTIP, 3, 3, 0.001")
    text = text.replace("*NODE PRINT, NSET=FIX\nRF", "*NODE PRINT, NSET=FIX, TOTALS=ONLY\nRF")
    text += "*STEP\n*STATIC\n*BOUNDARY\nTIP, 3, 3, 0.002\n*NODE PRINT, NSET=TIP\nU\n" \
            "*NODE PRINT, NSET=FIX, TOTALS=ONLY\nRF\n*END STEP\n"
    dat, proc = _run_deck(tmp_path, text, "tip")
    assert proc.returncode == 0, proc.stderr
    blocks = dat.read_text().split("displacements")[1:]
    forces = [float(b.split("total force")[1].split("\n", 1)[1].split()[2]) for b in blocks]
    for block, v in zip(blocks, (0.001, 0.002), strict=True):
        rows = [ln.split() for ln in block.split("total force")[0].splitlines() if len(ln.split()) == 4]
        assert len(rows) == 5 and all(float(r[3]) == pytest.approx(v, rel=1e-6) for r in rows)
    assert forces[0] == pytest.approx(_CCX_TIP_CLAMP_Z, rel=3e-2)
    assert forces[1] == pytest.approx(2.0 * forces[0], rel=1e-3)
    imp = import_deck(tmp_path / "tip.inp", tmp_path / "imp" / "tip.toml")
    prob = tomllib.loads(imp.problem.read_text())
    means = [e for e in prob["equation"] if e.get("value")]  # (the clamp's means are at zero)
    assert len(means) == 5 and all(e["value"] == pytest.approx(0.002) for e in means)
    assert prob["stages"][0]["targets"] == {e["name"]: pytest.approx(0.004) for e in means}


@pytest.mark.parametrize("change, message", [
    (("TYPE=S4,", "TYPE=S9R5,"), "TYPE=S9R5 is not supported"),
    (("FIX, 1, 6", "FIX, 4, 4"), "rotation dof 4 of shell node 1 without the translation 2"),
    (("MATERIAL=STEEL\n0.1", "MATERIAL=STEEL\n"), "needs the thickness on its data line"),
    (("MATERIAL=STEEL\n0.1", "MATERIAL=STEEL\n-0.1"), "the thickness must be positive"),
    (("MATERIAL=STEEL\n0.1", "MATERIAL=STEEL, OFFSET=0.7\n0.1"), "OFFSET=0.7"),
])
def test_refusals_are_one_line_exit_2(tmp_path, change, message):
    text = plate_deck(nx=2, ny=1, B=2.0).replace(*change)
    deck = _write(tmp_path / "bad.inp", text)
    proc = _cli(["run", deck, "--out", tmp_path / "o", "--quiet"])
    assert proc.returncode == 2, proc.stderr
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip() and "note:" not in ln]
    assert len(lines) == 1 and message in lines[0], proc.stderr
    with pytest.raises(DeckError):
        import_deck(deck, tmp_path / "i" / "bad.toml")


def test_symmetry_plane_maps_onto_both_layers(tmp_path):
    """XSYMM-like 1, 5, 6 on a flat shell in the x-y plane: both layers' x held (a symmetry plane); rotations 4, 5
    with the translations free: the tangential components of u_top - u_bottom vanish (equations)."""
    imp = import_deck(_write(tmp_path / "x.inp", plate_deck(nx=2, ny=1, B=2.0, fix="1, 1\nFIX, 5, 6")),
                      tmp_path / "x" / "x.toml")
    toml = imp.problem.read_text()
    assert 'components = "x"' in toml and "[[equation]]" not in toml
    imp = import_deck(_write(tmp_path / "r.inp", plate_deck(nx=2, ny=1, B=2.0, fix="4, 5")),
                      tmp_path / "r" / "r.toml")
    toml = imp.problem.read_text()
    assert toml.count("[[equation]]") == 2 * 2 and "[[dirichlet]]" not in toml


TIED_EDGE = """*NODE, NSET=NALL
1, 0.0, 0.0, 0.0
2, 1.0, 0.0, 0.0
3, 1.0, 1.0, 0.0
4, 0.0, 1.0, 0.0
5, 0.0, 0.0, 1.0
6, 1.0, 0.0, 1.0
7, 1.0, 1.0, 1.0
8, 0.0, 1.0, 1.0
11, 1.0, 0.0, 0.5
12, 2.0, 0.0, 0.5
13, 2.0, 1.0, 0.5
14, 1.0, 1.0, 0.5
15, 3.0, 0.0, 0.5
16, 3.0, 1.0, 0.5
*ELEMENT, TYPE=C3D8, ELSET=SOLID
1, 1, 2, 3, 4, 5, 6, 7, 8
*ELEMENT, TYPE=S4, ELSET=SHELL
2, 11, 12, 13, 14
3, 12, 15, 16, 13
*NSET, NSET=FIX
1, 2, 3, 4, 5, 6, 7, 8
*NSET, NSET=TIP
15, 16
*SURFACE, NAME=SOLIDFACE
SOLID, S4
*SURFACE, NAME=SHELLEDGE
2, S6
*MATERIAL, NAME=STEEL
*ELASTIC
210000, 0.3
*SOLID SECTION, ELSET=SOLID, MATERIAL=STEEL
*SHELL SECTION, ELSET=SHELL, MATERIAL=STEEL
0.1
*TIE, NAME=T1, POSITION TOLERANCE=0.1
SHELLEDGE, SOLIDFACE
*BOUNDARY
FIX, 1, 3
*STEP, NLGEOM
*STATIC
1.0, 1.0
*CLOAD
TIP, 3, -1.0
*NODE PRINT, NSET=TIP
U
*END STEP
"""


#: TIED_EDGE with S8R shells: the mid-nodes 21 .. 27 (24 on the tied edge, 26 at the tip)
TIED_EDGE_S8R = TIED_EDGE.replace("16, 3.0, 1.0, 0.5\n", "16, 3.0, 1.0, 0.5\n" + "".join(
    f"{n}, {x}, {y}, 0.5\n" for n, x, y in ((21, 1.5, 0.0), (22, 2.0, 0.5), (23, 1.5, 1.0), (24, 1.0, 0.5),
                                              (25, 2.5, 0.0), (26, 3.0, 0.5), (27, 2.5, 1.0)))).replace(
    "*ELEMENT, TYPE=S4, ELSET=SHELL\n2, 11, 12, 13, 14\n3, 12, 15, 16, 13",
    "*ELEMENT, TYPE=S8R, ELSET=SHELL\n2, 11, 12, 13, 14, 21, 22, 23, 24\n3, 12, 15, 16, 13, 25, 26, 27, 22").replace(
    "*NSET, NSET=TIP\n15, 16", "*NSET, NSET=TIP\n15, 16, 26")


@pytest.mark.parametrize("kind", ["S4", "S8R"])
def test_shell_edge_tied_to_a_solid_is_a_clamp(tmp_path, kind):
    """A strip whose edge (S6: from its node 4 to node 1) is tied (*TIE) to the face of a C3D8 block held in place:
    the edge is clamped, so the tip deflects as the same strip clamped at that edge (its edge nodes held in dofs 1-5)
    to 0.5 % (S4, measured 0.17 %: the tie is a penalty, 100 E / h with h the shell's thickness, the smaller facet
    dimension; with the contact pairs' 10 E / h of the block's face it was 17 % softer). S8R: the six-node side face
    of the edge as its two 4-node halves, the slave of the tie (measured 0.24 %)."""
    deck = TIED_EDGE if kind == "S4" else TIED_EDGE_S8R
    dat, proc = _run_deck(tmp_path, deck, "tied")
    assert proc.returncode == 0, proc.stderr
    tied = _dat(dat)["U"][15][2]
    clamp = deck.replace("*TIE, NAME=T1, POSITION TOLERANCE=0.1\nSHELLEDGE, SOLIDFACE\n", "").replace(
        "FIX, 1, 3", "FIX, 1, 3\n11, 1, 5\n14, 1, 5" + ("\n24, 1, 5" if kind == "S8R" else ""))
    dat, proc = _run_deck(tmp_path, clamp, "clamped")
    assert proc.returncode == 0, proc.stderr
    clamped = _dat(dat)["U"][15][2]
    assert clamped < -0.2 and tied == pytest.approx(clamped, rel=5e-3)


def test_shell_edge_faces():
    """extrude_surface's edge face sets: the lateral face along edge k of a quad4 cell (its corners k, k + 1 as
    given, both layers), outward; an edge shared by two cells has none (one line), nor have triangles."""
    from covcontact.mesh.shell import ShellMeshError, extrude_surface

    pts = np.array([[1, 0, .5], [2, 0, .5], [2, 1, .5], [1, 1, .5], [3, 0, .5], [3, 1, .5]], float)
    cells = np.array([[0, 1, 2, 3], [1, 4, 5, 2]])
    m = extrude_surface(pts, "quad4", cells, 0.1, face_sets={"E": [(np.array([0]), "edge4")],
                                                              "F": [(np.array([1]), "edge2")]})
    for name, normal in (("E", (-1.0, 0.0, 0.0)), ("F", (1.0, 0.0, 0.0))):
        (face,) = m.face_sets[name]
        x = m.points[face]
        n = np.cross(x[1] - x[0], x[3] - x[0])
        np.testing.assert_allclose(n / np.linalg.norm(n), normal, atol=1e-12)
        assert set(np.round(x[:, 2], 12)) == {0.45, 0.55}
    with pytest.raises(ShellMeshError, match="shared with another cell"):
        extrude_surface(pts, "quad4", cells, 0.1, face_sets={"E": [(np.array([0]), "edge2")]})
    with pytest.raises(ShellMeshError, match="these cells are tri3"):
        extrude_surface(pts, "tri3", np.array([[0, 1, 2]]), 0.1, face_sets={"E": [(np.array([0]), "edge1")]})


def test_side_faces_of_quadratic_shells_are_halves():
    """quad8 cells (hex18 solid-shells, whose side faces have six nodes): the side face along an edge (`edge4`, a
    deck's S6), the `edges` set and a node set's side faces come as 4-node halves, corner to mid-node, outward; their
    areas add up to the edge's length times the thickness."""
    from covcontact.mesh.shell import extrude_surface

    ids: dict = {}
    pts: list = []

    def node(x, y):
        if (x, y) not in ids:
            ids[x, y] = len(pts)
            pts.append([x, y, 0.0])
        return ids[x, y]

    cells = np.array([[node(i, 0), node(i + 1, 0), node(i + 1, 1), node(i, 1), node(i + 0.5, 0), node(i + 1, 0.5),
                       node(i + 0.5, 1), node(i, 0.5)] for i in range(2)])
    left = [ids[0, 0], ids[0, 0.5], ids[0, 1]]
    m = extrude_surface(np.array(pts, float), "quad8", cells, 0.1, node_sets={"left": left},
                        face_sets={"E": [(np.array([0]), "edge4")]})

    def area_normals(faces):
        x = m.points[faces]
        n = np.cross(x[:, 1] - x[:, 0], x[:, 3] - x[:, 0])
        return np.linalg.norm(n, axis=1).sum(), n / np.linalg.norm(n, axis=1)[:, None]

    assert m.face_sets["edges"].shape == (12, 4)
    assert area_normals(m.face_sets["edges"])[0] == pytest.approx(6 * 0.1, rel=1e-12)
    for name in ("E", "left"):
        area, normals = area_normals(m.face_sets[name])
        assert m.face_sets[name].shape == (2, 4) and area == pytest.approx(0.1, rel=1e-12)
        np.testing.assert_allclose(normals, [[-1.0, 0.0, 0.0]] * 2, atol=1e-12)


def test_edges_of_other_shells_are_refused(tmp_path):
    text = TIED_EDGE.replace("*ELEMENT, TYPE=S4, ELSET=SHELL\n2, 11, 12, 13, 14\n3, 12, 15, 16, 13",
                             "*ELEMENT, TYPE=S3, ELSET=SHELL\n2, 11, 12, 14\n3, 12, 15, 16")
    with pytest.raises(DeckError, match="S6 of an S3 element is an edge: covcontact reads the edges of S4, S4R, S8"):
        import_deck(_write(tmp_path / "s3.inp", text), tmp_path / "i" / "s3.toml")


def test_s8_edges_as_master(tmp_path):
    """The edge of S8R shells as the master of a *TIE: its six-node side faces are their 4-node halves, exact where
    the edge is straight (a note says it): the block's face (the slave) holds the edge's nodes in place (within 1e-3
    of the tip's deflection; the block's single face, coarser than the master, leaves the edge's rotation freer than
    a clamp: 10 % more deflection, which is why the finer side is the slave in test_shell_edge_tied_to_a_solid_is_a_
    clamp); a curved edge (its mid-side node off the chord) is listed as unsupported, one line naming the pair."""
    text = TIED_EDGE_S8R.replace("SHELLEDGE, SOLIDFACE", "SOLIDFACE, SHELLEDGE")
    for n, (x, y) in enumerate([(0, 0), (1, 0), (1, 1), (0, 1)] * 2):  # (the block as thick as the shell: its
        z = ("0.0", "0.45") if n < 4 else ("1.0", "0.55")                # face is the edge's side face)
        text = text.replace(f"\n{n + 1}, {x:.1f}, {y:.1f}, {z[0]}\n", f"\n{n + 1}, {x:.1f}, {y:.1f}, {z[1]}\n")
    text = text.replace("*NSET, NSET=TIP\n15, 16, 26", "*NSET, NSET=TIP\n15, 16, 26, 11, 14, 24")
    dat, proc = _run_deck(tmp_path, text, "m")
    assert proc.returncode == 0, proc.stderr
    assert "the master surface SHELLEDGE holds straight edges of S8/S8R elements" in proc.stderr, proc.stderr
    U = _dat(dat)["U"]
    assert U[15][2] < -0.2 and all(np.linalg.norm(U[k]) < 1e-3 * abs(U[15][2]) for k in (11, 14, 24))
    curved = _write(tmp_path / "c.inp", text.replace("24, 1.0, 0.5, 0.5", "24, 1.05, 0.5, 0.5"))
    proc = _cli(["run", curved, "--out", tmp_path / "c", "--quiet"])
    assert proc.returncode == 2
    assert "the master surface SHELLEDGE holds curved edges of S8/S8R elements" in proc.stderr, proc.stderr




#: produced by running CalculiX 2.20 (Debian's ccx) on test_edge_load_ednor's decks: u_x of the tip's corner node
#: (11 of the S4 plate, 21 of the S8R plate) under EDNOR2 = -1 on the tip elements' edges
_CCX_EDNOR_TIP_X = {"S4": 4.713240e-04, "S8R": 4.717399e-04}


@pytest.mark.parametrize("kind", ["S4", "S8R"])
def test_edge_load_ednor(tmp_path, kind):
    """*DLOAD EDNOR2 (force per length normal to the edge, in the shell; positive pushing into the element, as a
    pressure) on the tip edges of the cantilever plate: a pressure -1 / t on the solid-shells' side faces there. The
    tip's u_x equals CalculiX's to 1e-4 (measured 7e-5 S4, 2e-5 S8R: on S8R's six-node side faces, taken as their two
    4-node halves, the pressure is weighted 0 at the corners and 2 at the mid-side nodes, so that the nodal forces are
    the quadratic edge's 1/6, 2/3, 1/6; uniform on the halves, 1/4, 1/2, 1/4, the corner moved 8 % more) and the
    deflection of the same load given as those consistent nodal forces (*CLOAD) to 1e-6."""
    els = "\n".join(f"{k}, EDNOR2, -1.0" for k in (10, 20, 30, 40))
    text = plate_deck(kind, loads=False, fix="1, 3").replace("*NODE PRINT, NSET=TIP",
                                                             f"*DLOAD\n{els}\n*NODE PRINT, NSET=TIP")
    dat, proc = _run_deck(tmp_path, text, "ednor")
    assert proc.returncode == 0, proc.stderr
    U = _dat(dat)["U"]
    corner = 11 if kind == "S4" else 21
    assert U[corner][0] == pytest.approx(_CCX_EDNOR_TIP_X[kind], rel=1e-4)
    tip = sorted(U)
    h = 8.0 / 4  # (the tip elements' edge length)
    shares = (0.5, 0.5) if kind == "S4" else (1 / 6, 2 / 3, 1 / 6)
    w: dict[int, float] = {}
    step = len(shares) - 1
    for k in range(4):
        for n, s in zip(tip[step * k: step * k + len(shares)], shares, strict=True):
            w[n] = w.get(n, 0.0) + s * h
    cl = "\n".join(f"{n}, 1, {v:.12e}" for n, v in w.items())
    ref = plate_deck(kind, loads=False, fix="1, 3").replace("*NODE PRINT, NSET=TIP", f"*CLOAD\n{cl}\n*NODE PRINT, "
                                                                                      f"NSET=TIP")
    dat_ref, proc = _run_deck(tmp_path, ref, "cload")
    assert proc.returncode == 0, proc.stderr
    for n in tip:
        np.testing.assert_allclose(U[n], _dat(dat_ref)["U"][n], rtol=1e-6, atol=1e-9)


def test_edge_load_on_a_solid_is_one_line(tmp_path):
    text = TIED_EDGE.replace("*STATIC\n1.0, 1.0\n", "*STATIC\n1.0, 1.0\n*DLOAD\n1, EDNOR1, 1.0\n")
    deck = _write(tmp_path / "e.inp", text)
    proc = _cli(["run", deck, "--out", tmp_path / "e", "--quiet"])
    assert proc.returncode == 2 and "EDNOR1 on element 1, a hex8 element: edge loads act on the edges of shell" \
        in proc.stderr, proc.stderr


#: produced by running CalculiX 2.20 (Debian's ccx) on test_el_print_of_shells' deck: element 1's points 1 and 2
#: (sxx) and point 1 (sxz), CalculiX's S4 expanded into a C3D8I brick
_CCX_S4_POINT_STRESS = {"sxx1": 3.248249e-02, "sxx2": 3.246941e-02, "sxz1": 1.250000e-04}


def test_el_print_of_shells(tmp_path):
    """*EL PRINT S on S4 elements: each element's solid-shell's eight Gauss points in CalculiX's order of a C3D8
    (the bottom four first): the bending stress sxx at the clamp within 3 % of CalculiX's at its points 1 and 2
    (measured 2.2 % and 2.2 %; the elements differ: ANS + EAS against incompatible modes), the transverse shear sxz
    within 1 % (0.3 %), the top points the bottom ones' negatives; E on shells is said in a note, not left empty
    silently; S6 elements (three solid-shells each) are not printed, with a note."""
    text = plate_deck("S4", nx=2, ny=1).replace("*END STEP", "*EL PRINT, ELSET=PLATE\nS\n*EL PRINT, ELSET=PLATE\nE\n"
                                                             "*END STEP")
    dat, proc = _run_deck(tmp_path, text, "elp")
    assert proc.returncode == 0, proc.stderr
    assert "*EL PRINT E on shell elements (PLATE): not printed for them" in proc.stderr, proc.stderr
    rows = {}
    block = dat.read_text().split("stresses")[1].split("strains")[0]
    for line in block.splitlines():
        f = line.split()
        if len(f) == 8 and f[0].isdigit():
            rows[(int(f[0]), int(f[1]))] = np.array([float(x) for x in f[2:]])
    assert len(rows) == 16
    assert rows[(1, 1)][0] == pytest.approx(_CCX_S4_POINT_STRESS["sxx1"], rel=3e-2)
    assert rows[(1, 2)][0] == pytest.approx(_CCX_S4_POINT_STRESS["sxx2"], rel=3e-2)
    assert rows[(1, 1)][4] == pytest.approx(_CCX_S4_POINT_STRESS["sxz1"], rel=1e-2)
    np.testing.assert_allclose(rows[(1, 5)][[0, 1, 3]], -rows[(1, 1)][[0, 1, 3]], rtol=1e-5)
    tri = plate_deck("S6", nx=2, ny=1).replace("*END STEP", "*EL PRINT, ELSET=PLATE\nS\n*END STEP")
    dat, proc = _run_deck(tmp_path, tri, "tri")
    assert proc.returncode == 0, proc.stderr
    assert "S3 and S6 are each three solid-shells" in proc.stderr


def test_shell_node_shared_with_a_solid_is_a_hinge(tmp_path):
    """Shell elements sharing nodes with a solid element: CalculiX joins them there by a hinge (its manual: the
    connection between 3D elements and shells is always hinged), here the equations u_b + u_t - 2 u_s = 0, the mean of
    the shell node's layers following the solid node, the rotation free. A strip simply supported at both ends and
    loaded at its middle, its left end's nodes shared with a C3D8 block held in place: the same deflection as the strip
    pinned there by *BOUNDARY 1-3 (to 1e-6), where without the hinge the strip's end would be free."""
    pinned = plate_deck(nx=10, ny=1, B=1.0, fix="1, 3", both_ends=True)
    block = ("*NODE\n901, -1.0, 0.0, 0.0\n902, -1.0, 1.0, 0.0\n903, -1.0, 0.0, 1.0\n904, 0.0, 0.0, 1.0\n"
             "905, 0.0, 1.0, 1.0\n906, -1.0, 1.0, 1.0\n*ELEMENT, TYPE=C3D8, ELSET=BLOCK\n"
             "901, 901, 1, 12, 902, 903, 904, 905, 906\n*NSET, NSET=BLK\n901, 902, 903, 904, 905, 906, 1, 12\n"
             "*SOLID SECTION, ELSET=BLOCK, MATERIAL=STEEL\n")
    hinged = pinned.replace("*MATERIAL", block + "*MATERIAL", 1).replace("*STEP", "*BOUNDARY\nBLK, 1, 3\n*STEP", 1)
    w = {}
    for name, text in (("pinned", pinned), ("hinged", hinged)):
        dat, proc = _run_deck(tmp_path, text, name)
        assert proc.returncode == 0, proc.stderr
        w[name] = _dat(dat)["U"][6][2]
    assert abs(w["pinned"]) > 1e-4
    assert w["hinged"] == pytest.approx(w["pinned"], rel=1e-6)
    imp = import_deck(tmp_path / "hinged.inp", tmp_path / "i" / "h.toml")
    eqs = [e for e in tomllib.loads(imp.problem.read_text())["equation"] if e["name"].startswith("hinge")]
    assert len(eqs) == 6 and all(e["terms"][2][2] == -2.0 for e in eqs)


def test_equation_on_shell_nodes_holds_their_mean(tmp_path):
    """*EQUATION on shell nodes: a shell node's displacement is the mean of its two layers (CalculiX's expanded
    nodes), so each term c u becomes c/2 on each layer: the tip corners of the cantilever plate held to the same
    deflection while only one of them is loaded move alike (the .dat's U, the layers' mean, equal to 1e-6)."""
    text = plate_deck(loads=False).replace("*STEP", "*EQUATION\n2\n11, 3, 1.0, 55, 3, -1.0\n*STEP", 1)
    text = text.replace("*NODE PRINT, NSET=TIP", "*CLOAD\n11, 3, 1e-4\n*NODE PRINT, NSET=TIP")
    dat, proc = _run_deck(tmp_path, text, "eq")
    assert proc.returncode == 0, proc.stderr
    U = _dat(dat)["U"]
    assert U[11][2] > 1e-4 and U[55][2] == pytest.approx(U[11][2], rel=1e-6)
    assert U[33][2] != pytest.approx(U[11][2], rel=1e-3)  # (the edge between them is free)
