"""Meshes: generators, boundary faces, orientation, file reading and writing."""

from __future__ import annotations

import math

import meshio
import numpy as np
import pytest
from scipy.spatial import cKDTree

from covcontact.fem.quadrature import gauss_hex, gauss_quad
from covcontact.fem.shapes import NODES, shape_functions
from covcontact.mesh import (
    FACES,
    MeshError,
    block,
    boundary_faces,
    check_orientation,
    cylinder_patch,
    face_normals,
    faces_on_nodes,
    hemisphere_solid,
    jacobian_determinants,
    match_boundary_faces,
    plate,
    read_mesh,
    sphere_patch,
    to_meshio,
    write_vtu,
)
from covcontact.mesh.faces import _FACE_MAPS, FACE_LABELS
from covcontact.mesh.mesh import Mesh

PI = math.pi
CASES = {
    "block": lambda c: block(2.0, 1.0, 1.5, 3, 2, 2, c, origin=(1.0, -1.0, 0.5)),
    "plate": lambda c: plate(2.0, 1.0, 0.1, 4, 3, c),
    "cyl_x": lambda c: cylinder_patch(1.0, 2.0, 0.0, PI / 2, 0.1, 4, 3, c, axis="x"),
    "cyl_full": lambda c: cylinder_patch(1.0, 2.0, 0.0, 2 * PI, 0.2, 8, 2, c, center=(1, 2, 3)),
    "sphere": lambda c: sphere_patch(1.0, 0.3, 1.2, 0.0, 1.0, 0.1, 4, 3, c),
    "sphere_ring": lambda c: sphere_patch(1.0, PI / 10, PI / 2, 0.0, 2 * PI, 0.05, 3, 8, c),
    "cap": lambda c: sphere_patch(2.0, 0.0, 1.0, 0.0, 2 * PI, 0.1, 2, 8, c),
    "cap_sector": lambda c: sphere_patch(2.0, 0.0, 1.0, 0.2, 2.0, 0.1, 2, 4, c),
    "hemisphere": lambda c: hemisphere_solid(1.0, 4, 2, c, origin=(0.5, 0.0, 0.0)),
    "hemisphere_focus": lambda c: hemisphere_solid(1.0, 6, 2, c, focus=0.3),
}
PARAMS = [
    (name, cell)
    for name in CASES
    for cell in ("hex8", "hex18", "hex27")
    if not (name.startswith("hemisphere") and cell == "hex18")
]


def _face_integral(mesh: Mesh, faces: np.ndarray) -> float:
    """Sum over faces of int x . n dA (3x3 Gauss, exact for quad4/quad9 geometry)."""
    ftype = "quad4" if faces.shape[1] == 4 else "quad9"
    pts, w = gauss_quad(3)
    N, dN, _ = shape_functions(ftype, pts)
    X = mesh.points[faces]
    x = np.einsum("pa,fai->fpi", N, X)
    rho = np.einsum("fai,paj->fpji", X, dN)
    n = np.cross(rho[:, :, 0], rho[:, :, 1])
    return float(np.einsum("fpi,fpi,p->", x, n, w))


def _volume(mesh: Mesh) -> float:
    pts, w = gauss_hex(3)
    return float((jacobian_determinants(mesh, pts) @ w).sum())


@pytest.mark.parametrize("name,cell", PARAMS)
def test_generator_is_valid(name: str, cell: str) -> None:
    mesh = CASES[name](cell)
    assert mesh.cell_type == cell and mesh.cells.shape[1] == {"hex8": 8, "hex18": 18, "hex27": 27}[cell]
    # positive Jacobian at every Gauss point of the full rule
    assert jacobian_determinants(mesh).min() > 0.0
    assert check_orientation(mesh) == []
    # no duplicate nodes, and every node is used
    d, _ = cKDTree(mesh.points).query(mesh.points, k=2)
    assert d[:, 1].min() > 1e-6 * np.ptp(mesh.points, axis=0).max()
    assert np.array_equal(np.unique(mesh.cells), np.arange(mesh.n_nodes))
    # boundary faces point away from their element's centre
    faces, elem, _ = boundary_faces(mesh)
    n = face_normals(mesh.points, faces)
    out = mesh.points[faces].mean(axis=1) - mesh.points[mesh.cells[elem]].mean(axis=1)
    assert np.all(np.einsum("fi,fi->f", n, out) > 0.0)
    if cell != "hex18":  # closed boundary: divergence theorem, int x.n dA = 3 V
        assert _face_integral(mesh, faces) == pytest.approx(3.0 * _volume(mesh), rel=1e-10)
    # every face set is a subset of the boundary faces, outward ordered
    keys = {tuple(f) for f in faces}
    for fs in mesh.face_sets.values():
        assert fs.shape[1] == (4 if cell == "hex8" else 9)
        assert all(tuple(f) in keys for f in fs)
    assert np.array_equal(mesh.node_set("all"), np.arange(mesh.n_nodes))


