"""Segment-to-surface contact and tied pairs: tangents against finite differences, the tangent parts, the
expansion of a slave point onto its facet's nodes, and bad input (docs/theory.md, sections 12 and 14)."""

from __future__ import annotations

import numpy as np
import pytest
from two_blocks import two_blocks

from covcontact.contact.element import CASES
from covcontact.contact.points import VirtualPoints, gauss_points
from covcontact.io.loader import load_problem
from covcontact.io.validate import InputError
from covcontact.solvers.model import Model
from covcontact.tangent_check import check_tangent


def _problem(tmp_path, extra: str = "", cell: str = "hex8"):
    path = tmp_path / "p.toml"
    path.write_text(two_blocks(cell, cell, 'type = "sts"\n' + extra))
    return load_problem(path)


@pytest.mark.parametrize("extra, cell", [
    ("", "hex8"),
    ("friction = 0.3", "hex8"),
    ("two_pass = true\norder = 3", "hex8"),
    ("smoothing = 0.004\nfriction = 0.2", "hex8"),
    ('method = "augmented"\ngap_tolerance = 1e-5', "hex8"),
    ("friction = 0.2", "hex27"),
    ('gap = "nodal"', "hex8"),
    ('gap = "nodal"\nsmoothing = 0.004', "hex8"),
    ('gap = "nodal"', "hex27"),
], ids=["frictionless", "coulomb", "two-pass-order3", "smoothed-coulomb", "augmented", "quad9-coulomb", "nodal",
        "nodal-smoothed", "nodal-quad9"])
def test_exact_tangent_against_differences(tmp_path, extra, cell):
    """A block pressed and pulled across another with segment-to-surface contact: the exact tangent matches
    central differences of the residual to 1e-6 (relative, every free column) at steps 1 and 3 (sticking and
    sliding points with friction)."""
    prob = _problem(tmp_path, extra, cell)
    for step in (1, 3):
        rep = check_tangent(prob, step=step, columns=None if cell == "hex8" else 80)
        assert rep["converged"] and rep["judged"] > 0, rep.get("reason")
        assert rep["relative_error"] <= 1e-6, (step, rep["relative_error"])


@pytest.mark.parametrize("extra", ["friction = 0.2", 'gap = "nodal"'], ids=["coulomb", "nodal"])
def test_analytic_master(tmp_path, extra):
    """Segment-to-surface against a rigid sphere, with friction or on nodal gaps: exact tangent to 1e-6."""
    text = """
[problem]
name = "sts-sphere"
[[bodies]]
name = "block"
material = { model = "neo-hooke", E = 100.0, nu = 0.3 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 0.25, nx = 4, ny = 4, nz = 1, origin = [-0.5, -0.5, 0.0] }
[[rigid]]
name = "ball"
shape = "sphere"
center = [0.0, 0.0, -0.5]
radius = 0.5
[[contact]]
slave = "block.zmin"
master = "ball"
penalty = 1.0e4
type = "sts"
tangent = "exact"
EXTRA
[[dirichlet]]
set = "block.zmax"
components = "xyz"
value = [0.02, 0.0, -0.03]
[steps]
count = 2
"""
    path = tmp_path / "s.toml"
    path.write_text(text.replace("EXTRA", extra))
    prob = load_problem(path)
    rep = check_tangent(prob, step=2, columns=None)
    assert rep["converged"] and rep["relative_error"] <= 1e-6, rep["relative_error"]


@pytest.mark.parametrize("extra", ["", 'gap = "nodal"'], ids=["points", "nodal"])
def test_tangent_parts_keep_their_meaning(tmp_path, extra):
    """Per point the tangent splits as for a slave node: case a = main + rotational + curvature parts, case d =
    the main part, and the parts differ from zero; expanded onto the facet nodes they keep that sum. On nodal gaps
    the main part is the nodes' blocks, the others the points' at their interpolated forces."""
    prob = _problem(tmp_path, extra)
    res = prob.run(out=tmp_path / "out")
    assert res.exit_code == 0
    model = res.model
    x = model.positions(res.u)
    state = res.state.contact
    ev, _ = model.contact.evaluate(x, 1.0, state, case=CASES["a"], want_parts=True)
    main, rot, curv, _ = [b.csr() for b in ev.parts]
    Ka = ev.blocks.csr()
    assert abs(Ka - (main + rot + curv)).max() <= 1e-9 * abs(Ka).max()
    assert abs(rot).max() > 0 and abs(main).max() > 0
    ev_d, _ = model.contact.evaluate(x, 1.0, state, case=CASES["d"])
    assert abs(ev_d.blocks.csr() - main).max() <= 1e-9 * abs(main).max()


