"""Faces of wedge meshes: a face set holds the triangles or the quadrilaterals of the wedges (the generators' sets,
Gmsh groups, Abaqus *SURFACE S1..S5, face sets of your own), outward; pressures on both kinds; wedge faces as
contact surfaces; and the one-line errors where a set would mix them (docs/input.md)."""

from __future__ import annotations

import meshio
import numpy as np
import pytest
from two_blocks import two_blocks

from covcontact.io.loader import load_problem
from covcontact.io.validate import InputError
from covcontact.mesh.convert import convert
from covcontact.mesh.faces import face_normals
from covcontact.mesh.generators import block
from covcontact.mesh.io import MeshError, read_mesh
from covcontact.tangent_check import check_tangent


def test_generated_sets_are_one_type_each_and_outward():
    m = convert(block(2.0, 1.0, 1.0, 2, 2, 2, "hex8"), "wedge6")
    expect = {"xmin": ([-1, 0, 0], 4), "xmax": ([1, 0, 0], 4), "ymin": ([0, -1, 0], 4), "ymax": ([0, 1, 0], 4),
              "zmin": ([0, 0, -1], 3), "zmax": ([0, 0, 1], 3)}
    for name, (direction, nfn) in expect.items():
        f = m.face_sets[name]
        assert f.shape[1] == nfn, name
        n = face_normals(m.points, f)
        np.testing.assert_allclose(n / np.linalg.norm(n, axis=1, keepdims=True), np.tile(direction, (len(f), 1)),
                                   atol=1e-12)
    # the faces cover the block's sides: areas 1 x 2 (x faces 1 x 1)
    area = {k: np.abs(face_normals(m.points, f)).sum() * (0.5 if f.shape[1] == 3 else 4.0)
            for k, f in m.face_sets.items()}
    assert area["zmin"] == pytest.approx(2.0) and area["xmin"] == pytest.approx(1.0)


WEDGE_BAR = """
[problem]
name = "wedge-bar"
[[bodies]]
name = "bar"
element = "wedge6"
material = { model = "svk", E = 200.0, nu = 0.0 }
mesh = { generator = "block", lx = 2.0, ly = 1.0, lz = 1.0, nx = 4, ny = 2, nz = 2 }
[[dirichlet]]
set = "bar.xmin"
components = "x"
[[dirichlet]]
set = "bar.ymin"
components = "y"
[[dirichlet]]
set = "bar.zmin"
components = "z"
[[pressure]]
set = "bar.SET"
value = -2.0
[steps]
count = 2
"""


@pytest.mark.parametrize("fset, axis, length", [("xmax", 0, 2.0), ("zmax", 2, 1.0)])
def test_pressure_on_quadrilateral_and_triangular_faces(tmp_path, fset, axis, length):
    """A tension (pressure -2) on the wedges' quadrilateral end or triangular top of a bar in uniaxial stress
    (nu = 0): the reaction balances it exactly and the stretch is the closed form of St. Venant-Kirchhoff,
    2 = lambda E (lambda^2 - 1) / 2 per reference area (a dead load on the reference faces)."""
    from scipy.optimize import brentq

    path = tmp_path / "bar.toml"
    path.write_text(WEDGE_BAR.replace("SET", fset))
    res = load_problem(path).run(out=tmp_path / "out")
    assert res.exit_code == 0
    lam = brentq(lambda s: s * 200.0 * (s * s - 1.0) / 2.0 - 2.0, 1.0, 2.0, xtol=1e-15)
    x, X = res.model.positions(res.u), res.model.system.X
    far = np.abs(X[:, axis] - length) < 1e-9
    np.testing.assert_allclose(x[far, axis] - X[far, axis], (lam - 1.0) * length, rtol=1e-9)