@pytest.mark.parametrize("cell,per_dir", [("hex8", (1, 1, 1)), ("hex18", (2, 2, 1)), ("hex27", (2, 2, 2))])
def test_block_counts_and_sets(cell: str, per_dir: tuple[int, int, int]) -> None:
    nx, ny, nz = 3, 2, 4
    mesh = block(3.0, 2.0, 4.0, nx, ny, nz, cell)
    assert mesh.n_nodes == np.prod([p * n + 1 for p, n in zip(per_dir, (nx, ny, nz), strict=True)])
    assert mesh.n_cells == nx * ny * nz
    nbf = boundary_faces(mesh)[0].shape[0]
    if cell == "hex18":
        assert nbf == 2 * nx * ny  # only the t = -1 / t = +1 faces are hex18 faces
    else:
        assert nbf == 2 * (nx * ny + ny * nz + nz * nx)
    centre = np.array([1.5, 1.0, 2.0])
    faces = boundary_faces(mesh)[0]
    n = face_normals(mesh.points, faces)
    assert np.all(np.einsum("fi,fi->f", n, mesh.points[faces].mean(axis=1) - centre) > 0.0)
    for d, ax in enumerate("xyz"):
        lo, hi = mesh.node_set(ax + "min"), mesh.node_set(ax + "max")
        assert np.all(mesh.points[lo, d] == 0.0) and np.all(mesh.points[hi, d] == [3, 2, 4][d])
        assert np.count_nonzero(mesh.points[:, d] == 0.0) == lo.size
    zmax = mesh.face_set("zmax")
    assert zmax.shape[0] == nx * ny
    assert np.allclose(face_normals(mesh.points, zmax) / (1.0 * 1.0 / 4), [0.0, 0.0, 1.0])


def test_plate_sets() -> None:
    t = 0.05
    mesh = plate(2.0, 1.0, t, 4, 2, "hex18", origin=(0.0, 0.0, 1.0))
    assert np.all(mesh.points[mesh.node_set("top"), 2] == 1.0 + t)
    assert np.all(mesh.points[mesh.node_set("bottom"), 2] == 1.0)
    assert np.array_equal(mesh.node_set("top"), mesh.node_set("zmax"))
    assert np.all(face_normals(mesh.points, mesh.face_set("top"))[:, 2] > 0.0)
    assert np.all(face_normals(mesh.points, mesh.face_set("bottom"))[:, 2] < 0.0)
    assert mesh.face_set("top").shape == (8, 9)
    assert "xmin" not in mesh.face_sets  # hex18 side faces are not contact faces
    assert np.all(mesh.points[mesh.node_set("xmax"), 0] == 2.0)
    with pytest.raises(KeyError, match="known: .*top"):
        mesh.node_set("topp")


