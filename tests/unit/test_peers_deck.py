"""The CalculiX deck writer and result readers of benchmarks/peers (no ccx needed)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "benchmarks" / "peers"))
sys.path.insert(0, str(ROOT / "tests" / "verification"))

from ccx_deck import C3D8_FACES, c10_d1, face_numbers, hertz_deck
from ccx_results import parse_dat, parse_sta, parse_stdout
from hertz_setup import hertz_mesh

from covcontact.fem.shapes import NODES
from covcontact.materials import lame


@pytest.fixture(scope="module")
def mesh():
    return hertz_mesh(n=6, nr=3)


def _blocks(text: str) -> dict[str, list[list[str]]]:
    """Keyword line -> data lines split at commas (keywords repeated: data lines appended)."""
    out, key = {}, None
    for line in text.splitlines():
        if line.startswith("*"):
            key = line.split(",")[0].strip().upper()
            out.setdefault(key, [])
        elif key is not None and line.strip():
            out[key].append([f.strip() for f in line.split(",")])
    return out


@pytest.mark.parametrize("plane_n", [2, 4])
def test_counts(mesh, plane_n):
    text, info = hertz_deck(mesh, "svk", 1.0, 0.3, 0.01, 10, 1e4, plane_n=plane_n)
    b = _blocks(text)
    n_plane = 2 * (plane_n + 1) ** 2
    assert info.body_nodes == mesh.n_nodes == 175 and info.body_elements == mesh.n_cells == 108
    assert len(b["*NODE"]) == info.n_nodes == mesh.n_nodes + n_plane
    assert len(b["*ELEMENT"]) == info.n_elements == mesh.n_cells + plane_n**2
    assert all(len(row) == 9 for row in b["*ELEMENT"])
    # node numbers 1..n, each once; every element node is defined
    ids = sorted(int(r[0]) for r in b["*NODE"])
    assert ids == list(range(1, info.n_nodes + 1))
    assert max(int(v) for r in b["*ELEMENT"] for v in r[1:]) == info.n_nodes
    # slave faces = the curved face set, master faces = the plane's top faces
    surf = b["*SURFACE"]
    assert len(surf) == info.slave_faces + info.master_faces
    assert info.slave_faces == len(mesh.face_sets["curved"]) == 27 and info.master_faces == plane_n**2
    # CalculiX reads at most 20 characters per field (the heading is free text)
    assert max(len(f) for k, rows in b.items() if k != "*HEADING" for r in rows for f in r) <= 20
    assert "NODE TO SURFACE" in text and "NLGEOM" in text


def test_face_numbers_pick_the_curved_faces(mesh):
    """The face S1..S6 of each slave element holds exactly the four nodes of the covcontact face, and
    the element's other four nodes lie inside the ball (nearer its centre)."""
    elems, nums = face_numbers(mesh, "curved")
    centre = np.array([0.0, 0.0, 1.0])
    for e, s, face in zip(elems, nums, mesh.face_sets["curved"], strict=True):
        local = list(C3D8_FACES[s - 1])
        on = mesh.cells[e, local]
        assert set(on.tolist()) == set(face[:4].tolist())
        off = np.delete(mesh.cells[e], local)
        r_on = np.linalg.norm(mesh.points[on] - centre, axis=1)
        r_off = np.linalg.norm(mesh.points[off] - centre, axis=1)
        assert r_off.max() < r_on.min()
    assert set(nums.tolist()) <= {1, 2, 3, 4, 5, 6}


def test_c3d8_face_table():
    """S1..S6 of C3D8 are the faces zeta = -1, zeta = +1, eta = -1, xi = +1, eta = +1, xi = -1 of the
    natural cube (the node order of C3D8 is that of covcontact's hex8)."""
    nat = NODES["hex8"]
    for nodes, (axis, value) in zip(C3D8_FACES, [(2, -1), (2, 1), (1, -1), (0, 1), (1, 1), (0, -1)], strict=True):
        assert sorted(nodes) == sorted(np.flatnonzero(nat[:, axis] == value).tolist())


def test_materials_and_scale(mesh):
    E, nu, S = 1.0, 0.3, 1e5
    svk, _ = hertz_deck(mesh, "svk", E, nu, 0.01, 10, 1e4, stress_scale=S)
    b = _blocks(svk)
    assert float(b["*ELASTIC"][0][0]) == pytest.approx(E * S) and float(b["*ELASTIC"][0][1]) == nu
    assert float(b["*SURFACE BEHAVIOR"][0][0]) == pytest.approx(1e4 * S)
    assert float(b["*STATIC"][0][0]) == pytest.approx(0.1)  # 10 fixed increments
    assert float(b["*BOUNDARY"][-1][-1]) == pytest.approx(-0.01)
    nh, _ = hertz_deck(mesh, "neo-hooke", E, nu, 0.01, 10, 1e4)
    C10, D1 = (float(v) for v in _blocks(nh)["*HYPERELASTIC"][0])
    lam, mu = lame(E, nu)
    # small-strain moduli: shear 2 C10 = mu, bulk 2 / D1 = lambda + 2 mu / 3
    assert 2.0 * C10 == pytest.approx(mu) and 2.0 / D1 == pytest.approx(lam + 2.0 * mu / 3.0)
    assert (C10, D1) == pytest.approx(c10_d1(E, nu))
    with pytest.raises(ValueError):
        hertz_deck(mesh, "mooney", E, nu, 0.01, 10, 1e4)