def test_expansion_distributes_a_point_to_its_nodes():
    """R_a = N_a R_g and K_ab = N_a N_b K_gg (and the mixed blocks) for a point of a quad4 facet."""
    X = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [5, 5, 5]], dtype=float)
    conn, N, w, _ = gauss_points(X[:4], np.array([[0, 1, 2, 3]]), 2)
    assert w.sum() == pytest.approx(1.0)
    pts = VirtualPoints(5)
    ids = pts.add(conn, N)
    rng = np.random.default_rng(1)
    R = rng.normal(size=(4, 6))
    K = rng.normal(size=(4, 6, 6))
    c = np.stack([np.full(4, 4), ids], axis=1)  # master node 4, then the point
    c2, R2, K2 = pts.expand(c, R, K)
    assert c2.shape == (4, 5) and np.all(c2[:, 0] == 4) and np.all(c2[:, 1:] == [0, 1, 2, 3])
    T = np.zeros((4, 6, 15))
    T[:, :3, :3] = np.eye(3)
    for a in range(4):
        T[:, 3:, 3 + 3 * a: 6 + 3 * a] = N[:, a, None, None] * np.eye(3)
    np.testing.assert_allclose(R2, np.einsum("mi,mij->mj", R, T), atol=1e-14)
    np.testing.assert_allclose(K2, np.einsum("mia,mij,mjb->mab", T, K, T), atol=1e-14)
    np.testing.assert_allclose(pts.positions(np.vstack([X, np.zeros((4, 3))])),
                               np.einsum("ga,gai->gi", N, X[conn]))


def test_tied_tangent(tmp_path):
    """law = "tied" with segment-to-surface points: the block pulled off and sheared stays bonded; the tangent
    matches differences to 1e-6."""
    prob = _problem(tmp_path, 'law = "tied"')
    prob.dirichlet[1].values = (0.03, 0.01, 0.02)  # pulled upwards: the tie holds in tension
    rep = check_tangent(prob, step=2, columns=None)
    assert rep["converged"] and rep["relative_error"] <= 1e-6, rep["relative_error"]
    res = prob.run(out=tmp_path / "out")
    assert res.exit_code == 0
    f = res.summary["steps"][-1]["pairs"]["contact1"]["contact_force"]
    assert f[2] < 0  # the punch is held down by the tie