@pytest.mark.parametrize("cell", ["hex8", "hex18", "hex27"])
def test_cylinder_patch_geometry(cell: str) -> None:
    R, t, L = 1.0, 0.1, 2.0
    mesh = cylinder_patch(R, L, 0.0, PI / 2, t, 8, 2, cell, axis="y")
    r = np.hypot(mesh.points[:, 2], mesh.points[:, 0])  # axis y: angle from z towards x
    assert np.allclose(r[mesh.node_set("inner")], R - t / 2, rtol=0, atol=1e-14)
    assert np.allclose(r[mesh.node_set("outer")], R + t / 2, rtol=0, atol=1e-14)
    assert np.allclose(mesh.points[mesh.node_set("end1"), 1], L)
    assert np.allclose(mesh.points[mesh.node_set("angle0"), 0], 0.0)
    for name, sign in (("inner", -1.0), ("outer", 1.0)):
        f = mesh.face_set(name)
        c = mesh.points[f].mean(axis=1)
        radial = c * [1.0, 0.0, 1.0]
        assert np.all(sign * np.einsum("fi,fi->f", face_normals(mesh.points, f), radial) > 0.0)
    exact = 0.25 * PI * ((R + t / 2) ** 2 - (R - t / 2) ** 2) * L
    tol = 2e-2 if cell == "hex8" else 1e-5
    assert _volume(mesh) == pytest.approx(exact, rel=tol)


def test_full_cylinder_merges_seam() -> None:
    mesh = cylinder_patch(1.0, 1.0, 0.0, 2 * PI, 0.1, 8, 2, "hex27")
    assert mesh.n_nodes == 16 * 5 * 3  # closed: no duplicate column at the seam
    assert "angle0" not in mesh.node_sets


@pytest.mark.parametrize("cell", ["hex8", "hex18", "hex27"])
def test_sphere_patch_geometry(cell: str) -> None:
    R, t = 2.0, 0.1
    mesh = sphere_patch(R, 0.2, 1.0, 0.0, PI / 3, t, 6, 4, cell, center=(1.0, 0.0, 0.0))
    r = np.linalg.norm(mesh.points - [1.0, 0.0, 0.0], axis=1)
    assert np.allclose(r[mesh.node_set("outer")], R + t / 2, rtol=0, atol=1e-13)
    c = np.linalg.norm(mesh.points[mesh.node_set("theta0")] - [1.0, 0.0, 0.0], axis=1)
    assert np.allclose((mesh.points[mesh.node_set("theta0"), 2]) / c, math.cos(0.2))
    exact = ((R + t / 2) ** 3 - (R - t / 2) ** 3) / 3 * (math.cos(0.2) - math.cos(1.0)) * PI / 3
    assert _volume(mesh) == pytest.approx(exact, rel=2e-2 if cell == "hex8" else 1e-4)


@pytest.mark.parametrize("cell", ["hex8", "hex27"])
def test_sphere_cap(cell: str) -> None:
    R, t, th = 2.0, 0.1, 0.8
    mesh = sphere_patch(R, 0.0, th, 0.0, 2 * PI, t, 3, 8, cell)
    r = np.linalg.norm(mesh.points, axis=1)
    assert np.allclose(r[mesh.node_set("inner")], R - t / 2, rtol=0, atol=1e-13)
    pole = mesh.points[mesh.node_set("pole")]
    assert np.allclose(pole[:, :2], 0.0) and pole.shape[0] == (2 if cell == "hex8" else 3)
    rim = mesh.points[mesh.node_set("theta1")]
    assert np.allclose(rim[:, 2] / np.linalg.norm(rim, axis=1), math.cos(th))
    exact = ((R + t / 2) ** 3 - (R - t / 2) ** 3) / 3 * (1.0 - math.cos(th)) * 2 * PI
    # coarse: 8 facets around the rim (hex8 chords), quadratic mid-nodes exactly on the sphere
    assert _volume(mesh) == pytest.approx(exact, rel=0.15 if cell == "hex8" else 1.5e-3)
    sector = sphere_patch(R, 0.0, th, 0.0, PI / 2, t, 3, 4, cell)
    assert np.allclose(sector.points[sector.node_set("phi0"), 1], 0.0, atol=1e-14)
    assert np.allclose(sector.points[sector.node_set("phi1"), 0], 0.0, atol=1e-14)


