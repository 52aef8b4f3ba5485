"""Frictional sliding over tri6 and quad8 facets (C3D10 and C3D20 meshes): in steady sliding the friction force is
mu times the normal force, the closed form, and a deck of a tet10 punch slid on a tet10 block (the everyday FreeCAD
/ PrePoMax case: *CONTACT PAIR, TYPE=SURFACE TO SURFACE with *FRICTION) runs to its end.

The deck died in its slide step with a ZeroDivisionError in the friction history transfer: a slave point that crossed
a whole patch quadrilateral of a tri6 face in a step had its old contact point projected onto the facet's
continuation, which folds one facet size beyond its edges (docs/theory.md sections 7 and 19;
tests/unit/test_friction_transfer.py).

On tri6 facets the covariant slip a_ij (xi - xi_n)^j is measured on the patch quadrilaterals, whose map is not
affine: over a step's slip it turns each point's slip direction a little (an error proportional to the slip per step
over the facet size), so the points' tractions, each exactly mu N, do not all point along the motion. The resultant
falls short of mu N by about 1e-3 at a slip of 0.075 of the facet size per step (0.4 % at 0.15, 0.1 to 0.7 % on the
deck below); on quad8 facets, one affine quad9 each on a flat mesh, it is exact.
"""

import json

import numpy as np
import pytest

from covcontact.cli import main
from covcontact.io.loader import load_problem
from covcontact.mesh.convert import convert
from covcontact.mesh.generators import block

MU = 0.2

# ------------------------------------------------------------------------------------------------ the deck

#: corners of the faces S1..S4 of a C3D10 (Abaqus / CalculiX numbering, from 0)
_TET_FACES = [(0, 1, 2), (0, 3, 1), (1, 3, 2), (2, 3, 0)]


def _tet10_box(size, n, origin):
    """A box of tet10 (six per brick, VTK order = C3D10 order) with the generator's node sets."""
    return convert(block(*size, *n, cell="hex8", origin=origin), "tet10")


def _faces_on(mesh, nodes, first_element):
    """{face number: element labels} of the tetrahedra's faces whose corners all lie in ``nodes``."""
    on = np.zeros(len(mesh.points), dtype=bool)
    on[nodes] = True
    out: dict[int, list[int]] = {}
    for e, cell in enumerate(mesh.cells):
        for k, face in enumerate(_TET_FACES):
            if on[cell[list(face)]].all():
                out.setdefault(k + 1, []).append(first_element + e)
    return out


def _lines(values, per=12):
    values = [str(v) for v in values]
    return [", ".join(values[i:i + per]) for i in range(0, len(values), per)]


def punch_deck(slide=0.6, increment=0.5) -> str:
    """A 0.8 x 0.8 x 0.4 tet10 punch on a 2 x 2 x 1 tet10 block (24 + 24 elements), pressed by a pressure of 5 in a
    first step, slid by ``slide`` along x in a second (initial increment ``increment`` of the step)."""
    b = _tet10_box((2.0, 2.0, 1.0), (2, 2, 1), (0.0, 0.0, 0.0))
    p = _tet10_box((0.8, 0.8, 0.4), (2, 2, 1), (0.2, 0.6, 1.0))
    nb, eb = len(b.points), len(b.cells)
    out = ["*HEADING", "tet10 punch pressed onto a tet10 block and slid with friction", "*NODE, NSET=NALL"]
    out += [f"{i + 1}, {x:.12g}, {y:.12g}, {z:.12g}" for i, (x, y, z) in enumerate(np.vstack([b.points, p.points]))]
    for name, mesh, n0, e0 in (("BLOCK", b, 0, 0), ("PUNCH", p, nb, eb)):
        out.append(f"*ELEMENT, TYPE=C3D10, ELSET={name}")
        out += [f"{e0 + e + 1}, " + ", ".join(str(n0 + k + 1) for k in cell) for e, cell in enumerate(mesh.cells)]
    out += ["*NSET, NSET=BOTTOM", *_lines(b.node_sets["zmin"] + 1), "*NSET, NSET=PTOP",
            *_lines(p.node_sets["zmax"] + nb + 1)]
    for name, faces in (("SBLOCK", _faces_on(b, b.node_sets["zmax"], 1)),
                        ("SPUNCH", _faces_on(p, p.node_sets["zmin"], eb + 1))):
        for k, els in faces.items():
            out += [f"*ELSET, ELSET={name}{k}", *_lines(els)]
        out += [f"*SURFACE, NAME={name}, TYPE=ELEMENT", *(f"{name}{k}, S{k}" for k in faces)]
    top = _faces_on(p, p.node_sets["zmax"], eb + 1)
    for k, els in top.items():
        out += [f"*ELSET, ELSET=PTOP{k}", *_lines(els)]
    out += ["*MATERIAL, NAME=STEEL", "*ELASTIC", "100000., 0.3",
            "*SOLID SECTION, ELSET=BLOCK, MATERIAL=STEEL", "*SOLID SECTION, ELSET=PUNCH, MATERIAL=STEEL",
            "*CONTACT PAIR, INTERACTION=SI1, TYPE=SURFACE TO SURFACE", "SPUNCH, SBLOCK",
            "*SURFACE INTERACTION, NAME=SI1", "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR", "1.0e7",
            "*FRICTION", f"{MU}, 1.0e7", "*BOUNDARY", "BOTTOM, 1, 3",
            "*STEP, NLGEOM", "*STATIC", "1.0, 1.0", "*DLOAD", *(f"PTOP{k}, P{k}, 5." for k in top),
            "*BOUNDARY", "PTOP, 1, 2", "*END STEP",
            "*STEP, NLGEOM", "*STATIC", f"{increment}, 1.0", "*BOUNDARY", f"PTOP, 1, 1, {slide}", "*END STEP"]
    return "\n".join(out) + "\n"


