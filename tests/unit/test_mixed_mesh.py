"""Bodies of several cell types (hexahedra and wedges, wedges and tetrahedra): the mesh file read with its blocks,
the boundary across them, the element tangent of a mixed body against finite differences, homogeneous deformations
reproduced exactly (elastic and plastic, the history of two cell types side by side), the mass, the VTU blocks,
the materials by element set over both types, contact on a mixed body, resume, and the one-line errors (cells that
do not conform, types that do not mix)."""

from __future__ import annotations

from pathlib import Path

import meshio
import numpy as np
import pytest

from covcontact.assembly import Pattern
from covcontact.elements import SolidBody
from covcontact.elements.composite import CompositeBody
from covcontact.materials import J2Plasticity, NeoHooke
from covcontact.mesh import Mesh, read_mesh
from covcontact.mesh.convert import convert
from covcontact.mesh.faces import all_boundary_faces, face_normals, nonconforming_cells
from covcontact.mesh.generators import block
from covcontact.mesh.io import MeshError

DATA = Path(__file__).resolve().parents[1] / "data"
MIXED = DATA / "mixed_block.msh"  # hexahedra (x < 1) and wedges (x > 1) on [0, 2] x [0, 1] x [0, 1]


def test_gmsh_file_of_bricks_and_wedges():
    """The file's two volume types form one mesh: its blocks, its boundary (triangles and quadrilaterals across the
    blocks, none of the faces the bricks share with the wedges), face sets of one type each, and the sets named in
    mesh order."""
    m = read_mesh(MIXED)
    assert m.is_mixed and m.cell_types == ("hex8", "wedge6")
    assert [len(b.cells) for b in m.blocks] == [18, 52] and m.n_cells == 70
    with pytest.raises(ValueError, match="no single connectivity"):
        m.connectivity()
    (tri, _, _), (quad, _, _) = all_boundary_faces(m)
    # the boundary of the box is its area 10 exactly: triangles on z = 0 and z = 1, quadrilaterals elsewhere
    tri_area = 0.5 * np.linalg.norm(face_normals(m.points, tri), axis=1).sum()  # (flat faces: exact areas)
    quad_area = 4.0 * np.linalg.norm(face_normals(m.points, quad), axis=1).sum()
    assert tri_area == pytest.approx(2.0, rel=1e-12)  # the wedges' ends: 1 x 1 on z = 0 and on z = 1
    assert tri_area + quad_area == pytest.approx(10.0, rel=1e-12)
    x = m.points[quad].mean(axis=1)[:, 0]
    assert not np.any(np.isclose(x, 1.0))  # the bricks' faces on x = 1 meet the wedges' (inside)
    assert nonconforming_cells(m).shape == (0, 2)
    assert m.face_sets["xmin"].shape == (6, 4) and m.face_sets["xmax"].shape == (6, 4)
    assert "zmin" not in m.face_sets and m.node_sets["zmin"].size > 0  # (triangles and quadrilaterals: nodes only)
    assert m.element_sets["block"].tolist() == list(range(70))
    # one cell type asked for: just those cells
    assert read_mesh(MIXED, cell_type="wedge6").cell_type == "wedge6"


def _mixed_box(split_x: float = 1.0, seed: int = 0, distort: float = 0.12):
    """A 2 x 1 x 1 box of 4 x 2 x 2 bricks whose columns beyond ``split_x`` are cut into wedges, the interior nodes
    moved randomly; returns the mesh and its interior nodes."""
    m = block(2.0, 1.0, 1.0, 4, 2, 2, "hex8")
    centre = m.points[m.cells].mean(axis=1)
    mixed = convert(m, "wedge6", np.flatnonzero(centre[:, 0] > split_x))
    X = mixed.points
    inside = np.flatnonzero(np.all((X > 1e-9) & (X < np.array([2.0, 1.0, 1.0]) - 1e-9), axis=1))
    X[inside] += distort * np.random.default_rng(seed).uniform(-1.0, 1.0, (inside.size, 3))
    return mixed, inside


