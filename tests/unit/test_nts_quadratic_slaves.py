"""Node-to-surface contact with area weighting on tri6 and quad8 slave faces (tet10 and hex20 bodies).

The integral of a corner shape function is zero on a tri6 face and -1/12 of the face on a quad8 face, so as tributary
areas the corners took no or a pulling contact force and area weighting was refused there. The slave areas are now
CalculiX's node-to-face spring areas (``surface.slave_area``): tri6 corners 0 and mid-nodes 1/3 of the face, quad8
corners 1/100 and mid-nodes 24/100; a node without area is no slave of an area-weighted pair.
"""

import json

import numpy as np
import pytest

from covcontact.cli import main
from covcontact.contact.surface import SLAVE_AREA_SHARES, slave_area, tributary_area
from covcontact.io.loader import load_problem
from covcontact.mesh.convert import convert
from covcontact.mesh.generators import block


def _mesh(cell):
    return convert(block(2.0, 1.0, 1.0, 2, 2, 1, cell="hex8" if cell == "tet10" else "hex27"), cell)


@pytest.mark.parametrize("cell,nen", [("tet10", 6), ("hex20", 8)])
def test_slave_areas_are_non_negative_and_sum_to_the_face(cell, nen):
    mesh = _mesh(cell)
    faces = mesh.face_sets["zmax"]
    assert faces.shape[1] == nen
    X = mesh.points.copy()
    a = slave_area(X, faces)
    assert a.min() >= 0.0 and a.sum() == pytest.approx(2.0, rel=1e-13)  # the face set's area 2 x 1
    # each face's share: CalculiX's fractions of its area (faces of equal area here)
    share = SLAVE_AREA_SHARES[nen]
    per_face = 2.0 / len(faces)
    expected = np.bincount(faces.ravel(), np.tile(share * per_face, len(faces)), minlength=len(X))
    np.testing.assert_allclose(a, expected, atol=1e-14)
    corners = np.unique(faces[:, :4 if nen == 8 else 3])
    assert np.all(a[corners] == 0.0) if nen == 6 else np.all(a[corners] > 0.0)
    # the consistent integral that was refused: zero (tri6) or negative (quad8) at the corners
    assert tributary_area(X, faces)[corners].max() < 1e-12
    # a curved face: the areas still add up to its area (the face rule's, as tributary_area integrates it)
    X[:, 2] += 0.3 * X[:, 0] ** 2 - 0.2 * X[:, 1] ** 2
    a = slave_area(X, faces)
    assert a.min() >= 0.0 and a.sum() == pytest.approx(tributary_area(X, faces).sum(), rel=1e-13) and a.sum() > 2.0


PUNCH = """
[problem]
name = "flat-punch"

[[bodies]]
name = "punch"
element = "{cell}"
material = {{ model = "svk", E = 1000.0, nu = 0.3 }}
mesh = {{ generator = "block", lx = 1.0, ly = 1.0, lz = 0.5, nx = 2, ny = 2, nz = 1 }}

[[rigid]]
name = "floor"
shape = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]

[[contact]]
name = "floor"
slave = "punch.zmin"
master = "floor"
weighting = "area"
penalty = 1.0e5

[[dirichlet]]
set = "punch.xmin"
components = "x"

[[dirichlet]]
set = "punch.ymin"
components = "y"

[[pressure]]
set = "punch.zmax"
value = 2.0

[steps]
count = 1
"""


def _pressed(tmp_path, cell):
    path = tmp_path / "punch.toml"
    path.write_text(PUNCH.format(cell=cell))
    res = load_problem(path).run(out=tmp_path / "out", quiet=True)
    assert res.exit_code == 0
    p = res.model.contact.passes[0]
    return res, p, res.state.contact.passes[0]


def test_tet10_flat_punch_takes_the_load_through_compressive_nodal_forces(tmp_path):
    """A flat tet10 punch (unit square base, symmetry supports, free to expand) pressed onto a rigid plane by a
    uniform pressure of 2: the contact force is the load, every slave node pushes, and as the spring areas are the
    consistent nodal forces of a uniform pressure, the contact pressure is uniform: p at every node, gap -p / K."""
    res, p, st = _pressed(tmp_path, "tet10")
    assert res.summary["steps"][-1]["contact_force"] == pytest.approx([0.0, 0.0, 2.0], abs=2e-6)
    assert st.force.sum(axis=0) == pytest.approx([0.0, 0.0, 2.0], abs=2e-6)
    assert p.ns == 16  # the mid-nodes of the 8 tri6 faces of the base; its 9 corners carry no area, no slaves
    assert np.all(st.force[:, 2] > 0.0)
    np.testing.assert_allclose(st.force[:, 2] / p.area, 2.0, rtol=1e-6)
    np.testing.assert_allclose(st.gap, -2.0 / 1.0e5, rtol=1e-6)