def test_tet10_punch_slid_with_friction_deck(tmp_path, capsys):
    deck = tmp_path / "punch.inp"
    deck.write_text(punch_deck())
    code = main(["run", str(deck), "--out", str(tmp_path / "out"), "--quiet"])
    err = capsys.readouterr().err
    assert code == 0, err
    s = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert s["status"] == "completed"
    slide = [st for st in s["steps"] if st.get("stage") != s["steps"][0].get("stage")]
    assert len(slide) >= 2 and slide[-1]["load_factor"] == pytest.approx(1.0)
    for st in slide:  # every slide step: sliding at mu N (the load 5 x 0.64), against the motion
        fx, fy, fz = st["contact_force"]
        assert fz == pytest.approx(3.2, rel=1e-5)  # (the Newton tolerance)
        assert -fx / (MU * fz) == pytest.approx(1.0, abs=1e-2)  # measured 0.9931 .. 0.9989
        assert abs(fy) < 0.02 * abs(fx)
        pair = st["pairs"]["pair1"]
        assert pair["slip"] == pair["active_contacts"] > 150 and pair["stick"] == 0
    # the block's support takes the contact force; the dragging support holds the punch against it, but for the
    # x-share of the pressure on the punch's top, which follows the face as it tilts under the friction's moment
    # (NLGEOM: a follower pressure; measured 1.4e-4 of the friction force)
    fx = slide[-1]["contact_force"][0]
    assert s["steps"][-1]["reactions"]["BLOCK.BOTTOM"] == pytest.approx(slide[-1]["contact_force"], rel=1e-5)
    assert s["steps"][-1]["reactions"]["PUNCH.PTOP"][0] == pytest.approx(-fx, rel=5e-4)


# ------------------------------------------------------------------------------ a block slid on quad facets

SLIDE = """
[problem]
name = "slide"

[[bodies]]
name = "base"
element = "{base}"
material = {{ model = "svk", E = 1.0e6, nu = 0.3 }}
mesh = {{ generator = "block", lx = 2.0, ly = 2.0, lz = 1.0, nx = 2, ny = 2, nz = 1 }}

[[bodies]]
name = "block"
element = "hex8"
material = {{ model = "svk", E = 1.0e6, nu = 0.3 }}
mesh = {{ generator = "block", lx = 0.8, ly = 0.8, lz = 0.4, nx = 2, ny = 2, nz = 1, origin = [0.2, 0.6, 1.0] }}

[[contact]]
name = "slide"
slave = "block.zmin"
master = "base.zmax"
type = "sts"
penalty = 1.0e8
friction = {mu}

[[dirichlet]]
set = "base.zmin"
components = "xyz"

[[dirichlet]]
name = "drive"
set = "block.zmax"
components = "xy"

[[pressure]]
set = "block.zmax"
value = 5.0

[steps]
count = 1

# (Newton's default rtol of 1e-8 is relative to the larger of a step's first residuals, some 4e5 here where a slide
# step starts with the penalty 1e8 against the slid block: that leaves up to 2e-4 of the normal force 3.2)
[solver]
rtol = 1.0e-11

[[stages]]
name = "slide"
targets = {{ drive = [0.6, 0.0] }}
steps = {{ count = {steps} }}
"""


@pytest.mark.parametrize("base,facets,steps,tol", [("hex20", "quad8", 4, 2e-5), ("tet10", "tri6", 8, 2e-3)])
def test_block_slides_over_quadratic_facets_at_mu_n(tmp_path, base, facets, steps, tol):
    """A hex8 block pressed (pressure 5 on 0.8 x 0.8) onto the quad8 faces of a hex20 base or the tri6 faces of a
    tet10 base, then dragged 0.6 along x (three quarters of its length, across element edges): in every step of the
    slide all its points slip and the friction force is mu times the normal force, against the motion."""
    path = tmp_path / "slide.toml"
    path.write_text(SLIDE.format(base=base, mu=MU, steps=steps))
    problem = load_problem(path)
    assert problem.bodies[0].mesh.face_sets["zmax"].shape[1] == {"quad8": 8, "tri6": 6}[facets]
    res = problem.run(out=tmp_path / "out")
    assert res.exit_code == 0
    slide = [st for st in res.summary["steps"] if st.get("stage") == "slide"]
    assert len(slide) == steps
    for st in slide:
        fx, fy, fz = st["contact_force"]
        assert fz == pytest.approx(5.0 * 0.64, rel=1e-5)  # (the Newton tolerance)
        assert np.hypot(fx, fy) / (MU * fz) == pytest.approx(1.0, abs=tol)  # quad8 3e-6, tri6 1.0e-3 .. 1.4e-3
        assert -fx / (MU * fz) == pytest.approx(1.0, abs=tol)
        pair = st["pairs"]["slide"]
        assert pair["slip"] == pair["active_contacts"] >= 12 and pair["stick"] == 0
    reaction = res.summary["steps"][-1]["reactions"]["block.zmax"]
    # the drive holds the block against it (up to the follower pressure on its slightly tilted top)
    assert reaction[0] == pytest.approx(-slide[-1]["contact_force"][0], rel=1e-4)
