"""The tetrahedra, wedge and 20-node brick (tet4, tet10, wedge6, hex20): shape functions, rules, element tangents
against finite differences (SVK, Neo-Hooke, J2 in elastic, plastic and unloading states) and the patch test
(a homogeneous deformation leaves no force on interior nodes of a distorted mesh)."""

from __future__ import annotations

import numpy as np
import pytest

from covcontact.assembly import Pattern
from covcontact.elements import SolidBody
from covcontact.fem.cells import CELLS, NODES, rule, shapes
from covcontact.materials import J2Plasticity, NeoHooke, SaintVenantKirchhoff
from covcontact.mesh.convert import SOURCE, convert
from covcontact.mesh.generators import block

MATERIALS = {"svk": SaintVenantKirchhoff(E=200.0, nu=0.3), "neo-hooke": NeoHooke(E=200.0, nu=0.3)}


@pytest.mark.parametrize("cell", CELLS)
def test_shapes_interpolate_and_rules_integrate(cell):
    """N_a(x_b) = delta_ab, sum N = 1, sum dN = 0, dN against differences, the rule's weights sum to the volume
    and integrate the element's polynomials exactly (the volume of a distorted straight-edged cell)."""
    N, _ = shapes(cell, NODES[cell])
    np.testing.assert_allclose(N, np.eye(len(N)), atol=1e-14)
    p, w = rule(cell)
    N, dN = shapes(cell, p)
    np.testing.assert_allclose(N.sum(axis=1), 1.0, atol=1e-14)
    np.testing.assert_allclose(dN.sum(axis=1), 0.0, atol=1e-13)
    x = p[0] + 0.013
    h = 1e-6
    fd = np.stack([(shapes(cell, x + h * e)[0] - shapes(cell, x - h * e)[0])[0] / (2 * h) for e in np.eye(3)], axis=1)
    np.testing.assert_allclose(fd, shapes(cell, x)[1][0], atol=1e-9)
    assert w.sum() == pytest.approx({"tet4": 1 / 6, "tet10": 1 / 6, "wedge6": 1.0, "hex20": 8.0}[cell])