def _composite(mesh: Mesh, materials) -> CompositeBody:
    return CompositeBody([(np.arange(b.first, b.first + len(b.cells)), SolidBody(b.cell_type, mesh.points, b.cells, mat))
                          for b, mat in zip(mesh.blocks, materials)])


def _residual(body, u, state=None) -> np.ndarray:
    r = np.zeros(3 * body.n_nodes)
    assert body.assemble(u, np.zeros(0), r, None, want_K=False, state=state) == -1
    return r


def test_homogeneous_deformation_on_a_distorted_mixed_mesh():
    """The patch test across the two cell types: x = F X leaves no force on interior nodes and the same stress in
    every cell; the composite body's cells, stresses and Gauss volumes come in mesh order."""
    mesh, inside = _mixed_box()
    body = _composite(mesh, [NeoHooke(E=200.0, nu=0.3)] * 2)
    assert body.cell_type == "mixed" and body.n_elements == mesh.n_cells == 8 + 16 and body.cells is None
    F = np.array([[1.1, 0.05, 0.0], [0.02, 0.95, 0.03], [0.0, -0.04, 1.05]])
    u = mesh.points @ F.T - mesh.points
    r = _residual(body, u).reshape(-1, 3)
    assert inside.size > 0 and np.abs(r[inside]).max() <= 1e-10 * np.abs(r).max()
    cauchy = body.stress(u).cauchy
    np.testing.assert_allclose(cauchy, cauchy[[0]].repeat(len(cauchy), 0), atol=1e-9 * np.abs(cauchy).max())
    np.testing.assert_allclose(body.stress(u).cauchy_nodal, cauchy[[0]].repeat(mesh.n_nodes, 0),
                               atol=1e-9 * np.abs(cauchy).max())
    assert body.gauss_volumes().sum() == pytest.approx(2.0, rel=1e-12)  # the box's volume, padded rows zero


def test_mixed_tangent_matches_differences():
    """The tangent of a body of bricks (Neo-Hooke) and wedges (J2, yielding) against central differences of its
    residual, from a plastic committed state (history arrays of 8 and 6 Gauss points side by side)."""
    mesh, _ = _mixed_box(split_x=1.5, distort=0.05)
    body = _composite(mesh, [NeoHooke(E=200.0, nu=0.3), J2Plasticity(E=200.0, nu=0.3, yield_stress=1.0,
                                                                     hardening={"law": "linear", "modulus": 20.0})])
    rng = np.random.default_rng(3)
    u = 0.03 * mesh.points[:, [0]] * np.array([1.0, -0.3, -0.3]) + 0.002 * rng.standard_normal(mesh.points.shape)
    state = body.new_state()
    assert state["hist"].shape[:2] == (mesh.n_cells, 8)  # the bricks' 8 points; the wedges use 6 of them
    body.assemble(u, np.zeros(0), np.zeros(u.size), None, want_K=False, state=state)
    committed = {k: v.copy() for k, v in state.items()}
    assert committed["hist"][8:, :6, 6].max() > 0  # the wedges yielded (equivalent plastic strain)
    v = u * 1.05 + 0.001 * rng.standard_normal(u.shape)
    P = Pattern(mesh.n_nodes, [b.cells for b in mesh.blocks])
    data = P.zeros()
    trial = body.kernel_state(committed, committed)
    body.assemble(v, data, np.zeros(v.size), P, state=trial)
    K = P.csr(data).toarray()
    h = 1e-7
    for j in rng.choice(v.size, 24, replace=False):
        vp, vm = v.ravel().copy(), v.ravel().copy()
        vp[j] += h
        vm[j] -= h
        col = (_residual(body, vp, body.kernel_state(committed, committed))
               - _residual(body, vm, body.kernel_state(committed, committed))) / (2 * h)
        assert np.abs(K[:, j] - col).max() <= 1e-6 * np.abs(K).max()
    assert np.array_equal(committed["hist"], state["hist"])  # evaluating changed nothing committed


