"""Shell bodies from mid-surface meshes (mesh/shell.py; docs/input.md "Shells from mid-surfaces"): the solid-shell
mesh a surface mesh and a thickness make, and a shell body so built against the same solid-shells generated
directly."""

from __future__ import annotations

import math

import meshio
import numpy as np
import pytest

from covcontact.io.loader import load_problem
from covcontact.io.validate import InputError
from covcontact.mesh.generators import cylinder_patch, plate
from covcontact.mesh.shell import ShellMeshError, extrude_surface


def _mid_surface(mesh, nen):
    """The mid-surface (points, cells) of a one-element-thick solid-shell mesh whose top nodes are its bottom
    nodes + n (as the generators number them)."""
    n = mesh.n_nodes // 2
    assert np.array_equal(mesh.cells[:, nen:], mesh.cells[:, :nen] + n)
    return 0.5 * (mesh.points[:n] + mesh.points[n:]), mesh.cells[:, :nen]


def test_a_flat_surface_gives_the_plate():
    """A plate's mid-surface and thickness give the plate generator's nodes and cells exactly, and its face sets."""
    ref = plate(2.0, 1.0, 0.1, 4, 2)
    X, surf = _mid_surface(ref, 4)
    m = extrude_surface(X, "quad4", surf, 0.1)
    np.testing.assert_array_equal(m.cells, ref.cells)
    np.testing.assert_allclose(m.points, ref.points, atol=1e-15)
    np.testing.assert_array_equal(np.sort(m.face_sets["top"], axis=1), np.sort(ref.face_sets["top"], axis=1))
    assert m.face_sets["edges"].shape[0] == 2 * (4 + 2)  # the lateral faces along the free edges
    # offsets: the given surface as the shell's top (Abaqus SPOS, offset +1/2) or bottom
    top = extrude_surface(X, "quad4", surf, 0.1, "top")
    np.testing.assert_allclose(top.points[:, 2], ref.points[:, 2] - 0.05, atol=1e-15)
    assert extrude_surface(X, "quad4", surf, 0.1, -0.5).points[:, 2].min() == pytest.approx(0.05)


@pytest.mark.parametrize("cell, surface", [("hex8", "quad4"), ("hex18", "quad9")])
def test_directors_on_a_cylinder(cell, surface):
    """On a cylinder's mid-surface (radius 2, thickness 0.1) the directors are radial: every node inside the patch
    (and, with quad9, along its free edges to the parabolic interpolation's 1.3e-5) lies at R -+ t/2 on the radius
    through its mid-surface point."""
    R, t = 2.0, 0.1
    ref = cylinder_patch(R, 3.0, 0.0, 1.2, t, 6, 4, cell=cell)
    nen = ref.cells.shape[1] // 2
    X, surf = _mid_surface(ref, nen)
    m = extrude_surface(X, surface, surf, t)
    err = np.abs(m.points - ref.points).max(axis=1)
    n = X.shape[0]
    phi = np.arctan2(X[:, 1], X[:, 0])
    inside = np.tile((phi > 1e-9) & (phi < 1.2 - 1e-9), 2)
    assert err[inside].max() < 1e-12
    if surface == "quad9":
        assert err.max() < 2e-5
    else:  # a free edge's node takes its one flat facet's normal: off by about t/2 sin(h / 2R)
        assert err.max() == pytest.approx(0.5 * t * math.sin(0.1), rel=0.05)
    assert m.cell_type == cell and m.n_nodes == 2 * n


def test_orientation_made_consistent_and_moebius_refused():
    """Cells given with mixed orientations are turned to agree with the first one; a Moebius strip cannot be and
    is refused naming two cells."""
    ref = plate(2.0, 1.0, 0.1, 4, 2)
    X, surf = _mid_surface(ref, 4)
    mixed = surf.copy()
    mixed[1::2] = mixed[1::2][:, [0, 3, 2, 1]]
    m = extrude_surface(X, "quad4", mixed, 0.1)
    assert np.allclose(m.points[m.face_sets["top"].ravel(), 2], 0.1)  # every top face on top
    # a Moebius strip of 8 quads
    k = 8
    a = np.linspace(0.0, 2.0 * math.pi, k, endpoint=False)
    pts = []
    for s in (-0.2, 0.2):
        pts.append(np.stack([(1 + s * np.cos(a / 2)) * np.cos(a), (1 + s * np.cos(a / 2)) * np.sin(a),
                             s * np.sin(a / 2)], axis=1))
    P = np.vstack(pts)
    cells = [[i, i + 1, k + i + 1, k + i] for i in range(k - 1)] + [[k - 1, k, 0, 2 * k - 1]]
    with pytest.raises(ShellMeshError, match="cannot be oriented"):
        extrude_surface(P, "quad4", np.array(cells), 0.01)