@pytest.mark.parametrize("cell", ["hex8", "hex27"])
def test_hemisphere_solid(cell: str) -> None:
    R = 1.5
    mesh = hemisphere_solid(R, 4, 2, cell, origin=(0.0, 0.0, -1.0))
    c = np.array([0.0, 0.0, R - 1.0])
    assert np.allclose(np.linalg.norm(mesh.points[mesh.node_set("curved")] - c, axis=1), R)
    assert np.allclose(mesh.points[mesh.node_set("flat"), 2], R - 1.0)
    pole = mesh.node_set("pole")
    assert pole.size == 1 and np.allclose(mesh.points[pole[0]], [0.0, 0.0, -1.0], atol=1e-15)
    assert mesh.points[:, 2].min() == pytest.approx(-1.0, abs=1e-15)
    fc = mesh.face_set("curved")
    n = face_normals(mesh.points, fc)
    assert np.all(np.einsum("fi,fi->f", n, mesh.points[fc].mean(axis=1) - c) > 0.0)
    assert np.all(face_normals(mesh.points, mesh.face_set("flat"))[:, 2] > 0.0)
    exact = 2.0 / 3.0 * PI * R**3
    assert _volume(mesh) == pytest.approx(exact, rel=0.1 if cell == "hex8" else 5e-4)


def test_hemisphere_focus_refines_pole() -> None:
    coarse = hemisphere_solid(1.0, 6, 2, focus=1.0)
    fine = hemisphere_solid(1.0, 6, 2, focus=0.3)

    def pole_gap(m: Mesh) -> float:
        p = m.points[m.node_set("curved")]
        return float(np.sort(np.linalg.norm(p, axis=1))[1])

    assert pole_gap(fine) < 0.45 * pole_gap(coarse)


def test_generator_errors() -> None:
    with pytest.raises(ValueError, match="theta1"):
        sphere_patch(1.0, 0.5, PI, 0.0, 1.0, 0.1, 2, 2)
    with pytest.raises(ValueError, match="divisible by 4"):
        sphere_patch(1.0, 0.0, 1.0, 0.0, 2 * PI, 0.1, 2, 6)
    with pytest.raises(ValueError, match="hex18"):
        hemisphere_solid(1.0, 4, cell="hex18")
    with pytest.raises(ValueError, match="even"):
        hemisphere_solid(1.0, 3)
    with pytest.raises(ValueError, match="unknown cell"):
        block(1, 1, 1, 1, 1, 1, "tet4")
    with pytest.raises(ValueError, match="diameter"):
        cylinder_patch(1.0, 1.0, 0.0, 1.0, 2.5, 2, 2)


def test_face_tables_outward_on_reference_cell() -> None:
    for cell, table in FACES.items():
        if cell not in FACE_LABELS:  # tet4, tet10, hex20: tests/unit/test_cells.py
            continue
        n = face_normals(NODES[cell], table)
        for label, nf in zip(FACE_LABELS[cell], n, strict=True):
            axis, value = _FACE_MAPS[label][:2]
            expected = np.zeros(3)
            expected[axis] = value
            assert np.allclose(nf, expected), (cell, label)


def test_check_orientation_and_matching() -> None:
    mesh = block(2.0, 1.0, 1.0, 2, 1, 1, "hex27")
    bad = Mesh(mesh.points, "hex27", mesh.cells.copy())
    bad.cells[1] = bad.cells[1][[4, 5, 6, 7, 0, 1, 2, 3, 12, 13, 14, 15, 8, 9, 10, 11,
                                 16, 17, 18, 19, 20, 21, 22, 23, 25, 24, 26]]
    assert check_orientation(bad) == [1]
    top = mesh.face_set("zmax")
    matched, found = match_boundary_faces(mesh, top[:, [3, 2, 1, 0]])  # clockwise
    assert found.all() and np.array_equal(matched, top)
    _, found = match_boundary_faces(mesh, np.array([[0, 1, 2, 3]]))
    assert not found.any()
    assert faces_on_nodes(mesh, mesh.node_set("xmin")).shape == (1, 9)


def test_write_vtu_round_trip(tmp_path) -> None:
    mesh = block(1.0, 1.0, 2.0, 2, 1, 3, "hex27")
    path = tmp_path / "out.vtu"
    u = mesh.points * 0.1
    write_vtu(path, mesh, point_data={"u": u}, cell_data={"id": np.arange(mesh.n_cells)})
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.vtu"]  # no temp file left
    back = read_mesh(path)
    assert back.cell_type == "hex27"
    assert np.array_equal(back.cells, mesh.cells) and np.allclose(back.points, mesh.points)
    raw = meshio.read(path)
    assert np.allclose(raw.point_data["u"], u)
    hex8 = read_mesh(_write(tmp_path / "h8.vtu", block(1, 1, 1, 2, 2, 2)))
    assert hex8.cell_type == "hex8" and hex8.n_cells == 8