TENSION = """
[problem]
name = "mixed"
[[bodies]]
name = "bar"
mesh = { file = "FILE" }
MATERIAL
[bodies.sets]
y0 = { box = [[-1.0, -1e-9, -1.0], [3.0, 1e-9, 3.0]] }
[[dirichlet]]
set = "bar.xmin"
components = "x"
[[dirichlet]]
set = "bar.y0"
components = "y"
[[dirichlet]]
set = "bar.zmin"
components = "z"
[[dirichlet]]
name = "pull"
set = "bar.xmax"
components = "x"
value = 0.1
[steps]
count = 2
"""


def _tension(tmp_path: Path, material: str, name: str = "t") -> Path:
    path = tmp_path / f"{name}.toml"
    path.write_text(TENSION.replace("FILE", str(MIXED)).replace("MATERIAL", material))
    return path


def test_uniaxial_tension_of_the_gmsh_mixed_block(tmp_path):
    """Uniaxial stress of the mixed block, stretched by 5 %: St. Venant-Kirchhoff's reaction lambda E (lambda^2 - 1)
    / 2 on the unit cross-section; J2 with linear hardening in two materials by element set (the bricks and the
    wedges of one law, each with its own material): Kirchhoff stress tau = (sigma_y0 + H ln lambda) / (1 + H / E)
    and the reaction tau / lambda. The VTU holds a hexahedron and a wedge block with their cell data."""
    from covcontact.io.loader import load_problem

    res = load_problem(_tension(tmp_path, 'material = { model = "svk", E = 200.0, nu = 0.3 }')).run(
        out=tmp_path / "svk", quiet=True)
    assert res.exit_code == 0
    lam = 1.05
    assert res.summary["steps"][-1]["reactions"]["bar.xmax"][0] == pytest.approx(200.0 * lam * (lam ** 2 - 1) / 2,
                                                                                   rel=1e-8)
    out = meshio.read(tmp_path / "svk" / "step_0002.vtu")
    assert [b.type for b in out.cells] == ["hexahedron", "wedge"]
    assert [len(b) for b in out.cell_data["von_mises"]] == [18, 52]
    vm = np.concatenate(out.cell_data["von_mises"])
    np.testing.assert_allclose(vm, vm[0], rtol=1e-8)
    assert np.concatenate(out.cell_data["body_id"]).max() == 0
    j2 = ('material = { model = "j2", E = 200.0, nu = 0.3, yield_stress = 1.0, hardening = { law = "linear", '
          'modulus = 20.0 } }\nmaterials = { wedges = { model = "j2", E = 200.0, nu = 0.3, yield_stress = 1.0, '
          'hardening = { law = "linear", modulus = 20.0 } } }\n[bodies.cells]\nwedges = { box = [[1.0, -1.0, '
          '-1.0], [3.0, 2.0, 2.0]] }')
    res = load_problem(_tension(tmp_path, j2, "j2")).run(out=tmp_path / "j2", quiet=True)
    assert res.exit_code == 0
    E, H, sy = 200.0, 20.0, 1.0
    tau = (sy + H * np.log(lam)) / (1 + H / E)
    assert res.summary["steps"][-1]["reactions"]["bar.xmax"][0] == pytest.approx(tau / lam, rel=1e-8)
    out = meshio.read(tmp_path / "j2" / "step_0002.vtu")
    eq = np.concatenate(out.cell_data["equivalent_plastic_strain"])
    np.testing.assert_allclose(eq, np.log(lam) - tau / E, rtol=1e-8)  # alpha = ln lambda - tau / E everywhere


def test_mass_of_a_mixed_body(tmp_path):
    """The mass matrix of the mixed block holds rho V in every direction (consistent and lumped)."""
    from covcontact.assembly.system import System
    from covcontact.io.loader import load_problem

    problem = load_problem(_tension(tmp_path, 'material = { model = "svk", E = 200.0, nu = 0.3, density = 3.0 }'))
    system = System(problem.bodies)
    for lumped in (False, True):
        M = system.mass(lumped=lumped)
        ones = np.zeros(system.n_dofs)
        ones[0::3] = 1.0
        assert ones @ (M @ ones) == pytest.approx(3.0 * 2.0, rel=1e-12)