def test_triangles_and_quad8():
    """tri3 cells become three quad4 each, sharing the edge mid-points with their neighbours (the mesh conforms:
    area kept, no duplicate node); quad8 cells get their centre node (the serendipity surface's centre)."""
    X = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    tri = np.array([[0, 1, 2], [0, 2, 3]])
    m = extrude_surface(X, "tri3", tri, 0.1, element_sets={"second": np.array([1])})
    assert m.cells.shape == (6, 8) and m.n_nodes == 2 * (4 + 5 + 2)
    from covcontact.mesh.faces import face_normals

    area = np.linalg.norm(face_normals(m.points, m.face_sets["top"]), axis=1)
    np.testing.assert_array_equal(m.element_sets["second"], [3, 4, 5])
    q = m.points[m.face_sets["top"]]
    quad_area = 0.5 * np.linalg.norm(np.cross(q[:, 2] - q[:, 0], q[:, 3] - q[:, 1]), axis=1)
    assert quad_area.sum() == pytest.approx(1.0, rel=1e-14) and np.all(area > 0)
    X8 = np.array([[0.0, 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0], [1, 0, 0], [2, 0.5, 0], [1, 1, 0], [0, 0.5, 0]])
    m8 = extrude_surface(X8, "quad8", np.arange(8)[None], 0.2)
    assert m8.cell_type == "hex18"
    np.testing.assert_allclose(m8.points[8], [1.0, 0.5, -0.1])


CANTILEVER = """
[problem]
name = "cantilever"
[[bodies]]
name = "p"
material = { model = "svk", E = 1.0e5, nu = 0.3 }
MESH
[[dirichlet]]
set = "p.xmin"
[[force]]
set = "p.xmax"
value = [0.0, 0.0, -0.002]
distribution = "total"
[steps]
count = 2
[output]
vtu = false
"""


def test_shell_body_equals_the_generated_plate(tmp_path):
    """A cantilever plate (2 x 1, t = 0.1, 8 x 4 solid-shells, a tip load) as a shell body from its mid-surface mesh
    (a Gmsh file with physical curves for the clamped and the loaded edge) and as the plate generator's solid-shells:
    the same tip deflection to 1e-10."""
    ref = plate(2.0, 1.0, 0.1, 8, 4)
    X, surf = _mid_surface(ref, 4)
    xmin = np.flatnonzero(np.isclose(X[:, 0], 0.0))
    xmax = np.flatnonzero(np.isclose(X[:, 0], 2.0))
    lines_min = np.array([[a, b] for a, b in zip(xmin[:-1], xmin[1:])])
    lines_max = np.array([[a, b] for a, b in zip(xmax[:-1], xmax[1:])])
    msh = meshio.Mesh(X, [("quad", surf), ("line", lines_min), ("line", lines_max)],
                      cell_data={"gmsh:physical": [np.full(len(surf), 3), np.full(len(lines_min), 1),
                                                   np.full(len(lines_max), 2)],
                                 "gmsh:geometrical": [np.full(len(surf), 1), np.full(len(lines_min), 1),
                                                      np.full(len(lines_max), 2)]},
                      field_data={"xmin": np.array([1, 1]), "xmax": np.array([2, 1]), "plate": np.array([3, 2])})
    meshio.write(tmp_path / "surface.msh", msh, file_format="gmsh22", binary=False)
    shell = tmp_path / "shell.toml"
    shell.write_text(CANTILEVER.replace("MESH", 'shell = { thickness = 0.1 }\nmesh = { file = "surface.msh" }'))
    solid = tmp_path / "solid.toml"
    solid.write_text(CANTILEVER.replace("MESH", 'formulation = "solid-shell"\nmesh = { generator = "plate", '
                                        'lx = 2.0, ly = 1.0, t = 0.1, nx = 8, ny = 4 }'))
    a = load_problem(shell).run(out=tmp_path / "a")
    b = load_problem(solid).run(out=tmp_path / "b")
    assert a.exit_code == 0 and b.exit_code == 0
    assert a.model.problem.bodies[0].mesh.element_sets["plate"].size == 32
    wa, wb = a.u.reshape(-1, 3)[:, 2].min(), b.u.reshape(-1, 3)[:, 2].min()
    assert wa < -1e-4 and wa == pytest.approx(wb, rel=1e-10)


