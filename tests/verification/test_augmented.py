"""Augmented Lagrangian (Uzawa) contact and the automatic penalty, on problems."""

from pathlib import Path

import pytest

from covcontact.io.loader import load_problem
from covcontact.tangent_check import check_tangent

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "contact"


def plane(penalty, method="penalty", tol=None):
    prob = load_problem(EXAMPLES / "block_on_plane.toml")
    c = prob.contacts[0]
    c.penalty, c.method, c.gap_tolerance = penalty, method, tol
    return prob


def test_uzawa_reaches_the_gap_tolerance_and_forgets_the_penalty(tmp_path):
    """With the augmented method the answer no longer depends on the penalty: two penalties 100x apart
    give the same contact force, and the penetration ends below the tolerance."""
    forces = {}
    for eps in (1e4, 1e6):
        res = plane(eps, "augmented", 1e-8).run(out=tmp_path / f"{eps:g}")
        assert res.exit_code == 0
        for s in res.summary["steps"]:
            pair = s["pairs"]["contact1"]
            assert pair["max_penetration"] <= 1e-8
            assert s["uzawa_iterations"] >= 1
        forces[eps] = res.summary["steps"][-1]["contact_force"][2]
    assert forces[1e4] == pytest.approx(forces[1e6], rel=1e-5)
    # the pure penalty with the soft value is visibly off (penetration 1e-3 of a 1e-2 compression)
    soft = plane(1e4).run(out=tmp_path / "soft").summary["steps"][-1]["contact_force"][2]
    assert abs(soft - forces[1e6]) > 1e-2 * forces[1e6]


def test_uzawa_on_deformable_pair(tmp_path):
    prob = load_problem(EXAMPLES / "two_blocks.toml")
    c = prob.contacts[0]
    c.method, c.gap_tolerance, c.penalty = "augmented", 1e-7, 1e4
    res = prob.run(out=tmp_path, tangent="exact")
    assert res.exit_code == 0
    last = res.summary["steps"][-1]
    assert last["pairs"]["contact1"]["max_penetration"] <= 1e-7
    assert last["contact_force"][2] == pytest.approx(-last["reactions"]["punch.zmax"][2], rel=1e-8)


def test_tangent_with_multipliers():
    """Step 2 starts from the multipliers of step 1: the assembled tangent still matches FD."""
    prob = load_problem(EXAMPLES / "two_blocks.toml")
    c = prob.contacts[0]
    c.method, c.gap_tolerance, c.penalty = "augmented", 1e-7, 1e4
    rep = check_tangent(prob, step=2, tangent="exact", columns=40)
    assert rep["converged"] and rep["relative_error"] < 1e-6, rep


def test_auto_penalty(tmp_path):
    """penalty = "auto": 10 E / h of the body; here E = 1000, h = 1/3: 3e4 per area."""
    res = plane("auto").run(out=tmp_path)
    assert res.exit_code == 0
    eps = res.model.contact.passes[0].eps / res.model.contact.passes[0].area
    assert eps == pytest.approx(10 * 1000.0 / (1.0 / 3.0), rel=1e-9)
    last = res.summary["steps"][-1]
    p = last["contact_force"][2]  # unit area: force = mean pressure
    assert -last["min_gap"] == pytest.approx(p / 3e4, rel=1e-3)