def one_element(cell: str, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    X = NODES[cell] * [1.0, 0.8, 1.3] + 0.06 * rng.uniform(-1.0, 1.0, NODES[cell].shape)
    return np.ascontiguousarray(X), np.arange(len(X))[None]


def residual(body, u, state=None) -> np.ndarray:
    r = np.zeros(3 * body.n_nodes)
    assert body.assemble(u, np.zeros(0), r, None, want_K=False, state=state) == -1
    return r


def tangent(body, u, state=None):
    P = Pattern(body.n_nodes, [body.cells])
    data = P.zeros()
    r = np.zeros(3 * body.n_nodes)
    assert body.assemble(u, data, r, P, state=state) == -1
    return P.csr(data).toarray(), r


def _fd(body, u, state=None):
    h = 1e-6
    K = np.empty((u.size, u.size))
    for j in range(u.size):
        up, um = u.ravel().copy(), u.ravel().copy()
        up[j] += h
        um[j] -= h
        K[:, j] = (residual(body, up, state) - residual(body, um, state)) / (2 * h)
    return K


@pytest.mark.parametrize("mat", list(MATERIALS))
@pytest.mark.parametrize("cell", CELLS)
def test_tangent_matches_differences(cell, mat):
    X, cells = one_element(cell, 1)
    body = SolidBody(cell, X, cells, MATERIALS[mat])
    assert body.check_reference() == []
    u = 0.1 * np.random.default_rng(2).uniform(-1.0, 1.0, X.shape)
    K, r = tangent(body, u)
    np.testing.assert_allclose(r, residual(body, u), atol=1e-13 * np.abs(r).max())
    Kfd = _fd(body, u)
    assert np.abs(K - Kfd).max() <= 1e-6 * np.abs(K).max()


@pytest.mark.parametrize("cell", CELLS)
def test_plastic_tangent_matches_differences(cell):
    """J2 with linear hardening: the consistent tangent against differences of the residual with the history of
    the last commit fixed, in a plastic state and in an unloading (elastic from a plastic) state."""
    mat = J2Plasticity(E=200.0, nu=0.3, yield_stress=0.5, hardening={"law": "linear", "modulus": 20.0})
    X, cells = one_element(cell, 3)
    body = SolidBody(cell, X, cells, mat)
    rng = np.random.default_rng(4)
    direction = rng.uniform(-1.0, 1.0, X.shape)
    state = body.new_state()
    checked = 0
    for scale in (0.05, 0.1, 0.08):  # load, load further (plastic), unload
        u = scale * direction
        trial = {"hist": state["hist"].copy(), "hist_n": state["hist"].copy()}
        K, _ = tangent(body, u, trial)
        Kfd = _fd(body, u, {"hist": state["hist"].copy(), "hist_n": state["hist"].copy()})
        assert np.abs(K - Kfd).max() <= 1e-6 * np.abs(K).max(), scale
        state = {"hist": trial["hist"]}
        checked += 1
    assert checked == 3 and np.abs(state["hist"]).max() > 0  # it yielded


def _split(cell: str, seed: int = 0):
    """A distorted mesh of ``cell`` on [0, 2]^3 (2 x 2 x 2 bricks split or trimmed) and its interior nodes."""
    m = convert(block(lx=2.0, ly=2.0, lz=2.0, nx=2, ny=2, nz=2, cell=SOURCE[cell]), cell)
    X, cells = m.points.copy(), m.cells
    rng = np.random.default_rng(seed)
    corners = np.unique(cells[:, :4]) if cell == "tet10" else np.arange(len(X))
    interior = corners[np.all((X[corners] > 1e-9) & (X[corners] < 2 - 1e-9), axis=1)]
    X[interior] += 0.15 * rng.uniform(-1.0, 1.0, (len(interior), 3))
    if cell == "tet10":  # straight edges: the mid-nodes at the midpoints of the distorted corners
        e = cells[:, 4:].ravel()
        ends = cells[:, [[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]]].reshape(-1, 2)
        X[e] = 0.5 * (X[ends[:, 0]] + X[ends[:, 1]])
    interior = np.flatnonzero(np.all((X > 1e-9) & (X < 2 - 1e-9), axis=1))
    return np.ascontiguousarray(X), np.ascontiguousarray(cells, dtype=np.int64), interior


@pytest.mark.parametrize("cell", CELLS)
def test_patch_test(cell):
    """A homogeneous finite deformation x = F X on a distorted mesh: no force on the interior nodes (the stress is
    uniform and the rule integrates the gradients exactly), and the element stresses are the homogeneous one."""
    X, cells, interior = _split(cell)
    body = SolidBody(cell, X, cells, NeoHooke(E=200.0, nu=0.3))
    assert body.check_reference() == []
    F = np.array([[1.1, 0.05, 0.0], [0.02, 0.95, 0.03], [0.0, -0.04, 1.05]])
    u = X @ F.T - X
    r = residual(body, u).reshape(-1, 3)
    assert np.abs(r[interior]).max() <= 1e-10 * np.abs(r).max()
    cauchy = body.stress(u).cauchy
    np.testing.assert_allclose(cauchy, cauchy[0][None, :].repeat(len(cauchy), 0), atol=1e-9 * np.abs(cauchy).max())


TENSION = """
[problem]
name = "bar"
[[bodies]]
name = "bar"
element = "CELL"
material = { model = "svk", E = 200.0, nu = 0.3 }
mesh = MESH
[bodies.sets]
x0 = { box = [[-1e-9, -1.0, -1.0], [1e-9, 3.0, 3.0]] }
x1 = { box = [[1.999999999, -1.0, -1.0], [2.1, 3.0, 3.0]] }
y0 = { box = [[-1.0, -1e-9, -1.0], [3.0, 1e-9, 3.0]] }
z0 = { box = [[-1.0, -1.0, -1e-9], [3.0, 3.0, 1e-9]] }
[[dirichlet]]
set = "bar.x0"
components = "x"
[[dirichlet]]
set = "bar.y0"
components = "y"
[[dirichlet]]
set = "bar.z0"
components = "z"
[[dirichlet]]
name = "pull"
set = "bar.x1"
components = "x"
value = 0.1
[steps]
count = 2
"""


@pytest.mark.parametrize("cell", CELLS)
def test_mesh_file_run_and_vtu(tmp_path, cell):
    """A body of ``cell`` read from a mesh file (VTU written by meshio, the distorted mesh of the patch test)
    stretched by 5 % in uniaxial stress: the reaction equals the closed form of St. Venant-Kirchhoff and the hex8
    generator's to 1e-8 (the deformation is homogeneous, which every element reproduces), and the result files
    hold the cells with their own VTK type, whose boundary the pictures draw."""
    import meshio

    from covcontact.io.loader import load_problem

    X, cells, _ = _split(cell)
    vtk = {"tet4": "tetra", "tet10": "tetra10", "wedge6": "wedge", "hex20": "hexahedron20"}[cell]
    meshio.write(tmp_path / "bar.vtu", meshio.Mesh(X, [(vtk, cells)]))
    reactions = {}
    generated = '{ generator = "block", lx = 2.0, ly = 2.0, lz = 2.0, nx = 2, ny = 2, nz = 2 }'
    for name, element, mesh in ((cell, cell, '{ file = "bar.vtu" }'), ("hex8", "hex8", generated)):
        path = tmp_path / f"{name}.toml"
        path.write_text(TENSION.replace("CELL", element).replace("MESH", mesh))
        res = load_problem(path).run(out=tmp_path / name)
        assert res.exit_code == 0
        reactions[name] = res.summary["steps"][-1]["reactions"]["bar.x1"][0]
    # uniaxial stress, SVK: S = E E_xx with E_xx = (1.05^2 - 1) / 2, first Piola P = F S, on the area 4
    lam = 1.05
    assert reactions["hex8"] == pytest.approx(4.0 * lam * 200.0 * (lam ** 2 - 1) / 2, rel=1e-8)
    assert reactions[cell] == pytest.approx(reactions["hex8"], rel=1e-8)
    out = meshio.read(tmp_path / cell / "step_0002.vtu")
    assert [b.type for b in out.cells] == [vtk]
    assert out.point_data["displacement"][:, 0].max() == pytest.approx(0.1)
    # the pictures draw the boundary: 6 sides of 2 x 2 squares, as triangles where the cells are tetrahedra (and
    # on the two sides the wedges' diagonal cuts)
    from covcontact.io.pictures import surface_quads

    quads, _ = surface_quads(out)
    assert len(quads) == {"tet4": 48, "tet10": 48, "wedge6": 32, "hex20": 24}[cell]


@pytest.mark.parametrize("cell", ["tet4", "tet10", "hex20"])
def test_pressure_on_their_faces(tmp_path, cell):
    """The generators' face sets carry over (tri3, tri6, quad8 faces), and a pressure on them gives the consistent
    nodal forces: a tension p = 10 on the end x = 2 of the bar (on rollers) is carried by the support with the
    force p A = 40 and leaves every node of the end at the same displacement (a homogeneous stress: the tri6 and
    quad8 corner forces are zero or negative, which a lumped load would get wrong)."""
    from covcontact.io.loader import load_problem

    path = tmp_path / "p.toml"
    text = TENSION.replace("CELL", cell).replace("MESH", '{ generator = "block", lx = 2.0, ly = 2.0, lz = 2.0, '
                                                         'nx = 2, ny = 2, nz = 2 }')
    text = text.replace('[[dirichlet]]\nname = "pull"\nset = "bar.x1"\ncomponents = "x"\nvalue = 0.1\n',
                        '[[pressure]]\nset = "bar.xmax"\nvalue = -10.0\n')
    path.write_text(text)
    prob = load_problem(path)
    mesh = prob.bodies[0].mesh
    assert mesh.face_sets["xmax"].shape == {"tet4": (8, 3), "tet10": (8, 6), "hex20": (4, 8)}[cell]
    res = prob.run(out=tmp_path / "out")
    assert res.exit_code == 0
    assert res.summary["steps"][-1]["reactions"]["bar.x0"][0] == pytest.approx(-40.0, rel=1e-10)
    ux = res.u.reshape(-1, 3)[mesh.node_sets["xmax"], 0]
    assert ux.min() > 0 and ux.max() - ux.min() < 1e-9 * ux.max()


def test_tetrahedral_contact_surfaces_are_read(tmp_path):
    """A tetrahedral body as a contact master (tri6 facets), slave or self-contact surface loads; area weighting on
    its tri6 faces is one line."""
    from covcontact.io.loader import load_problem
    from covcontact.io.validate import InputError

    base = TENSION.replace("CELL", "tet10").replace("MESH", '{ generator = "block", lx = 2.0, ly = 2.0, lz = 2.0, '
                                                            'nx = 2, ny = 2, nz = 2 }')
    other = ('\n[[bodies]]\nname = "cap"\nelement = "hex8"\nmaterial = { model = "svk", E = 200.0, nu = 0.3 }\n'
             'mesh = { generator = "block", lx = 2.0, ly = 2.0, lz = 1.0, nx = 2, ny = 2, nz = 1, '
             'origin = [0.0, 0.0, 2.0] }\n')
    path = tmp_path / "p.toml"
    two = base.replace("[[dirichlet]]", other + "\n[[dirichlet]]", 1)
    path.write_text(two + '\n[[contact]]\nslave = "cap.zmin"\nmaster = "bar.zmax"\npenalty = 1.0e4\n')
    prob = load_problem(path)
    assert prob.contacts[0].master == ("bar", "zmax")
    path.write_text(two + '\n[[contact]]\nslave = "bar.zmax"\nmaster = "cap.zmin"\npenalty = 1.0e4\ntype = "sts"\n')
    assert load_problem(path).contacts[0].slave == ("bar", "zmax")
    path.write_text(two + '\n[[contact]]\nself = "bar.zmax"\npenalty = 1.0e4\n')
    assert load_problem(path).contacts[0].self_surfaces == (("bar", "zmax"),)
    path.write_text(two + '\n[[contact]]\nslave = "bar.zmax"\nmaster = "cap.zmin"\npenalty = 1.0e4\n'
                    'weighting = "area"\n')
    # area weighting on tri6 faces: CalculiX's node-to-face spring areas (corners none, mid-nodes a third of a face)
    assert load_problem(path).contacts[0].weighting == "area"
    path.write_text(two + '\n[[contact]]\nslave = "bar.zmax"\nmaster = "cap.zmin"\npenalty = 1.0e4\n'
                    'weighting = "areas"\n')
    with pytest.raises(InputError) as err:  # (a misspelt choice is one line naming the key)
        load_problem(path)
    assert "contact[0]" in str(err.value) and "weighting" in str(err.value) and "\n" not in str(err.value)


@pytest.mark.parametrize("cell, kind", [("tet10", "tetra10"), ("hex20", "hexahedron20"), ("wedge6", "wedge"),
                                        ("tet4", "tetra")])
def test_read_from_gmsh_and_abaqus_files(tmp_path, cell, kind):
    """The cells come back from Gmsh (msh 2.2) and Abaqus files in covcontact's node order (meshio maps
    Gmsh's tet10 and hex20 orders onto VTK's), with positive volumes and the element sets of the file."""
    import meshio

    from covcontact.mesh.io import read_mesh

    X, cells, _ = _split(cell)
    half = np.flatnonzero(X[cells].mean(axis=1)[:, 0] < 1.0)
    for fmt, suffix in (("gmsh22", ".msh"), ("abaqus", ".inp")):
        path = tmp_path / f"m_{fmt}{suffix}"
        tags = np.where(np.isin(np.arange(len(cells)), half), 1, 2)
        m = meshio.Mesh(X, [(kind, cells)], cell_data={"gmsh:physical": [tags], "gmsh:geometrical": [tags]})
        if fmt.startswith("gmsh"):
            m.field_data = {"left": np.array([1, 3]), "right": np.array([2, 3])}
        else:
            m.cell_sets = {"left": [half]}
            m.cell_data = {}
        meshio.write(path, m, file_format=fmt)
        mesh = read_mesh(path)
        assert mesh.cell_type == cell
        np.testing.assert_allclose(mesh.points[mesh.cells], X[cells], atol=1e-12)
        body = SolidBody(cell, mesh.points, mesh.cells, MATERIALS["svk"])
        assert body.check_reference() == []
        assert np.array_equal(mesh.element_sets["left"], half), fmt


def test_hex20_reduced_integration(tmp_path):
    """options = { integration = "reduced" } (hex20 only, as C3D20R): 8 Gauss points; the tangent matches
    differences, the homogeneous bar gives the closed form, and other cells are refused with one line."""
    from covcontact.io.loader import load_problem
    from covcontact.io.validate import InputError

    X, cells = one_element("hex20", 5)
    body = SolidBody("hex20", X, cells, MATERIALS["neo-hooke"], integration="reduced")
    assert body.weights.size == 8
    u = 0.1 * np.random.default_rng(6).uniform(-1.0, 1.0, X.shape)
    K, _ = tangent(body, u)
    assert np.abs(K - _fd(body, u)).max() <= 1e-6 * np.abs(K).max()
    text = TENSION.replace("MESH", '{ generator = "block", lx = 2.0, ly = 2.0, lz = 2.0, nx = 2, ny = 2, nz = 2 }')
    text = text.replace("[bodies.sets]", 'options = { integration = "reduced" }\n[bodies.sets]')
    path = tmp_path / "p.toml"
    path.write_text(text.replace("CELL", "hex20"))
    res = load_problem(path).run(out=tmp_path / "out")
    assert res.exit_code == 0
    assert res.summary["steps"][-1]["reactions"]["bar.x1"][0] == pytest.approx(43.05, rel=1e-8)
    path.write_text(text.replace("CELL", "tet10"))
    with pytest.raises(InputError) as err:
        load_problem(path)
    assert 'integration = "reduced" is for hex20' in str(err.value) and "\n" not in str(err.value)


def test_area_weighting_on_quadratic_faces_is_read(tmp_path):
    """Node-to-surface with area weighting on tri6 faces is read (CalculiX's node-to-face spring areas: the corner
    nodes carry none, tests/unit/test_nts_quadratic_slaves.py checks the forces); nodal weighting stays the default."""
    from covcontact.io.loader import load_problem

    base = TENSION.replace("CELL", "tet10").replace("MESH", '{ generator = "block", lx = 2.0, ly = 2.0, lz = 2.0, '
                                                            'nx = 2, ny = 2, nz = 2 }')
    floor = '\n[[rigid]]\nname = "floor"\nshape = "plane"\npoint = [0.0, 0.0, -0.01]\nnormal = [0.0, 0.0, 1.0]\n'
    path = tmp_path / "p.toml"
    path.write_text(base + floor + '\n[[contact]]\nslave = "bar.zmin"\nmaster = "floor"\npenalty = 1.0e4\n'
                    'weighting = "area"\n')
    assert load_problem(path).contacts[0].weighting == "area"
    path.write_text(base + floor + '\n[[contact]]\nslave = "bar.zmin"\nmaster = "floor"\npenalty = 1.0e4\n')
    assert load_problem(path).contacts[0].weighting == "nodal"


def _file_body(tmp_path, cells, points, element):
    import meshio

    meshio.write(tmp_path / "m.msh", meshio.Mesh(points, cells), file_format="gmsh22", binary=False)
    path = tmp_path / "p.toml"
    path.write_text(f'[problem]\nname = "f"\n[[bodies]]\nname = "b"\nelement = "{element}"\n'
                    'material = { model = "svk", E = 1.0, nu = 0.3 }\nmesh = { file = "m.msh" }\n'
                    '[steps]\ncount = 1\n')
    return path


def test_inverted_cells_and_unsupported_cell_types_are_one_line(tmp_path):
    """A file whose tet10 cell 0 is mirrored (node order) is an input error naming that cell; a file with pyramids
    beside hexahedra names the type and the supported ones (instead of dropping the pyramids)."""
    from covcontact.io.loader import load_problem
    from covcontact.io.validate import InputError

    m = convert(block(1.0, 1.0, 1.0, 1, 1, 1, "hex8"), "tet10")
    cells = m.cells.copy()
    cells[0] = m.cells[0][[0, 2, 1, 3, 6, 5, 4, 7, 9, 8]]  # corners 1 and 2 swapped, mid-nodes to match
    with pytest.raises(InputError) as err:
        load_problem(_file_body(tmp_path, [("tetra10", cells)], m.points, "tet10"))
    msg = str(err.value)
    assert "bodies[0].mesh" in msg and "1 of 6 tet10 cells are inverted or degenerate" in msg and "cells 0 " in msg
    h = block(1.0, 1.0, 1.0, 1, 1, 1, "hex8")
    pts = np.vstack([h.points, [[0.5, 0.5, 1.5]]])
    pyramid = np.array([[4, 5, 6, 7, 8]])
    with pytest.raises(InputError) as err:
        load_problem(_file_body(tmp_path, [("hexahedron", h.cells), ("pyramid", pyramid)], pts, "hex8"))
    msg = str(err.value)
    assert "holds pyramid cells, which covcontact does not have" in msg and "hexahedron" in msg
    assert "\n" not in msg
