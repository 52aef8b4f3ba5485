"""Coulomb friction in problems: sliding at mu N, sticking below it, assembled non-symmetric tangents."""

from pathlib import Path

import numpy as np
import pytest

from covcontact.io.loader import load_problem
from covcontact.tangent_check import check_tangent

ROOT = Path(__file__).resolve().parents[2]
SLIDING = ROOT / "examples" / "friction" / "block_sliding.toml"


def test_full_sliding_gives_mu_times_normal_force(tmp_path):
    res = load_problem(SLIDING).run(out=tmp_path)
    assert res.exit_code == 0 and res.model.symmetric is False
    last = res.summary["steps"][-1]["pairs"]["contact1"]
    assert last["slip"] == last["active_contacts"] == 25
    fx, fy, fz = last["contact_force"]
    # friction opposes the +x motion of the block; every node is on the cone (|t| = mu N), and the small
    # radial (Poisson) part of each node's slip turns a little of its traction away from x
    assert 0.2995 < -fx / fz <= 0.3 * (1 + 1e-9)
    assert abs(fy) < 1e-9 * fz
    # force balance with the dragging support
    react = res.summary["steps"][-1]["reactions"]["block.zmax"]
    assert np.allclose(react, [-fx, -fy, -fz], rtol=1e-8, atol=1e-9 * fz)


def test_small_drag_sticks(tmp_path):
    prob = load_problem(SLIDING)
    prob.dirichlet[0].values = (0.0005, 0.0, -0.01)
    res = prob.run(out=tmp_path)
    last = res.summary["steps"][-1]["pairs"]["contact1"]
    assert res.exit_code == 0
    assert last["stick"] > 0
    fx, _, fz = last["contact_force"]
    assert abs(fx) < 0.3 * fz


@pytest.mark.parametrize("step", [1, 4])
def test_assembled_friction_tangent(step):
    """Stick in step 1 (new contacts) and slip later: the assembled tangent matches finite differences."""
    rep = check_tangent(load_problem(SLIDING), step=step, tangent="exact", columns=40)
    assert rep["converged"] and rep["relative_error"] < 1e-6, rep


def test_friction_between_deformable_bodies(tmp_path):
    prob = load_problem(ROOT / "examples" / "contact" / "two_blocks.toml")
    prob.contacts[0].friction = 0.2
    prob.dirichlet[1].values = (0.05, 0.0, -0.02)  # the punch is pressed and dragged
    res = prob.run(out=tmp_path, tangent="exact")
    assert res.exit_code == 0
    last = res.summary["steps"][-1]
    pair = last["pairs"]["contact1"]
    assert pair["slip"] + pair["stick"] == pair["active_contacts"] > 0
    fx, _, fz = pair["contact_force"]
    assert abs(fx) <= 0.2 * fz * (1 + 1e-9)
    rep = check_tangent(prob, step=2, tangent="exact", columns=40)
    assert rep["relative_error"] < 1e-6, rep


def test_sliding_with_augmented_normal_law(tmp_path):
    """Friction under the augmented Lagrangian normal law: the penetration falls below the tolerance 1e-7
    (the penalty 1e4 alone lets the block sink about 1e-3), and the sliding force is still mu N."""
    prob = load_problem(SLIDING)
    pair = prob.contacts[0]
    pair.penalty, pair.method, pair.gap_tolerance, pair.gap_tolerance_relative = 1.0e4, "augmented", 1e-7, None
    res = prob.run(out=tmp_path)
    assert res.exit_code == 0
    last_step = res.summary["steps"][-1]
    last = last_step["pairs"]["contact1"]
    assert last["slip"] == last["active_contacts"] == 25
    assert -1e-7 <= last["min_gap"] < 0.0
    assert sum(s.get("uzawa_iterations", 0) for s in res.summary["steps"]) > 0
    fx, fy, fz = last["contact_force"]
    assert 0.2995 < -fx / fz <= 0.3 * (1 + 1e-9)
    react = last_step["reactions"]["block.zmax"]
    assert np.allclose(react, [-fx, -fy, -fz], rtol=1e-8, atol=1e-9 * fz)


def test_assembled_friction_tangent_augmented():
    prob = load_problem(SLIDING)
    prob.contacts[0].method, prob.contacts[0].gap_tolerance_relative = "augmented", 1e-3
    rep = check_tangent(prob, step=3, tangent="exact", columns=40)
    assert rep["converged"] and rep["relative_error"] < 1e-6, rep


PRESSED = """
[problem]
name = "pressed"
[[bodies]]
name = "lower"
element = "hex8"
material = { model = "svk", E = 210000.0, nu = 0.3 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 0.5, nx = 4, ny = 4, nz = 2 }
[[bodies]]
name = "upper"
element = "hex8"
material = { model = "svk", E = 210000.0, nu = 0.3 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 0.5, nx = 4, ny = 4, nz = 2, origin = [0.0, 0.0, 0.5] }
[[dirichlet]]
set = "lower.zmin"
[[dirichlet]]
set = "upper.zmax"
components = "xy"
[[pressure]]
set = "upper.zmax"
value = 100.0
[[contact]]
slave = "upper.zmin"
master = "lower.zmax"
penalty = 1.0e7
weighting = "area"
friction = 0.2
tangential_penalty = 47000.0
[steps]
count = 4
"""


def test_conforming_blocks_pressed_with_friction(tmp_path):
    """Two blocks whose meshes match at the interface (every slave node on a master node, on the edges of four facets)
    pressed together with friction and a soft tangential penalty (CalculiX's friction1): each slave keeps its facet of
    the last Newton iterate while Newton moves it across an edge by less than KEEP_BAND (before it, the slaves jumped
    between the facets around their node and the first step failed after 70 iterations and 7 cutbacks); at most 4
    iterations a step, the contact carrying the pressure (the support's reaction 100 A to 1e-6), every slave stuck
    in every step, the first included (a contact new in a step sticks from where the step found it), and the lateral
    force below 1e-5 of the normal one. Nothing slips, so the loading path does not matter: one step gives the four
    steps' displacements to 1e-6 of the largest (before, the first step was frictionless and one step differed)."""
    path = tmp_path / "pressed.toml"
    path.write_text(PRESSED)
    res = load_problem(path).run(out=tmp_path / "out")
    assert res.exit_code == 0
    assert max(s["iterations"] for s in res.summary["steps"]) <= 4
    step = res.summary["steps"][-1]
    assert step["reactions"]["lower.zmin"][2] == pytest.approx(100.0, rel=1e-6)
    assert all(s["pairs"]["contact1"]["stick"] == 25 for s in res.summary["steps"])
    fx, fy, fz = step["pairs"]["contact1"]["contact_force"]
    assert abs(fx) < 1e-5 * abs(fz) and abs(fy) < 1e-5 * abs(fz)
    path.write_text(PRESSED.replace("count = 4", "count = 1"))
    one = load_problem(path).run(out=tmp_path / "one")
    assert one.exit_code == 0 and one.summary["steps"][-1]["pairs"]["contact1"]["stick"] == 25
    np.testing.assert_allclose(one.u, res.u, rtol=0, atol=1e-6 * np.abs(res.u).max())