DAT = """
 total force (fx,fy,fz) for set NFLAT and time  0.5000000E+00

       -1.0E-06 -2.0E-06 -3.5E-05

 displacements (vx,vy,vz) for set NCURVED and time  0.5000000E+00

         7  0.000000E+00  1.000000E-03 -2.000000E-03
         9 -1.000000E-04  0.000000E+00 -1.000000E-03

 contact stress (slave node,press,tang1,tang2) for all contact elements and time 0.5000000E+00

         7  2.500000E-02  0.000000E+00  0.000000E+00

 total force (fx,fy,fz) for set NFLAT and time  0.1000000E+01

        0.0E+00  0.0E+00 -9.0E-05
"""

STA = """SUMMARY OF JOB INFORMATION
  STEP      INC     ATT  ITRS     TOT TIME     STEP TIME      INC TIME
     1          1     1     5  0.500000E+00  0.500000E+00  0.500000E+00
     1          2     1     3  0.100000E+01  0.100000E+01  0.500000E+00
"""


def test_readers():
    d = parse_dat(DAT)
    assert d.times == [0.5, 1.0]
    assert d.rf[1.0][2] == pytest.approx(-9.0e-5) and d.rf[0.5][1] == pytest.approx(-2.0e-6)
    assert set(d.u[0.5]) == {7, 9} and d.u[0.5][9][0] == pytest.approx(-1e-4)
    assert d.p[0.5] == {7: pytest.approx(0.025)} and 1.0 not in d.p
    assert parse_sta(STA) == [5, 3]
    s = parse_stdout(" number of equations\n 2934\n Using up to 2 cpu(s) for spooles.\n"
                     " Factoring the system of equations using the symmetric spooles solver\n"
                     "Total CalculiX Time: 3.5\n")
    assert s == {"equations": 2934, "ccx_time_s": 3.5, "solver": "symmetric spooles", "cpus": 2,
                 "error": False}


def test_two_bodies_deck_matches_the_problem():
    """bodies_deck: every node and element of both blocks once, numbered globally; the contact surfaces are the
    faces of the pair's sets; zero supports fixed in the model, the punch's motion ramped in the step; the
    pair's penalty as the pressure-overclosure slope, scaled with the stress unit."""
    from ccx_deck import bodies_deck

    from covcontact.io.loader import load_problem

    problem = load_problem(ROOT / "examples" / "contact" / "two_blocks.toml")
    text, info = bodies_deck(problem, stress_scale=10.0)
    base, punch = problem.bodies
    assert info.n_nodes == base.mesh.n_nodes + punch.mesh.n_nodes
    assert info.n_elements == base.mesh.n_cells + punch.mesh.n_cells
    node_lines = [ln for ln in text.splitlines() if ln and ln[0].isdigit() and ln.count(",") == 3]
    ids = [int(ln.split(",")[0]) for ln in node_lines]
    assert ids == list(range(1, info.n_nodes + 1))
    X = np.array([[float(v) for v in ln.split(",")[1:]] for ln in node_lines])
    np.testing.assert_allclose(X, np.vstack([base.mesh.points, punch.mesh.points]), rtol=0, atol=1e-12)
    assert info.slave_faces == len(punch.mesh.face_sets["zmin"])
    assert info.master_faces == len(base.mesh.face_sets["zmax"])
    lines = text.splitlines()
    slope = lines[lines.index("*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR") + 1].split(",")
    assert float(slope[0]) == pytest.approx(10.0 * problem.contacts[0].penalty)
    step = lines.index("*STEP, NLGEOM, INC=200")
    moved = [ln for ln in lines[step:] if ln.startswith("NPUNCH_ZMAX, 3, 3")]
    assert len(moved) == 1 and float(moved[0].split(",")[3]) == pytest.approx(-0.02)
    fixed = lines[lines.index("*BOUNDARY") + 1: step]
    assert sorted(fixed) == sorted([f"NBASE_ZMIN, {c}, {c}" for c in (1, 2, 3)]
                                   + [f"NPUNCH_ZMAX, {c}, {c}" for c in (1, 2)])
    # the slave faces' corner nodes are the punch's zmin nodes (offset by the base's nodes)
    sl = lines.index("*SURFACE, NAME=SSLAVE, TYPE=ELEMENT")
    faces = [ln.split(",") for ln in lines[sl + 1: sl + 1 + info.slave_faces]]
    nodes = set()
    for e, f in faces:
        cell = punch.mesh.cells[int(e) - 1 - base.mesh.n_cells]
        nodes |= {int(cell[a]) for a in C3D8_FACES[int(f.strip()[1:]) - 1]}
    assert nodes == set(punch.mesh.node_sets["zmin"].tolist())
