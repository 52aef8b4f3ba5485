"""Contact on tri3, tri6 and quad8 facets (tetrahedra, 20-node bricks): the patches of quadrilaterals interpolate the
face exactly and form one connected surface, their Gauss points integrate the face, the row-by-row expansion onto the
face nodes is T^T K T, and the exact tangents match central differences (docs/theory.md, section 19)."""

from __future__ import annotations

import numpy as np
import pytest
from two_blocks import PAIR, two_blocks

from covcontact.contact.facets import _CORNERS, patch_count, patch_weights, quad_patches
from covcontact.contact.points import VirtualPoints, gauss_points
from covcontact.contact.surface import MeshSurface, tributary_area
from covcontact.fem.cells import FACE_BY_NODES, face_shapes
from covcontact.fem.shapes import shape_functions
from covcontact.io.loader import load_problem
from covcontact.mesh.convert import convert
from covcontact.mesh.generators import block
from covcontact.tangent_check import check_tangent

RNG = np.random.default_rng(7)


@pytest.mark.parametrize("nen", [3, 6, 8])
def test_patches_interpolate_the_face(nen):
    """At any point of a patch quadrilateral the patch's position equals the face's at the same face parameters
    (an arbitrary curved face), and its normal points the face's way."""
    ftype = FACE_BY_NODES[nen]
    xyz = RNG.normal(size=(nen, 3))
    T = patch_weights(nen)
    qn = T.shape[1]
    corners = _CORNERS["quad8" if nen == 8 else "tri"]
    xi = RNG.uniform(-1.0, 1.0, size=(25, 2))
    Nq, dNq, _ = shape_functions("quad4" if qn == 4 else "quad9", xi)
    N4 = shape_functions("quad4", xi)[0]
    for s in range(patch_count(nen)):
        zeta = N4 @ corners[s]
        Nf, dNf = face_shapes(ftype, zeta)
        np.testing.assert_allclose(Nq @ (T[s] @ xyz), Nf @ xyz, atol=1e-13)
        tq = np.einsum("pvd,vi->pdi", dNq, T[s] @ xyz)
        tf = np.einsum("pad,ai->pdi", dNf, xyz)
        nq = np.cross(tq[:, 0], tq[:, 1])
        nf = np.cross(tf[:, 0], tf[:, 1])
        assert np.all(np.einsum("pi,pi->p", nq, nf) > 0.0)
    # the weights of every patch node sum to one (a rigid translation moves it alike)
    np.testing.assert_allclose(T.sum(axis=2), 1.0, atol=1e-14)