def _write(path, mesh):
    write_vtu(path, mesh)
    return path


def test_write_hex18_as_hex27(tmp_path) -> None:
    mesh = cylinder_patch(1.0, 1.0, 0.0, PI / 2, 0.1, 4, 2, "hex18")
    m = to_meshio(mesh, point_data={"z": mesh.points[:, 2]})
    assert m.cells[0].type == "hexahedron27"
    n_mid = (2 * 4 + 1) * (2 * 2 + 1)  # one mid-thickness node per through-thickness node pair
    assert m.points.shape[0] == mesh.n_nodes + n_mid
    assert np.allclose(m.point_data["z"], m.points[:, 2])
    back = read_mesh(_write(tmp_path / "s.vtu", mesh))
    assert np.array_equal(back.points[: mesh.n_nodes], mesh.points)
    assert _volume(back) == pytest.approx(_volume(Mesh(mesh.points, "hex18", mesh.cells)), rel=1e-12)


ABAQUS = """*HEADING
two hexahedra written by hand
*NODE
1, 0., 0., 0.
2, 1., 0., 0.
3, 2., 0., 0.
4, 0., 1., 0.
5, 1., 1., 0.
6, 2., 1., 0.
7, 0., 0., 1.
8, 1., 0., 1.
9, 2., 0., 1.
10, 0., 1., 1.
11, 1., 1., 1.
12, 2., 1., 1.
*ELEMENT, TYPE=C3D8, ELSET=EALL
1, 1, 2, 5, 4, 7, 8, 11, 10
2, 2, 3, 6, 5, 8, 9, 12, 11
*NSET, NSET=FIX
1, 4, 7, 10
*NSET, NSET=RIGHT, GENERATE
3, 12, 3
*ELSET, ELSET=LEFT
1
"""


def test_read_abaqus_sets(tmp_path) -> None:
    path = tmp_path / "two.inp"
    path.write_text(ABAQUS)
    mesh = read_mesh(path)
    assert mesh.cell_type == "hex8" and mesh.n_cells == 2 and mesh.n_nodes == 12
    assert np.array_equal(mesh.node_set("FIX"), [0, 3, 6, 9])
    assert np.array_equal(mesh.node_set("RIGHT"), [2, 5, 8, 11])
    assert np.array_equal(mesh.element_set("LEFT"), [0])
    assert np.array_equal(mesh.element_set("EALL"), [0, 1])
    assert check_orientation(mesh) == []


# two hexahedra and a physical surface "top" (z = 1, given clockwise seen from outside), a
# physical volume "body" and an unused node 13; Gmsh MSH 2.2 ascii
GMSH22 = """$MeshFormat
2.2 0 8
$EndMeshFormat
$PhysicalNames
2
2 1 "top"
3 2 "body"
$EndPhysicalNames
$Nodes
13
1 0 0 0
2 1 0 0
3 2 0 0
4 0 1 0
5 1 1 0
6 2 1 0
7 0 0 1
8 1 0 1
9 2 0 1
10 0 1 1
11 1 1 1
12 2 1 1
13 5 5 5
$EndNodes
$Elements
4
1 3 2 1 1 7 10 11 8
2 3 2 1 1 8 11 12 9
3 5 2 2 1 1 2 5 4 7 8 11 10
4 5 2 2 1 2 3 6 5 8 9 12 11
$EndElements
"""


def test_read_gmsh22_physical_groups(tmp_path) -> None:
    path = tmp_path / "two.msh"
    path.write_text(GMSH22)
    mesh = read_mesh(path)
    assert mesh.cell_type == "hex8" and mesh.n_cells == 2 and mesh.n_nodes == 12  # node 13 dropped
    assert np.array_equal(mesh.element_set("body"), [0, 1])
    top = mesh.face_set("top")
    assert top.shape == (2, 4)
    assert np.all(face_normals(mesh.points, top)[:, 2] > 0.0)  # re-ordered outward
    assert np.allclose(mesh.points[mesh.node_set("top"), 2], 1.0) and mesh.node_set("top").size == 6


