"""Contact problems end to end: every kind of master surface, convergence rates and the assembled tangent."""

from pathlib import Path

import numpy as np
import pytest

from covcontact.io.loader import load_problem
from covcontact.tangent_check import check_tangent

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "contact"


def quadratic_constants(summary: dict) -> list[float]:
    """C = r_(k+1) / r_k^2 over the asymptotic iterations (r_k < 1e-2, r_(k+1) above the round-off floor).

    Quadratic convergence keeps C bounded; linear convergence makes it blow up as r_k falls.
    """
    out = []
    for s in summary["steps"]:
        r = s["residual_norms"]
        out += [r[k + 1] / r[k] ** 2 for k in range(len(r) - 1) if r[k] < 1e-2 and r[k + 1] > 1e-11]
    return out


@pytest.fixture(scope="module")
def block_on_plane(tmp_path_factory):
    prob = load_problem(EXAMPLES / "block_on_plane.toml")
    return prob.run(out=tmp_path_factory.mktemp("bop"))


def test_block_on_plane_uniform_pressure(block_on_plane):
    """Frictionless compression of a hex27 block on a rigid plane: the contact pressure is uniform."""
    res = block_on_plane
    assert res.exit_code == 0
    last = res.summary["steps"][-1]
    pd = res.model.contact.point_data(res.model.system.n_nodes, res.state.contact)
    p = pd["contact_pressure"][pd["contact_status"] == 1]
    assert len(p) == 49  # every node of the 7 x 7 bottom face of 3 x 3 hex27 is in contact
    assert np.std(p) / np.mean(p) < 1e-9
    # force balance: contact force = reaction of the pressed top face = pressure x unit area, to the
    # residual tolerance of Newton (rtol = 1e-8 of the step's out-of-balance)
    reaction = last["reactions"]["block.zmax"][2]
    assert last["contact_force"][2] == pytest.approx(-reaction, rel=1e-8)
    assert np.mean(p) == pytest.approx(last["contact_force"][2], rel=1e-9)
    # St. Venant-Kirchhoff in uniaxial stress at 1 % shortening: S = E E_33 with E_33 = (0.99^2 - 1)/2,
    # Cauchy = F S F^T / J; the block's cross-section grows by the lateral stretch, so check the range only.
    assert 9.5 < np.mean(p) < 10.0
    # penetration = pressure / penalty (area weighting)
    assert last["min_gap"] == pytest.approx(-np.mean(p) / 1e7, rel=1e-6)


@pytest.mark.parametrize("name", ["block_on_sphere", "block_on_cylinder", "two_blocks", "ball_into_plate",
                                  "block_on_rigid_mesh"])
def test_quadratic_convergence(tmp_path, name):
    """The exact tangent converges quadratically in every step; case a nearly so (it drops O(g^2) terms);
    case d (main part only) converges linearly. Measured (C = r_(k+1) / r_k^2): exact max 1.2 .. 64,
    case a median 1 .. 920, case d median 2.7e4 .. 1.9e5."""
    prob = load_problem(EXAMPLES / f"{name}.toml")
    runs = {case: prob.run(out=tmp_path / case, tangent=case).summary for case in ("exact", "a", "d")}
    for case, summary in runs.items():
        assert summary["converged"], case
        for s in summary["steps"]:
            assert s["converged"] and s["cutbacks"] == 0 and s["active_contacts"] > 0
    c_exact = quadratic_constants(runs["exact"])
    c_a = quadratic_constants(runs["a"])
    c_d = quadratic_constants(runs["d"])
    assert c_exact and max(c_exact) < 1e3, c_exact
    assert np.median(c_a) < 2e3, c_a
    assert np.median(c_d) > 10 * np.median(c_a), (c_a, c_d)
    assert runs["d"]["total_iterations"] > runs["exact"]["total_iterations"]


@pytest.mark.parametrize("name", ["block_on_sphere", "two_blocks", "ball_into_plate", "block_on_rigid_mesh"])
def test_assembled_tangent_matches_finite_differences(name):
    prob = load_problem(EXAMPLES / f"{name}.toml")
    exact = check_tangent(prob, step=2, tangent="exact", columns=40)
    assert exact["converged"]
    assert exact["relative_error"] < 1e-6, exact
    main = check_tangent(prob, step=2, tangent="d", columns=40)
    assert main["relative_error"] > 10 * exact["relative_error"]


def test_rotational_part_matters_with_rigid_slaves(tmp_path):
    """The paper's set-up (rigid slave nodes, deformable master): dropping the rotational part costs
    iterations; the curvature part stays small with linear facets."""
    prob = load_problem(EXAMPLES / "ball_into_plate.toml")
    a = prob.run(out=tmp_path / "a", tangent="a").summary
    b = prob.run(out=tmp_path / "b", tangent="b").summary
    d = prob.run(out=tmp_path / "d", tangent="d").summary
    assert a["converged"] and b["converged"] and d["converged"]
    assert d["total_iterations"] > a["total_iterations"]
    assert abs(b["total_iterations"] - a["total_iterations"]) <= 2
    rot = [s["contribution_percent"]["rotational"] for s in a["steps"]]
    curv = [s["contribution_percent"]["curvature"] for s in a["steps"]]
    assert max(rot) > 1.0 and max(curv) < 0.1 * max(rot)


def test_analytic_master_has_no_rotational_part(tmp_path):
    res = load_problem(EXAMPLES / "block_on_sphere.toml").run(out=tmp_path)
    for s in res.summary["steps"]:
        assert s["contribution_percent"]["rotational"] == 0.0
    assert max(s["contribution_percent"]["curvature"] for s in res.summary["steps"]) > 0.0


def test_deformable_pair_force_balance(tmp_path):
    res = load_problem(EXAMPLES / "two_blocks.toml").run(out=tmp_path)
    last = res.summary["steps"][-1]
    top = last["reactions"]["punch.zmax"][2]
    base = last["reactions"]["base.zmin"][2]
    assert top == pytest.approx(-base, rel=1e-8)
    # the force on the slave nodes balances the punch's reaction
    assert last["contact_force"][2] == pytest.approx(-top, rel=1e-8)


def test_two_pass(tmp_path):
    """Two-pass: each surface is slave and master in turn; both passes carry load and balance."""
    prob = load_problem(EXAMPLES / "two_blocks.toml")
    prob.contacts[0].two_pass = True
    res = prob.run(out=tmp_path, tangent="exact")
    assert res.exit_code == 0
    last = res.summary["steps"][-1]
    pairs = last["pairs"]
    assert set(pairs) == {"contact1", "contact1/reverse"}
    assert all(p["active_contacts"] > 0 for p in pairs.values())
    # the forces of the two passes share the load: their sum balances the punch reaction
    top = last["reactions"]["punch.zmax"][2]
    f_slave = pairs["contact1"]["contact_force"][2]
    f_reverse = pairs["contact1/reverse"]["contact_force"][2]
    assert f_slave - f_reverse == pytest.approx(-top, rel=1e-8)
    for s in res.summary["steps"]:
        assert s["iterations"] <= 6