def test_model_maps_points_to_nodes(tmp_path):
    """The contact zone of a segment-to-surface pair holds the slave facets' nodes, not the point ids."""
    prob = _problem(tmp_path)
    res = prob.run(out=tmp_path / "out")
    model = Model(prob)
    dofs = model.contact.coupled_dofs(res.state.contact)
    assert dofs.max() < 3 * model.system.n_nodes
    punch = model.system.offset("punch") + np.unique(prob.body("punch").mesh.face_sets["zmin"])
    assert set(punch.tolist()) <= set((dofs // 3).tolist())


@pytest.mark.parametrize("extra, message", [
    ('order = 9', "contact[0].order: 9 Gauss points per direction"),
    ('order = 0', "contact[0].order: 0 Gauss points per direction"),
    ('weighting = "nodal"', "contact[0].weighting: type = \"sts\" integrates"),
    ('law = "tied"\nfriction = 0.2', "contact[0].friction: not used by law = \"tied\""),
    ('tie_tolerance = 0.1', "contact[0].tie_tolerance: tie_tolerance is for law = \"tied\""),
    ('gap = "nodal"\nfriction = 0.2', "contact[0].gap: gap = \"nodal\": not with friction"),
    ('gap = "nodal"\nmethod = "augmented"', "contact[0].gap: gap = \"nodal\": not with method = \"augmented\""),
    ('gap = "nodal"\nlaw = "arctan"\ntension = 10.0', "contact[0].gap: gap = \"nodal\": not with law = \"arctan\""),
    ('gap = "nodes"', "contact[0].gap: 'nodes' is not one of points, nodal"),
])
def test_bad_input(tmp_path, extra, message):
    with pytest.raises(InputError) as err:
        _problem(tmp_path, extra)
    assert message in str(err.value) and "\n" not in str(err.value), str(err.value)


@pytest.mark.parametrize("old, new, message", [
    ('slave = "punch.zmin"', 'slave = "punch.all"', "contact[0].slave: type = \"sts\" integrates over the slave's "
                                                    "faces, but 'punch.all' is a node set only"),
    ('type = "sts"', 'type = "nts"\norder = 2', "contact[0].order: the Gauss rule of the slave facets is for"),
    ('type = "sts"', 'type = "mortar"', "contact[0].type: 'mortar' is not one of nts, sts"),
    ('type = "sts"', 'type = "nts"\ngap = "nodal"', "contact[0].gap: gap = \"nodal\": it is for type = \"sts\""),
    ('slave = "punch.zmin"\nmaster = "base.zmax"', 'self = "punch.zmin"\nslave = "punch.zmin"',
     "contact[0].slave: not used with self"),
    ('slave = "punch.zmin"\nmaster = "base.zmax"', 'self = "punch.all"', "contact[0].self: 'punch.all' is a node set"),
    ('slave = "punch.zmin"\nmaster = "base.zmax"', 'self = "punch.zmin"\nlaw = "tied"',
     "contact[0].law: a surface cannot be tied to itself"),
    ('slave = "punch.zmin"\nmaster = "base.zmax"', 'slave = "punch.zmin"\nmaster = "punch.zmin"',
     "contact[0].master: slave and master are the same surface 'punch.zmin': a surface in contact with itself is "
     "self-contact: write self = \"punch.zmin\""),
])
def test_bad_pairs(tmp_path, old, new, message):
    text = two_blocks(extra='type = "sts"')
    assert old in text
    path = tmp_path / "p.toml"
    path.write_text(text.replace(old, new))
    with pytest.raises(InputError) as err:
        load_problem(path)
    assert message in str(err.value) and "\n" not in str(err.value), str(err.value)


@pytest.mark.parametrize("cell", ["hex8", "hex27"])
def test_nodal_gaps_on_a_plane_are_node_to_surface(tmp_path, cell):
    """Against a flat master the gap is affine in the position, so the dual weights' average of the points' gaps is the
    node's own gap and the node's area its tributary area (docs/theory.md section 16): gap = "nodal" gives node-to-surface
    with area weighting, iteration by iteration, to round-off."""
    text = """
[problem]
name = "nodal-plane"
[[bodies]]
name = "block"
element = "CELL"
material = { model = "neo-hooke", E = 100.0, nu = 0.3 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 0.25, nx = 3, ny = 2, nz = 1, origin = [-0.5, -0.5, 0.0] }
[[rigid]]
name = "floor"
shape = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.3, 0.0, 1.0]
[[contact]]
slave = "block.zmin"
master = "floor"
penalty = 1.0e4
PAIR
[[dirichlet]]
set = "block.zmax"
components = "xyz"
value = [0.05, 0.02, -0.03]
[steps]
count = 2
"""
    runs = {}
    for name, pair in (("nts", 'type = "nts"\nweighting = "area"'), ("nodal", 'type = "sts"\ngap = "nodal"')):
        path = tmp_path / f"{name}.toml"
        path.write_text(text.replace("CELL", cell).replace("PAIR", pair))
        runs[name] = load_problem(path).run(out=tmp_path / name)
        assert runs[name].exit_code == 0
    a, b = runs["nts"], runs["nodal"]
    assert [s["iterations"] for s in a.summary["steps"]] == [s["iterations"] for s in b.summary["steps"]]
    np.testing.assert_allclose(b.u, a.u, rtol=0, atol=1e-10 * np.abs(a.u).max())
    fa = a.summary["steps"][-1]["pairs"]["contact1"]["contact_force"]
    fb = b.summary["steps"][-1]["pairs"]["contact1"]["contact_force"]
    np.testing.assert_allclose(fb, fa, rtol=1e-9, atol=1e-12)
    assert abs(fa[2]) > 0.0


def test_nodal_gaps_refused_where_they_cannot_run(tmp_path):
    """gap = "nodal" against an analytic tool with a reference node, and in a run of several MPI ranks: one line each
    (InputError, exit 2), before anything starts."""
    from covcontact.solvers.choice import check_distributable

    text = two_blocks(extra='type = "sts"\ngap = "nodal"')
    path = tmp_path / "p.toml"
    path.write_text(text)
    with pytest.raises(InputError) as err:
        check_distributable(load_problem(path), "petsc", 2)
    assert "gap = \"nodal\" runs in one process" in str(err.value) and "\n" not in str(err.value)
    check_distributable(load_problem(path), "pardiso", 1)  # one process: accepted
    tool = text.replace('slave = "punch.zmin"\nmaster = "base.zmax"', 'slave = "punch.zmin"\nmaster = "ram"') + """
[[rigid]]
name = "ram"
shape = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
free = ["z"]
force = [0.0, 0.0, 1.0]
"""
    path.write_text(tool)
    with pytest.raises(InputError) as err:
        load_problem(path)
    assert "contact[0].gap: gap = \"nodal\": not against 'ram'" in str(err.value) and "\n" not in str(err.value)