@pytest.mark.parametrize("cell, nen", [("tet4", 3), ("tet10", 6), ("hex20", 8)])
def test_patches_form_one_surface(cell, nen):
    """The patches of a face set are one connected surface: their boundary edges lie on the face set's boundary
    (two per triangle edge there, one per quad8 edge), no edge is shared by more than two patches, the points on an
    edge are registered once (shared by the faces across it), and the patch nodes sit on the faces."""
    mesh = convert(block(2.0, 1.0, 1.0, 3, 2, 1, "hex27" if cell == "hex20" else "hex8"), cell)
    faces = mesh.face_sets["zmax"]
    assert faces.shape[1] == nen
    pts = VirtualPoints(mesh.n_nodes)
    quads, parent = quad_patches(faces, pts)
    surf = MeshSurface(quads, n_nodes=mesh.n_nodes + pts.count)
    assert surf.n_nonmanifold == 0
    assert len(quads) == patch_count(nen) * len(faces)
    np.testing.assert_array_equal(parent, np.repeat(np.arange(len(faces)), patch_count(nen)))
    edges = np.sort(np.vstack([faces[:, [a, (a + 1) % (3 if nen < 8 else 4)]] for a in range(3 if nen < 8 else 4)]),
                    axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    n_edges, n_boundary = len(counts), int(np.count_nonzero(counts == 1))
    per_edge = 1 if nen == 8 else 2
    assert np.count_nonzero(surf.nbr_facet < 0) == per_edge * n_boundary
    inner = {3: (1, 1), 6: (2, 7), 8: (0, 1)}[nen]  # points per face edge, points inside a face
    assert pts.count == inner[0] * n_edges + inner[1] * len(faces)
    assert pts.master.all()
    # every patch point lies on the plane z = 1 of the face set, inside the footprint
    X = np.vstack([mesh.points, pts.positions(mesh.points)])
    assert np.allclose(X[quads, 2], 1.0)
    assert X[quads, 0].min() >= -1e-12 and X[quads, 0].max() <= 2.0 + 1e-12


@pytest.mark.parametrize("nen", [3, 6, 8])
def test_gauss_points_integrate_the_face(nen):
    """The segment-to-surface points of a face (``order`` per direction on each patch quadrilateral) integrate its
    shape functions: on flat faces sum_g N_a w_g is the tributary area exactly; on a curved face the area converges
    with the order (the area element is not a polynomial there)."""
    mesh = convert(block(1.0, 1.0, 1.0, 2, 2, 1, "hex27" if nen == 8 else "hex8"),
                   {3: "tet4", 6: "tet10", 8: "hex20"}[nen])
    faces = mesh.face_sets["zmax"]
    X = mesh.points.copy()
    conn, N, w, facet = gauss_points(X, faces, 3)
    assert np.all(w > 0.0)
    area = tributary_area(X, faces)
    got = np.bincount(conn.ravel(), (N * w[:, None]).ravel(), minlength=len(X))
    nodes = np.unique(faces)
    np.testing.assert_allclose(got[nodes], area[nodes], atol=1e-13)
    assert w.sum() == pytest.approx(1.0, rel=1e-13)
    np.testing.assert_array_equal(np.bincount(facet), np.full(len(faces), len(w) // len(faces)))
    X[:, 2] += 0.3 * X[:, 0] ** 2 - 0.2 * X[:, 1] ** 2  # a curved top (exactly quadratic for tri6 and quad8)
    areas = [gauss_points(X, faces, order)[2].sum() for order in (2, 4, 8)]
    assert abs(areas[1] - areas[2]) <= max(0.05 * abs(areas[0] - areas[2]), 1e-14)  # flat tri3: exact
    assert abs(areas[1] - areas[2]) < 1e-6
    assert areas[2] > 1.0


def test_row_expansion_is_the_chain_rule():
    """A block of contact elements on patch quadrilaterals (master patch points and a slave point in one row),
    expanded row by row: R' = T^T R and K' = T^T K T with T the weights of every column on the distinct nodes."""
    pts = VirtualPoints(20)
    faces = np.array([[0, 1, 2, 3, 4, 5], [2, 1, 6, 4, 8, 9]])  # edge 1-2 and its mid-node 4 shared
    quads, _ = quad_patches(faces, pts)
    slave = pts.add(np.array([[10, 11, 12, 13]]), np.array([[0.1, 0.2, 0.3, 0.4]]))[0]
    conn = np.hstack([quads[[1, 4]], np.full((2, 1), slave)])
    nc = conn.shape[1]
    R = RNG.normal(size=(2, 3 * nc))
    K = RNG.normal(size=(2, 3 * nc, 3 * nc))
    c2, R2, K2 = pts.expand(conn, R, K)
    for e in range(2):
        nodes = list(dict.fromkeys(c2[e]))
        T = np.zeros((nc, len(nodes)))
        for q, node in enumerate(conn[e]):
            if node < pts.offset:
                T[q, nodes.index(node)] = 1.0
            else:
                j = node - pts.offset
                for a in range(pts.nen[j]):
                    if pts.N[j, a] != 0.0:
                        T[q, nodes.index(pts.conn[j, a])] += pts.N[j, a]
        T3 = np.kron(T, np.eye(3))
        first = [list(c2[e]).index(n) for n in nodes]
        dofs = (3 * np.array(first)[:, None] + np.arange(3)).ravel()
        np.testing.assert_allclose(R2[e][dofs], T3.T @ R[e], atol=1e-12)
        np.testing.assert_allclose(K2[e][np.ix_(dofs, dofs)], T3.T @ K[e] @ T3, atol=1e-12)
        pad = np.setdiff1d(np.arange(3 * c2.shape[1]), dofs)
        assert np.all(R2[e][pad] == 0.0) and np.all(K2[e][pad] == 0.0)
    # each row holds exactly its face's six nodes and the slave facet's four
    assert set(c2[0]) == {0, 1, 2, 3, 4, 5, 10, 11, 12, 13}
    assert set(c2[1]) == {1, 2, 6, 4, 8, 9, 10, 11, 12, 13}


@pytest.mark.parametrize("base, punch, extra", [
    ("tet4", "tet4", 'type = "sts"'),
    ("tet4", "hex8", ""),
    ("tet10", "tet10", 'type = "sts"\nfriction = 0.2'),
    ("hex20", "hex20", 'type = "sts"'),
    ("hex20", "hex8", "friction = 0.3"),
    ("tet4", "hex8", 'type = "sts"\ntwo_pass = true\nmethod = "augmented"\ngap_tolerance = 1e-5'),
    ("hex8", "tet10", 'law = "tied"\ntype = "sts"'),
], ids=["tri3-sts", "tri3-master-nts", "tri6-sts-coulomb", "quad8-sts", "quad8-master-nts-coulomb",
        "tri3-two-pass-augmented", "tri6-slave-tied"])
def test_exact_tangent_against_differences(tmp_path, base, punch, extra):
    """A block pressed and pulled across another, tri3 / tri6 / quad8 facets as master or slave: the exact tangent
    matches central differences of the residual to 1e-6 (relative, 60 columns, half of them in the contact zone) at
    steps 1 and 3 (sticking and sliding with friction)."""
    path = tmp_path / "p.toml"
    path.write_text(two_blocks(base, punch, extra))
    prob = load_problem(path)
    for step in (1, 3):
        rep = check_tangent(prob, step=step, columns=60)
        assert rep["converged"] and rep["zones"]["contact"] > 0, rep.get("reason")
        assert rep["relative_error"] <= 1e-6, (step, rep["relative_error"])


def test_run_reports_triangle_facets(tmp_path):
    """A run with a tet10 segment-to-surface slave writes its facets as triangle6 cells with their contact pressure;
    a constant pressure comes back as that constant (the N^2-weighted nodal mean)."""
    import meshio

    path = tmp_path / "p.toml"
    path.write_text(two_blocks("hex8", "tet10", 'type = "sts"'))
    res = load_problem(path).run(out=tmp_path / "out")
    assert res.exit_code == 0
    vtu = meshio.read(tmp_path / "out" / "step_0003.vtu")
    kinds = [b.type for b in vtu.cells]
    assert "triangle6" in kinds
    k = kinds.index("triangle6")
    assert vtu.cell_data["contact_facet_pressure"][k].max() > 0.0
    pts = res.model.contact.points
    ids = res.model.contact.passes[0].slaves
    w = np.ones(len(ids))
    field, has = pts.smooth(ids, w, np.full(len(ids), 3.5), res.model.contact.num.n_ext)
    np.testing.assert_allclose(field[has], 3.5, rtol=1e-12)
    assert has.sum() == len(np.unique(res.model.contact.passes[0].slave_faces))


@pytest.mark.parametrize("cell, extra", [("tet4", ""), ("tet10", 'type = "sts"\nfriction = 0.3')],
                         ids=["tri3-nts", "tri6-sts-coulomb"])
def test_self_contact_on_triangles(tmp_path, cell, extra):
    """Two tetrahedral bodies' face sets merged into one self-contact surface act as the two-pass pair between them
    (same iterations, displacements to round-off): a facet excluded for a slave takes all its patch quadrilaterals
    with it. The exact tangent of the tri3 self-contact matches central differences."""
    extra = extra + '\nweighting = "area"' if cell == "tet4" else extra
    runs = {}
    for name, pair in (("self", 'self = ["punch.zmin", "base.zmax"]'), ("pair", PAIR + "\ntwo_pass = true")):
        path = tmp_path / f"{name}.toml"
        path.write_text(two_blocks(cell, cell, extra, pair))
        runs[name] = load_problem(path)
    a = runs["self"].run(out=tmp_path / "self")
    b = runs["pair"].run(out=tmp_path / "pair")
    assert a.exit_code == b.exit_code == 0
    assert [s["iterations"] for s in a.summary["steps"]] == [s["iterations"] for s in b.summary["steps"]]
    np.testing.assert_allclose(a.u, b.u, rtol=0, atol=1e-9 * np.abs(b.u).max())
    assert a.summary["steps"][-1]["pairs"]["contact1"]["active_contacts"] > 16
    if cell == "tet4":  # (tri6 facets' tangents with friction: test_exact_tangent_against_differences)
        rep = check_tangent(runs["self"], step=3, columns=60)
        assert rep["converged"] and rep["zones"]["contact"] > 0
        assert rep["relative_error"] <= 1e-6, rep["relative_error"]