def test_gmsh_groups_of_wedges(tmp_path):
    """A Gmsh file of wedges with a triangle group (the top), a quadrilateral group (a side) and a group of both:
    the first two become face sets of their type, outward; the mixed one a node set only."""
    m = convert(block(1.0, 1.0, 1.0, 1, 1, 1, "hex8"), "wedge6")
    top, side = m.face_sets["zmax"], m.face_sets["xmax"]
    cells = [("wedge", m.cells), ("triangle", top[:, ::-1]), ("quad", side), ("triangle", top), ("quad", side)]
    phys = [np.full(len(m.cells), 1), np.full(len(top), 2), np.full(len(side), 3), np.full(len(top), 4),
            np.full(len(side), 4)]
    path = tmp_path / "w.msh"
    meshio.write(path, meshio.Mesh(m.points, cells, cell_data={"gmsh:physical": phys, "gmsh:geometrical": phys},
                                   field_data={"vol": np.array([1, 3]), "top": np.array([2, 2]),
                                               "side": np.array([3, 2]), "both": np.array([4, 2])}),
                 file_format="gmsh22", binary=False)
    mesh = read_mesh(path)
    assert mesh.cell_type == "wedge6"
    assert mesh.face_sets["top"].shape == (2, 3) and mesh.face_sets["side"].shape == (1, 4)
    assert np.all(face_normals(mesh.points, mesh.face_sets["top"])[:, 2] > 0)  # re-ordered outward
    assert "both" not in mesh.face_sets and len(mesh.node_sets["both"]) == 6


DECK = """*NODE
1, 0, 0, 0
2, 1, 0, 0
3, 0, 1, 0
4, 0, 0, 1
5, 1, 0, 1
6, 0, 1, 1
*ELEMENT, TYPE=C3D6, ELSET=W
1, 1, 2, 3, 4, 5, 6
*SURFACE, NAME=BOTTOM
W, S1
*SURFACE, NAME=TOP
W, S2
*SURFACE, NAME=FRONT
W, S3
*SURFACE, NAME=SLANT
W, S4
*SURFACE, NAME=BACK
W, S5
"""


def test_abaqus_wedge_surfaces(tmp_path):
    """C3D6 faces S1, S2 (triangles 1-2-3, 4-6-5) and S3..S5 (quadrilaterals 1-4-5-2, 2-5-6-3, 3-6-4-1), outward;
    a surface of both kinds is one line."""
    path = tmp_path / "w.inp"
    path.write_text(DECK)
    mesh = read_mesh(path)
    expect = {"BOTTOM": [0, 0, -1], "TOP": [0, 0, 1], "FRONT": [0, -1, 0], "SLANT": [1, 1, 0], "BACK": [-1, 0, 0]}
    for name, direction in expect.items():
        n = face_normals(mesh.points, mesh.face_sets[name])[0]
        np.testing.assert_allclose(n / np.linalg.norm(n), np.asarray(direction) / np.linalg.norm(direction),
                                   atol=1e-12)
        assert mesh.face_sets[name].shape[1] == (3 if name in ("BOTTOM", "TOP") else 4)
    path.write_text(DECK.replace("W, S3", "W, S3\nW, S1"))
    with pytest.raises(MeshError) as err:
        read_mesh(path)
    assert "mixes triangular and quadrilateral faces (wedges: S1, S2 and S3..S5)" in str(err.value)
    assert "\n" not in str(err.value)


def test_face_filters_of_one_type(tmp_path):
    """[bodies.faces] on a wedge mesh: a filter that picks the triangles gives a tri3 set; one that picks both
    kinds is one line."""
    base = WEDGE_BAR.replace("SET", "zmax")
    path = tmp_path / "bar.toml"
    text = base.replace("[[dirichlet]]", '[bodies.faces]\ntop = { normal = [0.0, 0.0, 1.0] }\n\n[[dirichlet]]', 1)
    path.write_text(text)
    prob = load_problem(path)
    assert prob.bodies[0].mesh.face_sets["top"].shape == (16, 3)
    path.write_text(text.replace("top = { normal = [0.0, 0.0, 1.0] }", "top = { box = [[1.5, -1.0, -1.0], [3.0, 3.0, "
                                                                        "3.0]] }"))
    with pytest.raises(InputError) as err:
        load_problem(path)
    assert "bodies[0].faces.top" in str(err.value) and "triangles and" in str(err.value)


def test_wedge_faces_in_contact(tmp_path):
    """A block pressed onto a wedge block: the wedges' triangular top as the master (tri3 patches) and their
    quadrilateral sides are not involved; exact tangent against central differences."""
    text = two_blocks("wedge6", "hex8", 'type = "sts"\nfriction = 0.2')
    path = tmp_path / "w.toml"
    path.write_text(text)
    prob = load_problem(path)
    assert prob.bodies[0].mesh.face_sets["zmax"].shape[1] == 3
    rep = check_tangent(prob, step=3, columns=60)
    assert rep["converged"] and rep["zones"]["contact"] > 0
    assert rep["relative_error"] <= 1e-6, rep["relative_error"]