# the same two hexahedra in Gmsh MSH 4.1 ascii: surface entity 1 (physical 1 "top"), volume
# entity 1 (physical 2 "body"); nodes given per entity block, tags not in order
GMSH41 = """$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
2
2 1 "top"
3 2 "body"
$EndPhysicalNames
$Entities
0 0 1 1
1 0 0 1 2 1 1 1 1 0
1 0 0 0 2 1 1 1 2 0
$EndEntities
$Nodes
2 12 1 12
2 1 0 6
10
7
8
11
12
9
0 1 1
0 0 1
1 0 1
1 1 1
2 1 1
2 0 1
3 1 0 6
1
2
3
4
5
6
0 0 0
1 0 0
2 0 0
0 1 0
1 1 0
2 1 0
$EndNodes
$Elements
2 4 1 4
2 1 3 2
1 7 10 11 8
2 8 11 12 9
3 1 5 2
3 1 2 5 4 7 8 11 10
4 2 3 6 5 8 9 12 11
$EndElements
"""


def test_read_gmsh41_physical_groups(tmp_path) -> None:
    path = tmp_path / "two41.msh"
    path.write_text(GMSH41)
    mesh = read_mesh(path)
    assert mesh.cell_type == "hex8" and mesh.n_cells == 2 and mesh.n_nodes == 12
    assert check_orientation(mesh) == []
    assert np.array_equal(mesh.element_set("body"), [0, 1])
    top = mesh.face_set("top")
    assert top.shape == (2, 4) and np.all(face_normals(mesh.points, top)[:, 2] > 0.0)
    assert np.allclose(mesh.points[mesh.node_set("top"), 2], 1.0) and mesh.node_set("top").size == 6


# Gmsh order of the 27-node hexahedron (Gmsh reference manual, node ordering): corners as VTK,
# edges 0-1, 0-3, 0-4, 1-2, 1-5, 2-3, 2-6, 3-7, 4-5, 4-7, 5-6, 6-7, faces 0321, 0154, 0473,
# 1265, 2376, 4567, then the centre.
_GMSH_H27 = [[0], [1], [2], [3], [4], [5], [6], [7],
             [0, 1], [0, 3], [0, 4], [1, 2], [1, 5], [2, 3], [2, 6], [3, 7], [4, 5], [4, 7],
             [5, 6], [6, 7], [0, 3, 2, 1], [0, 1, 5, 4], [0, 4, 7, 3], [1, 2, 6, 5],
             [2, 3, 7, 6], [4, 5, 6, 7], list(range(8))]


def test_read_gmsh_hex27_node_order(tmp_path) -> None:
    corners = NODES["hex27"][:8]
    xyz = np.array([corners[g].mean(axis=0) for g in _GMSH_H27])
    lines = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$Nodes", "27"]
    lines += [f"{k + 1} {x:.1f} {y:.1f} {z:.1f}" for k, (x, y, z) in enumerate(xyz)]
    lines += ["$EndNodes", "$Elements", "1", "1 12 2 1 1 " + " ".join(str(k + 1) for k in range(27))]
    lines += ["$EndElements", ""]
    path = tmp_path / "h27.msh"
    path.write_text("\n".join(lines))
    mesh = read_mesh(path)
    assert mesh.cell_type == "hex27"
    assert np.array_equal(mesh.points[mesh.cells[0]], NODES["hex27"])


def test_mesh_errors(tmp_path) -> None:
    bad = tmp_path / "bad.msh"
    bad.write_text("this is not a mesh\n$$$\n")
    with pytest.raises(MeshError, match="bad.msh: cannot read") as info:
        read_mesh(bad)
    assert "\n" not in str(info.value) and isinstance(info.value, ValueError)
    with pytest.raises(MeshError, match="no such file"):
        read_mesh(tmp_path / "missing.msh")
    quads = tmp_path / "quads.vtu"
    meshio.write(quads, meshio.Mesh(np.eye(4, 3), [("quad", np.array([[0, 1, 2, 3]]))]))
    with pytest.raises(MeshError, match="no supported volume cells.*quad"):
        read_mesh(quads)
