"""Self-contact: merged surfaces against the equivalent two-pass pair, tangents against finite differences,
the excluded neighbourhood and the facing test (docs/theory.md, section 18)."""

from __future__ import annotations

import numpy as np
import pytest
from two_blocks import two_blocks

from covcontact.contact.selfcontact import drop_excluded, excluded_facets
from covcontact.io.loader import load_problem
from covcontact.mesh.generators import block
from covcontact.tangent_check import check_tangent

MERGED = 'self = ["punch.zmin", "base.zmax"]'
PAIR = 'slave = "punch.zmin"\nmaster = "base.zmax"\ntwo_pass = true'


def _problem(tmp_path, pair: str, extra: str = "", name: str = "p"):
    path = tmp_path / f"{name}.toml"
    path.write_text(two_blocks(extra='weighting = "area"\n' + extra, pair=pair))
    return load_problem(path)


@pytest.mark.parametrize("extra", ["", "friction = 0.3"], ids=["frictionless", "coulomb"])
def test_merged_surfaces_equal_the_two_pass_pair(tmp_path, extra):
    """Two bodies' face sets merged into one self-contact surface (general contact) act as the two-pass pair
    between them: each node of either surface is a slave against the other, and the facets of its own face (which
    face the same way) are never candidates. Same iterations, displacements to round-off."""
    a = _problem(tmp_path, MERGED, extra, "self").run(out=tmp_path / "self")
    b = _problem(tmp_path, PAIR, extra, "pair").run(out=tmp_path / "pair")
    assert a.exit_code == b.exit_code == 0
    assert [s["iterations"] for s in a.summary["steps"]] == [s["iterations"] for s in b.summary["steps"]]
    np.testing.assert_allclose(a.u, b.u, rtol=0, atol=1e-10 * np.abs(b.u).max())
    last = a.summary["steps"][-1]["pairs"]["contact1"]
    ref = b.summary["steps"][-1]["pairs"]
    assert last["active_contacts"] == ref["contact1"]["active_contacts"] + ref["contact1/reverse"]["active_contacts"]
    assert last["active_contacts"] > 16
    # the pair's force: the sum over all its slaves, of both bodies
    np.testing.assert_allclose(last["contact_force"], np.add(ref["contact1"]["contact_force"],
                                                             ref["contact1/reverse"]["contact_force"]), atol=1e-8)


@pytest.mark.parametrize("extra", ["", "friction = 0.3", 'type = "sts"', 'type = "sts"\nfriction = 0.3',
                                   'type = "sts"\ngap = "nodal"'],
                         ids=["nts", "nts-coulomb", "sts", "sts-coulomb", "sts-nodal"])
def test_self_contact_tangent(tmp_path, extra):
    """The exact tangent of a self-contact matches central differences to 1e-6 at steps 1 and 3."""
    prob = _problem(tmp_path, MERGED, extra)
    for step in (1, 3):
        rep = check_tangent(prob, step=step, columns=None)
        assert rep["converged"] and rep["judged"] > 0, rep.get("reason")
        assert rep["relative_error"] <= 1e-6, (step, rep["relative_error"])


def test_excluded_neighbourhood():
    """A node never sees the facets around it; a point never sees its own facet."""
    mesh = block(lx=3.0, ly=3.0, lz=1.0, nx=3, ny=3, nz=1)
    faces = mesh.face_sets["zmax"]
    centre = faces[4]  # the middle facet of the 3 x 3 top face
    node = int(centre[0])
    ex = excluded_facets(faces, len(mesh.points), slave_nodes=np.array([node]))
    around = np.flatnonzero((faces == node).any(axis=1))
    assert sorted(ex[0][ex[0] >= 0].tolist()) == sorted(around.tolist()) and len(around) == 4
    ex = excluded_facets(faces, len(mesh.points), slave_facets=np.array([4]))
    assert ex[0][ex[0] >= 0].tolist() == [4]
    # candidates: excluded ones and those facing the same way as the slave are dropped
    ptr = np.array([0, 3])
    fac = np.array([0, 4, 8])
    own = np.array([[0.0, 0.0, 1.0]])
    fn = np.zeros((9, 3))
    fn[:, 2] = -1.0
    fn[8, 2] = 1.0  # faces the same way as the slave
    excl = np.array([[4, -1]])
    p2, f2 = drop_excluded(ptr, fac, excl, own, fn, np.zeros(1))
    assert p2.tolist() == [0, 1] and f2.tolist() == [0]


def test_same_surface_pair_hint(tmp_path):
    from covcontact.io.validate import InputError

    with pytest.raises(InputError) as err:
        _problem(tmp_path, 'slave = "punch.zmin"\nmaster = "punch.zmin"')
    assert 'self = "punch.zmin"' in str(err.value)
