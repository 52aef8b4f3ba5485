"""Hybrid elements in decks (C3D8H, C3D20H, C3D10H, ...): Abaqus's mixed u/p elements for nearly incompressible
materials become covcontact's F-bar bodies, said in a note (docs/input.md, the decks' element table)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from covcontact.cli import main


def _cube(etype: str, lateral: str) -> str:
    """A unit cube of 3 x 3 x 3 elements of Mooney-Rivlin rubber (C10 = 0.4, C01 = 0.1, D1 = 0.0004: mu0 = 1, K0 =
    5000) compressed by 20 % (the top face moved down 0.2); ``lateral``: "free" (symmetry planes x = 0 and y = 0,
    the top free to slide: homogeneous uniaxial compression) or "bonded" (top and bottom held in x and y)."""
    n = 3
    ids = {}
    nodes = []
    for kz in range(n + 1):
        for ky in range(n + 1):
            for kx in range(n + 1):
                ids[kx, ky, kz] = len(ids) + 1
                nodes.append(f"{ids[kx, ky, kz]}, {kx / n}, {ky / n}, {kz / n}")
    els = []
    for kz in range(n):
        for ky in range(n):
            for kx in range(n):
                c = [ids[kx, ky, kz], ids[kx + 1, ky, kz], ids[kx + 1, ky + 1, kz], ids[kx, ky + 1, kz],
                     ids[kx, ky, kz + 1], ids[kx + 1, ky, kz + 1], ids[kx + 1, ky + 1, kz + 1], ids[kx, ky + 1, kz + 1]]
                els.append(f"{len(els) + 1}, " + ", ".join(map(str, c)))

    def nset(name, sel):
        labels = sorted(v for k, v in ids.items() if sel(*k))
        return f"*NSET, NSET={name}\n" + "\n".join(", ".join(map(str, labels[i:i + 8])) for i in range(0, len(labels), 8))

    if lateral == "free":
        bcs = "BOT, 3, 3\nXSYM, 1, 1\nYSYM, 2, 2\nTOP, 3, 3, -0.2"
    else:
        bcs = "BOT, 1, 3\nTOP, 1, 2\nTOP, 3, 3, -0.2"
    return "\n".join(["*NODE", *nodes, f"*ELEMENT, TYPE={etype}, ELSET=EALL", *els,
                      nset("BOT", lambda x, y, z: z == 0), nset("TOP", lambda x, y, z: z == n),
                      nset("XSYM", lambda x, y, z: x == 0), nset("YSYM", lambda x, y, z: y == 0),
                      "*MATERIAL, NAME=RUB", "*HYPERELASTIC, MOONEY-RIVLIN", "0.4, 0.1, 0.0004",
                      "*SOLID SECTION, ELSET=EALL, MATERIAL=RUB", "*STEP, NLGEOM", "*STATIC", "0.25, 1.0",
                      "*BOUNDARY", bcs, "*NODE PRINT, NSET=TOP, TOTALS=ONLY", "RF", "*END STEP", ""])


def _run(tmp_path, etype, lateral, capsys, text=None, axis=2):
    """Run the cube deck (or ``text``): the force on its TOP set along ``axis``, stderr, the imported problem."""
    deck = tmp_path / f"{etype}_{lateral}.inp"
    deck.write_text(_cube(etype, lateral) if text is None else text)
    out = tmp_path / f"o_{etype}_{lateral}"
    code = main(["run", str(deck), "--out", str(out), "--quiet"])
    err = capsys.readouterr().err
    assert code == 0, err
    summary = json.loads((out / "summary.json").read_text())
    force = sum(np.asarray(v) for k, v in summary["steps"][-1]["reactions"].items() if k.endswith(".TOP"))
    return force[axis], err, (out / "deck" / f"{deck.stem}.toml").read_text()


def test_hybrid_cube_is_fbar_and_exact_in_uniaxial_compression(tmp_path, capsys):
    """C3D8H: an F-bar body and a note; homogeneous uniaxial compression to stretch 0.8 gives the incompressible
    Mooney-Rivlin nominal stress P = 2 (lambda - lambda^-2) (C10 + C01 / lambda) (Treloar; the manuals' Mooney-Rivlin)
    within 1e-3 (the bulk modulus 5000 mu0 leaves a compressibility of that order)."""
    force, err, toml = _run(tmp_path, "C3D8H", "free", capsys)
    assert 'formulation = "fbar"' in toml and "C3D8H (hybrid" in err and "become F-bar elements" in err
    lam = 0.8
    exact = 2.0 * (lam - lam ** -2) * (0.4 + 0.1 / lam)
    assert force == pytest.approx(exact, rel=1e-3)


def test_hybrid_relieves_locking(tmp_path, capsys):
    """The cube bonded to its plates: the C3D8 (full integration) locks, the hybrid (F-bar) does not. Measured: the
    force on the top -136.7 with C3D8, -1.129 with C3D8H, 1.41 times the free uniaxial compression's -0.801 (bonding
    stiffens a block by a factor of the order of its shape factor's square: a bound, not a reference)."""
    locked, _, _ = _run(tmp_path, "C3D8", "bonded", capsys)
    hybrid, _, _ = _run(tmp_path, "C3D8H", "bonded", capsys)
    free, _, _ = _run(tmp_path, "C3D8H", "free", capsys)
    assert abs(locked) > 50.0 * abs(hybrid)
    assert 1.0 < hybrid / free < 3.0  # bonded is stiffer than free, by a shape factor's order


def test_hybrid_tet4_refused(tmp_path, capsys):
    deck = tmp_path / "t.inp"
    deck.write_text("*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 0, 0, 1\n*ELEMENT, TYPE=C3D4H, ELSET=E\n"
                    "1, 1, 2, 3, 4\n*MATERIAL, NAME=M\n*ELASTIC\n1000, 0.49\n*SOLID SECTION, ELSET=E, MATERIAL=M\n"
                    "*STEP\n*STATIC\n*BOUNDARY\n1, 1, 3\n*END STEP\n")
    code = main(["run", str(deck), "--out", str(tmp_path / "o"), "--quiet"])
    err = capsys.readouterr().err
    assert code == 2 and "C3D4H (hybrid)" in err and "F-bar" in err


def _square(etype: str, lateral: str, x0: float = 0.0) -> str:
    """The unit square [x0, x0 + 1] x [0, 1] of 3 x 3 planar elements of the cube's rubber, compressed by 20 % (the top
    edge moved down 0.2); ``lateral`` "free" (the left edge on a symmetry line x = x0 when x0 = 0, the top free to
    slide: homogeneous) or "bonded" (top and bottom held in x)."""
    n = 3
    ids = {(kx, ky): ky * (n + 1) + kx + 1 for ky in range(n + 1) for kx in range(n + 1)}
    nodes = [f"{i}, {x0 + kx / n}, {ky / n}, 0." for (kx, ky), i in ids.items()]
    els = [f"{ky * n + kx + 1}, {ids[kx, ky]}, {ids[kx + 1, ky]}, {ids[kx + 1, ky + 1]}, {ids[kx, ky + 1]}"
           for ky in range(n) for kx in range(n)]

    def nset(name, sel):
        return f"*NSET, NSET={name}\n" + ", ".join(str(v) for k, v in sorted(ids.items()) if sel(*k))

    if lateral == "free":
        bcs = "BOT, 2, 2\nTOP, 2, 2, -0.2" + ("\nLEFT, 1, 1" if x0 == 0.0 else "")
    else:
        bcs = "BOT, 1, 2\nTOP, 1, 1\nTOP, 2, 2, -0.2"
    return "\n".join(["*NODE", *nodes, f"*ELEMENT, TYPE={etype}, ELSET=EALL", *els,
                      nset("BOT", lambda x, y: y == 0), nset("TOP", lambda x, y: y == n),
                      nset("LEFT", lambda x, y: x == 0),
                      "*MATERIAL, NAME=RUB", "*HYPERELASTIC, MOONEY-RIVLIN", "0.4, 0.1, 0.0004",
                      "*SOLID SECTION, ELSET=EALL, MATERIAL=RUB", "*STEP, NLGEOM", "*STATIC", "0.25, 1.0",
                      "*BOUNDARY", bcs, "*NODE PRINT, NSET=TOP, TOTALS=ONLY", "RF", "*END STEP", ""])


def _run_planar(tmp_path, etype, lateral, capsys, x0=0.0):
    return _run(tmp_path, etype, lateral, capsys, _square(etype, lateral, x0), axis=1)


@pytest.mark.parametrize("etype", ["CPE4H", "CPE8RH"])
def test_planar_hybrid_is_planar_fbar_and_exact_in_plane_strain_compression(tmp_path, capsys, etype):
    """CPE4H, CPE8RH: plane strain bodies with the planar F-bar and a note. Compressed to stretch 0.8 with the sides
    free, the square is in pure shear (lambda, 1 / lambda, 1): the incompressible Mooney-Rivlin nominal stress
    P = 2 (C10 + C01) (lambda - lambda^-3) (Treloar's pure shear) within 1e-3 (the compressibility, K0 = 5000 mu0)."""
    text = _square("CPE4H", "free")
    if etype == "CPE8RH":  # (mid-nodes: the quad8 square of the same corners)
        text = _quadratic(text)
    deck = tmp_path / f"{etype}.inp"
    deck.write_text(text)
    out = tmp_path / f"o_{etype}"
    code = main(["run", str(deck), "--out", str(out), "--quiet"])
    err = capsys.readouterr().err
    assert code == 0, err
    toml = (out / "deck" / f"{deck.stem}.toml").read_text()
    assert 'formulation = "plane_strain"' in toml and "fbar = true" in toml and "integration" not in toml
    assert f"{etype} (hybrid" in err and "planar F-bar" in err
    summary = json.loads((out / "summary.json").read_text())
    force = sum(np.asarray(v) for k, v in summary["steps"][-1]["reactions"].items() if k.endswith(".TOP"))[1]
    lam = 0.8
    assert force == pytest.approx(2.0 * 0.5 * (lam - lam ** -3), rel=1e-3)


def _quadratic(text: str) -> str:
    """The CPE4H deck of _square as CPE8RH: a mid-node on every edge (labels from 1001), in covcontact's (and the
    decks') order: corners, then the mid-nodes of the edges 1-2, 2-3, 3-4, 4-1; the sets get the mid-nodes on them."""
    lines = text.split("\n")
    k = lines.index("*ELEMENT, TYPE=CPE4H, ELSET=EALL")
    xy = {int(l.split(",")[0]): tuple(float(v) for v in l.split(",")[1:3]) for l in lines[1:k]}
    mids, new_nodes, els = {}, [], []
    j = k + 1
    while not lines[j].startswith("*"):
        e, *c = [int(v) for v in lines[j].split(",")]
        m = []
        for a, b in zip(c, c[1:] + c[:1]):
            key = frozenset((a, b))
            if key not in mids:
                mids[key] = 1001 + len(mids)
                x, y = ((xy[a][0] + xy[b][0]) / 2, (xy[a][1] + xy[b][1]) / 2)
                new_nodes.append(f"{mids[key]}, {x}, {y}, 0.")
                xy[mids[key]] = (x, y)
            m.append(mids[key])
        els.append(f"{e}, " + ", ".join(map(str, c + m)))
        j += 1
    rest = lines[j:]
    for i, l in enumerate(rest):
        if l.startswith("*NSET"):
            members = [int(v) for v in rest[i + 1].split(",")]
            extra = [v for key, v in mids.items() if key <= set(members)]
            rest[i + 1] = ", ".join(map(str, members + extra))
    return "\n".join(lines[:k] + new_nodes + ["*ELEMENT, TYPE=CPE8RH, ELSET=EALL"] + els + rest)


def test_planar_hybrid_relieves_locking(tmp_path, capsys):
    """The square bonded to its plates in plane strain: CPE4 locks, CPE4H (the planar F-bar) does not; CAX4H is
    read as an axisymmetric F-bar body, CPE3H as CPE3 with a note, and CPE4H with CPE3H in one body is listed."""
    locked, _, _ = _run_planar(tmp_path, "CPE4", "bonded", capsys)
    hybrid, _, _ = _run_planar(tmp_path, "CPE4H", "bonded", capsys)
    free, _, _ = _run_planar(tmp_path, "CPE4H", "free", capsys)
    assert abs(locked) > 20.0 * abs(hybrid)
    assert 1.0 < hybrid / free < 3.0
    _, err, toml = _run_planar(tmp_path, "CAX4H", "free", capsys, x0=1.0)
    assert 'formulation = "axisymmetric"' in toml and "fbar = true" in toml
    deck = tmp_path / "tri.inp"
    deck.write_text("*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 1, 1, 0\n*ELEMENT, TYPE=CPE3H, ELSET=E\n1, 1, 2, 3\n"
                    "*MATERIAL, NAME=M\n*ELASTIC\n1000, 0.3\n*SOLID SECTION, ELSET=E, MATERIAL=M\n*STEP\n*STATIC\n"
                    "*BOUNDARY\n1, 1, 2\n2, 2, 2\n*END STEP\n")
    assert main(["run", str(deck), "--out", str(tmp_path / "o3"), "--quiet"]) == 0
    assert "CPE3H (hybrid) read as CPE3" in capsys.readouterr().err
    deck.write_text(deck.read_text().replace("*MATERIAL", "*ELEMENT, TYPE=CPE4H, ELSET=E\n2, 2, 4, 5, 3\n*NODE\n5, 2, 1, 0\n"
                                             "*MATERIAL"))
    code = main(["run", str(deck), "--out", str(tmp_path / "o4"), "--quiet"])
    assert code == 2 and "mesh the body with quadrilaterals only" in capsys.readouterr().err