@pytest.mark.parametrize("shell, message", [
    ("shell = { thickness = -0.1 }", r"thickness: must be a positive number"),
    ('shell = { thickness = 0.1, offset = "midle" }', "middle"),
    ('shell = { thickness = 0.1 }\nformulation = "solid"', "leave out formulation"),
])
def test_bad_shell_input(tmp_path, shell, message):
    ref = plate(2.0, 1.0, 0.1, 2, 1)
    X, surf = _mid_surface(ref, 4)
    meshio.write(tmp_path / "s.vtu", meshio.Mesh(X, [("quad", surf)]))
    path = tmp_path / "p.toml"
    path.write_text(CANTILEVER.replace("MESH", shell + '\nmesh = { file = "s.vtu" }')
                    .replace('set = "p.xmin"', 'set = "p.edges"').replace("p.xmax", "p.top"))
    with pytest.raises(InputError, match=message):
        load_problem(path)


def test_a_volume_mesh_is_no_surface(tmp_path):
    ref = plate(2.0, 1.0, 0.1, 2, 1)
    meshio.write(tmp_path / "v.vtu", meshio.Mesh(ref.points, [("hexahedron", ref.cells)]))
    path = tmp_path / "p.toml"
    path.write_text(CANTILEVER.replace("MESH", 'shell = { thickness = 0.1 }\nmesh = { file = "v.vtu" }'))
    with pytest.raises(InputError, match="holds volume cells"):
        load_problem(path)


def test_paper_sphere_example_from_a_midsurface_mesh(tmp_path):
    """examples/shells/sphere_q9_midsurface.toml (the seed paper's Example 2 with the plate a Gmsh mid-surface mesh
    of quad9 cells) against examples/paper/sphere_q9.toml (the plate generator's hex18 solid-shells): the first three
    load steps (1, 5 and 10 % of the load, the contact's onset) take the same Newton iterations and the same
    contact forces to 1e-9. Measured over the paper's 100 steps: 437 iterations each, contact forces equal to
    8.5e-13 of the largest."""
    from pathlib import Path

    from covcontact.problem import Steps

    root = Path(__file__).resolve().parents[2] / "examples"
    runs = []
    for path in (root / "shells" / "sphere_q9_midsurface.toml", root / "paper" / "sphere_q9.toml"):
        problem = load_problem(path)
        problem.steps = Steps((0.01, 0.05, 0.1))
        problem.output.vtu = False
        problem.output.pictures = False
        res = problem.run(out=tmp_path / path.stem)
        assert res.exit_code == 0
        runs.append(res.summary["steps"])
    a, b = runs
    assert [s["iterations"] for s in a] == [s["iterations"] for s in b]
    fa, fb = (np.array([s["contact_force"] for s in r]) for r in (a, b))
    assert np.abs(fa).max() > 0.0
    np.testing.assert_allclose(fa, fb, rtol=0.0, atol=1e-9 * np.abs(fb).max())


@pytest.mark.parametrize("fold, warned", [(90.0, True), (30.0, False)])
def test_a_sharp_fold_of_the_mid_surface_is_warned(tmp_path, fold, warned):
    """The plate's mid-surface folded about the line x = 1 by ``fold`` degrees: beyond 45 degrees between the cells'
    normals at a node (a junction or a crease, where the mean director bends the shell) the run starts with a warning
    naming the body, the node and the angle (summary.json ``warnings``); a 30 degree fold runs without one."""
    ref = plate(2.0, 1.0, 0.1, 4, 2)
    X, surf = _mid_surface(ref, 4)
    a = np.radians(fold)
    far = X[:, 0] > 1.0 + 1e-12
    X = X.copy()
    X[far, 2] = (X[far, 0] - 1.0) * np.sin(a)
    X[far, 0] = 1.0 + (X[far, 0] - 1.0) * np.cos(a)
    meshio.write(tmp_path / "s.vtu", meshio.Mesh(X, [("quad", surf)]))
    path = tmp_path / "p.toml"
    path.write_text(CANTILEVER.replace("MESH", 'shell = { thickness = 0.1 }\nmesh = { file = "s.vtu" }')
                    .replace('set = "p.xmin"', 'set = "p.edges"').replace("p.xmax", "p.top"))
    res = load_problem(path).run(out=tmp_path / "o")
    words = [w for w in res.summary.get("warnings", []) if "junction or a crease" in w]
    if warned:
        assert len(words) == 1 and f"up to {fold:.0f}" in words[0] and "body 'p'" in words[0], words
    else:
        assert not words
