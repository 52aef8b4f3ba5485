"""Abaqus/CalculiX *SURFACE definitions in a mesh deck (docs/input.md, "Mesh files"): element surfaces by
element set and face identifier S1..S6, node surfaces, *INCLUDE; each a face set (outward) or node set."""

from __future__ import annotations

import numpy as np
import pytest

from covcontact.mesh.faces import face_normals
from covcontact.mesh.io import MeshError, read_mesh

#: two unit hex8 cells along x: nodes 1-6 at z = 0, 7-12 at z = 1; C3D8 order (bottom 1-2-3-4, top 5-6-7-8)
DECK = """*HEADING
two cells
*NODE
1, 0, 0, 0
2, 1, 0, 0
3, 2, 0, 0
4, 0, 1, 0
5, 1, 1, 0
6, 2, 1, 0
7, 0, 0, 1
8, 1, 0, 1
9, 2, 0, 1
10, 0, 1, 1
11, 1, 1, 1
12, 2, 1, 1
*ELEMENT, TYPE=C3D8, ELSET=BLOCK
1, 1, 2, 5, 4, 7, 8, 11, 10
2, 2, 3, 6, 5, 8, 9, 12, 11
*ELSET, ELSET=RIGHT
2
*NSET, NSET=CORNER
1
*INCLUDE, INPUT=surfaces.inp
"""
SURFACES = """** the surfaces, in a file of their own
*SURFACE, NAME=TOP, TYPE=ELEMENT
BLOCK, S2
*SURFACE, NAME=END
RIGHT, S4
*SURFACE, NAME=PIN, TYPE=NODE
CORNER
"""


def _write(tmp_path, surfaces=SURFACES):
    (tmp_path / "deck.inp").write_text(DECK)
    (tmp_path / "surfaces.inp").write_text(surfaces)
    return tmp_path / "deck.inp"


def test_element_and_node_surfaces(tmp_path):
    mesh = read_mesh(_write(tmp_path))
    top, end = mesh.face_sets["TOP"], mesh.face_sets["END"]
    assert len(top) == 2 and len(end) == 1
    assert np.allclose(mesh.points[top][:, :, 2], 1.0) and np.allclose(mesh.points[end][:, :, 0], 2.0)
    assert np.all(face_normals(mesh.points, top)[:, 2] > 0)  # outward
    assert np.all(face_normals(mesh.points, end)[:, 0] > 0)
    assert len(mesh.node_sets["TOP"]) == 6 and len(mesh.node_sets["PIN"]) == 1
    np.testing.assert_allclose(mesh.points[mesh.node_sets["PIN"][0]], [0.0, 0.0, 0.0])


@pytest.mark.parametrize("surfaces, message", [
    ("*SURFACE, NAME=BAD\nBLOCK, S7\n", "surfaces.inp, line 2: expected 'ELSET, S1'..'S6'"),
    ("*SURFACE, NAME=BAD\n1, S2\n", "element numbers in *SURFACE are not supported"),
    ("*SURFACE, NAME=BAD\nNOPE, S2\n", "*SURFACE BAD: no element set 'NOPE'"),
    ("*SURFACE, NAME=BAD\nRIGHT, S3\nBLOCK, S6\n", "*SURFACE BAD"),
])
def test_bad_surfaces(tmp_path, surfaces, message):
    with pytest.raises(MeshError) as err:
        read_mesh(_write(tmp_path, surfaces))
    assert message in str(err.value)


#: one C3D4 tetrahedron (0,0,0), (1,0,0), (0,1,0), (0,0,1) and its faces S1 .. S4 (Abaqus numbering: S1 = 1-2-3,
#: S2 = 1-4-2, S3 = 2-4-3, S4 = 3-4-1)
TET_DECK = """*NODE
1, 0, 0, 0
2, 1, 0, 0
3, 0, 1, 0
4, 0, 0, 1
*ELEMENT, TYPE=C3D4, ELSET=T
1, 1, 2, 3, 4
*SURFACE, NAME=BOTTOM
T, S1
*SURFACE, NAME=SIDE
T, S2
*SURFACE, NAME=SLANT
T, S3
*SURFACE, NAME=BACK
T, S4
"""


def test_tetrahedron_surfaces(tmp_path):
    """S1..S4 of a C3D4: face sets of outward tri3 faces at z = 0, y = 0, the slanted face and x = 0; S5 is an
    error naming the faces a tetrahedron has."""
    path = tmp_path / "tet.inp"
    path.write_text(TET_DECK)
    mesh = read_mesh(path)
    normals = {name: face_normals(mesh.points, mesh.face_sets[name])[0] for name in ("BOTTOM", "SIDE", "SLANT", "BACK")}
    for name, expected in (("BOTTOM", [0, 0, -1]), ("SIDE", [0, -1, 0]), ("SLANT", [1, 1, 1]), ("BACK", [-1, 0, 0])):
        n = normals[name] / np.linalg.norm(normals[name])
        np.testing.assert_allclose(n, np.asarray(expected) / np.linalg.norm(expected), atol=1e-12)
        assert mesh.face_sets[name].shape == (1, 3)
    path.write_text(TET_DECK.replace("T, S4", "T, S5"))
    with pytest.raises(MeshError) as err:
        read_mesh(path)
    assert "faces S1..S4, not S5" in str(err.value)