CONTACT = """
[problem]
name = "mixed-contact"
[[bodies]]
name = "block"
material = { model = "neo-hooke", E = 100.0, nu = 0.3 }
mesh = { file = "FILE" }
[[rigid]]
name = "plate"
shape = "plane"
point = [0.0, 0.0, 1.0]
normal = [0.0, 0.0, -1.0]
motion = { translation = [0.0, 0.0, -0.03] }
[[contact]]
slave = "block.zmax"
master = "plate"
penalty = 1.0e5
[[dirichlet]]
set = "block.zmin"
components = "xyz"
[steps]
count = 2
"""


def mixed_contact(tmp_path: Path) -> Path:
    """The Gmsh mixed block pressed by a rigid plate on its top (slave nodes of bricks and wedges)."""
    path = tmp_path / "mixed_contact.toml"
    path.write_text(CONTACT.replace("FILE", str(MIXED)))
    return path


def test_contact_on_a_mixed_body(tmp_path):
    """The plate's contact force balances the support's reaction; every top node is in contact."""
    from covcontact.io.loader import load_problem

    res = load_problem(mixed_contact(tmp_path)).run(out=tmp_path / "c", quiet=True)
    assert res.exit_code == 0
    last = res.summary["steps"][-1]
    top = read_mesh(MIXED).node_sets["zmax"].size
    assert last["active_contacts"] == top
    fz = last["contact_force"][2]
    assert fz < 0 and last["reactions"]["block.zmin"][2] == pytest.approx(-fz, rel=1e-6)  # (Newton tolerance)


def test_mixed_meshes_that_cannot_be_are_one_line(tmp_path):
    """A brick cut into wedges under an uncut brick (triangles on a quadrilateral) and a file of hexahedra with
    quadratic tetrahedra are input errors naming the problem."""
    from covcontact.io.loader import load_problem
    from covcontact.io.validate import InputError

    m = block(1.0, 1.0, 2.0, 1, 1, 2, "hex8")
    bad = convert(m, "wedge6", [0])  # the lower brick only: its top triangles lie on the upper brick's face
    assert nonconforming_cells(bad).tolist() == [[1, 0], [2, 0]]
    meshio.write(tmp_path / "bad.vtu", meshio.Mesh(bad.points, [(("hexahedron", "wedge")[k], b.cells)
                                                                for k, b in enumerate(bad.blocks)]))
    path = tmp_path / "p.toml"
    path.write_text('[problem]\nname = "f"\n[[bodies]]\nname = "b"\nmaterial = { model = "svk", E = 1.0, nu = 0.3 }\n'
                    'mesh = { file = "bad.vtu" }\n[steps]\ncount = 1\n')
    with pytest.raises(InputError) as err:
        load_problem(path)
    msg = str(err.value)
    assert "bodies[0].mesh" in msg and "not conforming: 2 triangular faces" in msg and "\n" not in msg
    t = convert(block(1.0, 1.0, 1.0, 1, 1, 1, "hex8"), "tet10")
    h = block(1.0, 1.0, 1.0, 1, 1, 1, "hex8")
    meshio.write(tmp_path / "two.vtu", meshio.Mesh(np.vstack([h.points, t.points + [2.0, 0.0, 0.0]]),
                                                   [("hexahedron", h.cells), ("tetra10", t.cells + len(h.points))]))
    with pytest.raises(MeshError, match="holds hex8 and tet10 cells, which one mesh does not mix .only hex8, wedge6, "
                                        "tet4 cells mix.: take the cells of one type"):
        read_mesh(tmp_path / "two.vtu")
    path.write_text(path.read_text().replace("bad.vtu", "two.vtu").replace('name = "b"\n', 'name = "b"\nelement = '
                                                                           '"tet10"\n'))
    assert load_problem(path).bodies[0].mesh.n_cells == 6  # the body's element takes the cells of its type
    with pytest.raises(ValueError, match="mixes only hex8, wedge6, tet4"):
        Mesh.of_blocks(h.points, [("hex8", h.cells), ("hex27", np.zeros((0, 27), dtype=np.int64)),
                                  ("tet10", t.cells[:1])])