def test_hex20_flat_punch_takes_the_load_without_pulling(tmp_path):
    """The same on quad8 faces: every node of the base is a slave; the uniform pressure's consistent corner forces
    (-1/12 of a face) pull where the corner springs (1/100) push, so the corners lift a little off the plane (zero
    force) while the load crosses at the mid-nodes; no node pulls."""
    res, p, st = _pressed(tmp_path, "hex20")
    assert p.ns == 21 and np.all(p.area > 0.0)
    assert st.force.sum(axis=0) == pytest.approx([0.0, 0.0, 2.0], abs=2e-6)
    assert np.all(st.force[:, 2] >= 0.0) and np.count_nonzero(st.force[:, 2] > 0.0) >= 12


def test_node_to_surface_deck_with_a_c3d10_slave_surface_runs(tmp_path, capsys):
    """*CONTACT PAIR, TYPE=NODE TO SURFACE whose slave is a C3D10 element surface (area-weighted since its faces
    are known): refused before ("area weighting on tri6 faces"), now run; the contact force carries the load."""
    punch = convert(block(1.0, 1.0, 0.5, 2, 2, 1, cell="hex8", origin=(0.5, 0.5, 1.0)), "tet10")
    base = block(2.0, 2.0, 1.0, 2, 2, 1, cell="hex8")
    nb = len(base.points)
    lines = ["*HEADING", "tet10 punch on a C3D8 block, node-to-surface", "*NODE"]
    lines += [f"{i + 1}, {x:.12g}, {y:.12g}, {z:.12g}" for i, (x, y, z) in enumerate(np.vstack([base.points,
                                                                                             punch.points]))]
    lines.append("*ELEMENT, TYPE=C3D8, ELSET=BASE")
    lines += [f"{e + 1}, " + ", ".join(str(k + 1) for k in c) for e, c in enumerate(base.cells)]
    lines.append("*ELEMENT, TYPE=C3D10, ELSET=PUNCH")
    ne = len(base.cells)
    lines += [f"{ne + e + 1}, " + ", ".join(str(nb + k + 1) for k in c) for e, c in enumerate(punch.cells)]

    def faces_on(mesh, nodes, first, faces):
        on = np.zeros(len(mesh.points), dtype=bool)
        on[nodes] = True
        return {k + 1: [first + e for e, c in enumerate(mesh.cells) if on[c[list(f)]].all()]
                for k, f in enumerate(faces)}

    hex_faces = [(0, 1, 2, 3), (4, 7, 6, 5), (0, 4, 5, 1), (1, 5, 6, 2), (2, 6, 7, 3), (3, 7, 4, 0)]
    tet_faces = [(0, 1, 2), (0, 3, 1), (1, 3, 2), (2, 3, 0)]
    surfaces = {"SBASE": faces_on(base, base.node_sets["zmax"], 1, hex_faces),
                "SPUNCH": faces_on(punch, punch.node_sets["zmin"], ne + 1, tet_faces),
                "PTOP": faces_on(punch, punch.node_sets["zmax"], ne + 1, tet_faces)}
    for name, by_face in surfaces.items():
        by_face = {k: v for k, v in by_face.items() if v}
        for k, els in by_face.items():
            lines += [f"*ELSET, ELSET={name}{k}", ", ".join(map(str, els))]
        lines += [f"*SURFACE, NAME={name}, TYPE=ELEMENT", *(f"{name}{k}, S{k}" for k in by_face)]
    top = {k: v for k, v in surfaces["PTOP"].items() if v}
    lines += ["*NSET, NSET=BOTTOM", ", ".join(str(k + 1) for k in base.node_sets["zmin"]),
              "*NSET, NSET=PTOPN", ", ".join(str(nb + k + 1) for k in punch.node_sets["zmax"]),
              "*MATERIAL, NAME=M", "*ELASTIC", "1000., 0.3",
              "*SOLID SECTION, ELSET=BASE, MATERIAL=M", "*SOLID SECTION, ELSET=PUNCH, MATERIAL=M",
              "*CONTACT PAIR, INTERACTION=SI, TYPE=NODE TO SURFACE", "SPUNCH, SBASE",
              "*SURFACE INTERACTION, NAME=SI", "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR", "1.0e5",
              "*BOUNDARY", "BOTTOM, 1, 3", "PTOPN, 1, 2",
              "*STEP, NLGEOM", "*STATIC", "1.0, 1.0", "*DLOAD", *(f"PTOP{k}, P{k}, 2." for k in top), "*END STEP"]
    deck = tmp_path / "nts.inp"
    deck.write_text("\n".join(lines) + "\n")
    code = main(["run", str(deck), "--out", str(tmp_path / "out"), "--quiet"])
    err = capsys.readouterr().err
    assert code == 0, err
    s = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert s["status"] == "completed"
    fz = s["steps"][-1]["contact_force"][2]
    assert fz == pytest.approx(2.0, rel=1e-6)  # the pressure 2 on the unit top
