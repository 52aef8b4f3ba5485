"""The solid half-/quarter-cylinder generator: validity, sets, exact geometry, grading."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial import cKDTree

from covcontact.fem.quadrature import gauss_hex
from covcontact.io.bodies_input import mesh_generators
from covcontact.mesh import boundary_faces, check_orientation, face_normals, jacobian_determinants
from covcontact.mesh.generators_solid import half_cylinder_solid

R, L = 1.5, 0.2
PARAMS = [(cell, part, grade) for cell in ("hex8", "hex27") for part in ("half", "quarter")
          for grade in ((0.0, 0.0), (4.5, 4.0))]


def _mesh(cell, part, grade, origin=(0.3, -0.1, 0.2)):
    return half_cylinder_solid(R, L, n=8, nr=3, n_len=2, cell=cell, part=part, grade_angle=grade[0],
                               grade_depth=grade[1], origin=origin)


@pytest.mark.parametrize("cell, part, grade", PARAMS)
def test_mesh_is_valid(cell, part, grade):
    o = np.array([0.3, -0.1, 0.2])
    mesh = _mesh(cell, part, grade, tuple(o))
    c = o + [0.0, 0.0, R]  # a point of the axis
    P = mesh.points
    # positive Jacobians at every Gauss point, no duplicate or unused nodes
    assert jacobian_determinants(mesh).min() > 0.0 and check_orientation(mesh) == []
    d, _ = cKDTree(P).query(P, k=2)
    assert d[:, 1].min() > 1e-6 * R
    assert np.array_equal(np.unique(mesh.cells), np.arange(mesh.n_nodes))
    # boundary faces point away from their element; every face set is made of them
    faces, elem, _ = boundary_faces(mesh)
    n = face_normals(P, faces)
    out = P[faces].mean(axis=1) - P[mesh.cells[elem]].mean(axis=1)
    assert np.all(np.einsum("fi,fi->f", n, out) > 0.0)
    keys = {tuple(f) for f in faces}
    expected = {"flat", "curved", "end0", "end1"} | ({"symx"} if part == "quarter" else set())
    assert set(mesh.face_sets) == expected
    assert set(mesh.node_sets) == expected | {"bottom_line", "all"}
    for fs in mesh.face_sets.values():
        assert fs.shape[1] == (4 if cell == "hex8" else 9) and all(tuple(f) in keys for f in fs)
    # the sets cover the whole boundary, each face once
    assert sum(len(fs) for fs in mesh.face_sets.values()) == len(faces)
    # node sets on their exact surfaces
    assert np.allclose(np.hypot(P[mesh.node_sets["curved"], 0] - c[0], P[mesh.node_sets["curved"], 2] - c[2]), R)
    assert np.allclose(P[mesh.node_sets["flat"], 2], c[2])
    assert np.allclose(P[mesh.node_sets["end0"], 1], o[1]) and np.allclose(P[mesh.node_sets["end1"], 1], o[1] + L)
    line = P[mesh.node_sets["bottom_line"]]
    assert len(line) == (3 if cell == "hex8" else 5) and np.allclose(line[:, [0, 2]], o[[0, 2]], atol=1e-14)
    assert P[:, 2].min() == pytest.approx(o[2], abs=1e-14)
    if part == "quarter":
        assert np.allclose(P[mesh.node_sets["symx"], 0], o[0])
        assert P[:, 0].min() == pytest.approx(o[0], abs=1e-14)
    # outward normals of the named faces
    nc = face_normals(P, mesh.face_sets["curved"])
    radial = P[mesh.face_sets["curved"]].mean(axis=1) - c
    radial[:, 1] = 0.0
    assert np.all(np.einsum("fi,fi->f", nc, radial) > 0.0)
    assert np.all(face_normals(P, mesh.face_sets["flat"])[:, 2] > 0.0)
    assert np.all(face_normals(P, mesh.face_sets["end0"])[:, 1] < 0.0)
    assert np.all(face_normals(P, mesh.face_sets["end1"])[:, 1] > 0.0)
    if part == "quarter":
        assert np.all(face_normals(P, mesh.face_sets["symx"])[:, 0] < 0.0)
    # volume: pi R^2 L / 2 (or / 4); measured -0.6 % (hex8), -3e-6 (hex27), graded -3.9 % and -1e-3 (the
    # grading stretches the elements far from the lowest line)
    pts, w = gauss_hex(3)
    vol = float((jacobian_determinants(mesh, pts) @ w).sum())
    exact = math.pi * R**2 * L / (2.0 if part == "half" else 4.0)
    tol = {("hex8", False): 1e-2, ("hex8", True): 5e-2, ("hex27", False): 1e-5, ("hex27", True): 2e-3}
    assert vol == pytest.approx(exact, rel=tol[cell, grade[0] > 0.0])


def test_counts():
    m = half_cylinder_solid(1.0, 0.1, n=8, nr=4, n_len=1, part="quarter")
    # box 4 x 4, bottom and side blocks 4 x 4 each sharing their edges, one layer (two node layers)
    assert m.n_cells == 48 and m.n_nodes == 2 * (5 * 5 + 5 * 4 + 4 * 4)
    assert half_cylinder_solid(1.0, 0.1, n=8, nr=4, n_len=3).n_cells == 3 * (32 + 32 + 2 * 16)


def test_grading_pulls_nodes_to_the_lowest_line():
    def surface_spacing(m):
        P = m.points[m.node_sets["curved"]]
        x = np.sort(np.abs(P[np.abs(P[:, 1]) < 1e-12, 0]))
        return x[1]

    def first_layer(m):
        P = m.points[m.node_sets["all"]]
        on = P[(np.abs(P[:, 0]) < 1e-12) & (np.abs(P[:, 1]) < 1e-12), 2]
        return np.sort(on)[1]

    plain = half_cylinder_solid(1.0, 0.1, n=16, nr=8, part="quarter")
    graded = half_cylinder_solid(1.0, 0.1, n=16, nr=8, part="quarter", grade_angle=4.5, grade_depth=4.0)
    # element sizes at the lowest line shrink by g/sinh(g) (0.10 and 0.15) to first order
    assert surface_spacing(graded) == pytest.approx(surface_spacing(plain) * 4.5 / math.sinh(4.5), rel=0.05)
    assert first_layer(graded) < 0.25 * first_layer(plain)


def test_loader_collects_the_generator():
    gens = mesh_generators()
    assert gens["half_cylinder_solid"] is half_cylinder_solid and "block" in gens


def test_errors():
    with pytest.raises(ValueError, match="hex18"):
        half_cylinder_solid(1.0, 0.1, cell="hex18")
    with pytest.raises(ValueError, match="even"):
        half_cylinder_solid(1.0, 0.1, n=5)
    with pytest.raises(ValueError, match="part"):
        half_cylinder_solid(1.0, 0.1, part="third")
    with pytest.raises(ValueError, match="grade_angle"):
        half_cylinder_solid(1.0, 0.1, grade_angle=-1.0)
    with pytest.raises(ValueError, match="radius"):
        half_cylinder_solid(0.0, 0.1)
