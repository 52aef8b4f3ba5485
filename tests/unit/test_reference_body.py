"""Rigid bodies with a reference node (docs/theory.md section 14): the coupling's tangent against central
differences of the residual, the rotation tangent map, equilibrium of force-driven bodies, messages."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from covcontact.contact.reference import tangent_map, tangent_map_derivative
from covcontact.io.loader import problem_from_dict
from covcontact.io.validate import InputError
from covcontact.motion import rotation_matrix
from covcontact.solvers.model import Model


def test_tangent_map_is_the_derivative_of_the_rotation():
    rng = np.random.default_rng(3)
    for theta in (np.zeros(3), 1e-5 * rng.standard_normal(3), rng.standard_normal(3), 2.5 * np.array([0, 0, 1.0])):
        T = tangent_map(theta)
        R = rotation_matrix(theta)
        h = 1e-6
        for k in range(3):
            e = np.zeros(3)
            e[k] = h
            dR = (rotation_matrix(theta + e) - rotation_matrix(theta - e)) / (2 * h)
            W = dR @ R.T  # = [T e_k]_x
            w = np.array([W[2, 1], W[0, 2], W[1, 0]])
            np.testing.assert_allclose(w, T[:, k], atol=1e-8)
        v = rng.standard_normal(3)
        D = tangent_map_derivative(theta, v)
        for k in range(3):
            e = np.zeros(3)
            e[k] = 1e-6
            fd = (tangent_map(theta + e).T @ v - tangent_map(theta - e).T @ v) / 2e-6
            np.testing.assert_allclose(D[:, k], fd, atol=1e-8)


def _block(nx=2):
    return {"name": "block", "material": {"model": "neo-hooke", "E": 1000.0, "nu": 0.3},
            "mesh": {"generator": "block", "lx": 1.0, "ly": 1.0, "lz": 1.0, "nx": nx, "ny": nx, "nz": nx}}


def _supports():
    return [{"set": "block.zmin", "components": "z"}, {"set": "block.xmin", "components": "x"},
            {"set": "block.ymin", "components": "y"}]


def _problem(rigid: dict, contact: dict, name="ref") -> dict:
    return {"problem": {"name": name}, "bodies": [_block()], "rigid": [rigid], "contact": [contact],
            "dirichlet": _supports()}


CASES = {
    "mesh-6dof": (
        {"name": "tool", "shape": "mesh", "mesh": {"generator": "block", "lx": 1.6, "ly": 1.6, "lz": 0.3,
                                                    "nx": 3, "ny": 3, "nz": 1, "origin": [-0.3, -0.3, 0.99]},
         "free": ["x", "y", "z", "rx", "ry", "rz"], "reference": [0.3, 0.2, 1.4]},
        {"slave": "block.zmax", "master": "tool.zmin", "penalty": 1e4, "tangent": "exact"}),
    "mesh-friction": (
        {"name": "tool", "shape": "mesh", "mesh": {"generator": "block", "lx": 1.6, "ly": 1.6, "lz": 0.3,
                                                    "nx": 3, "ny": 3, "nz": 1, "origin": [-0.3, -0.3, 0.99]},
         "free": ["x", "z", "ry"], "force": [0.5, 0.0, -1.0], "moment": [0.0, 0.2, 0.0]},
        {"slave": "block.zmax", "master": "tool.zmin", "penalty": 1e4, "friction": 0.3, "tangent": "exact"}),
    "cylinder-6dof": (
        {"name": "tool", "shape": "cylinder", "center": [0.5, 0.5, 1.79], "axis": [1.0, 0.2, 0.0],
         "radius": 0.8, "free": ["x", "y", "z", "rx", "ry", "rz"], "reference": [0.2, 0.6, 2.0],
         "moment": [0.1, -0.3, 0.2]},
        {"slave": "block.zmax", "master": "tool", "penalty": 1e4, "tangent": "exact"}),
    "sphere-friction": (
        {"name": "tool", "shape": "sphere", "center": [0.5, 0.5, 1.49], "radius": 0.5,
         "free": ["x", "y", "z", "rx", "ry", "rz"], "reference": [0.6, 0.4, 1.5]},
        {"slave": "block.zmax", "master": "tool", "penalty": 1e4, "friction": 0.2, "tangent": "exact"}),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_coupling_tangent_against_central_differences(case):
    """The whole model's tangent (bodies, contact mapped onto the reference node pair, applied moment) at
    a pose with a finite rotation, columns of every reference dof and of slave dofs."""
    rigid, contact = CASES[case]
    problem = problem_from_dict(_problem(rigid, contact), Path(f"{case}.toml"))
    model = Model(problem)
    ref = model.system.reference[0]
    rng = np.random.default_rng(7)
    u = 1e-3 * rng.standard_normal(model.n_dofs) * model.free
    u[3 * ref.A: 3 * ref.A + 3] = [0.01, -0.02, -0.03]      # pressed in by 0.03 (after the 0.01 gap)
    u[3 * ref.B: 3 * ref.B + 3] = [0.05, -0.04, 0.3]       # a finite rotation vector
    state = model.initial_state()
    R, K, trial = model.evaluate(u, 1.0, state)
    assert model.active_count(trial) > 0
    K = K.toarray()
    cols = list(range(3 * ref.A, 3 * ref.A + 6))
    top = np.flatnonzero(np.isclose(model.system.X[:, 2], 1.0) & (np.arange(model.system.n_nodes) < ref.A))
    cols += list((3 * top[:4, None] + np.arange(3)).ravel())
    h = 1e-7
    err = []
    for j in cols:
        e = np.zeros_like(u)
        e[j] = h
        Rp, _, _ = model.evaluate(u + e, 1.0, state, trial, want_K=False)
        Rm, _, _ = model.evaluate(u - e, 1.0, state, trial, want_K=False)
        fd = (Rp - Rm) / (2 * h)
        err.append(np.linalg.norm(fd - K[:, j]) / max(np.linalg.norm(K[:, j]), 1e-300))
    assert max(err) < 1e-6, (case, np.round(np.log10(np.array(err) + 1e-300), 1))


def _run(raw: dict, tmp_path: Path):
    problem = problem_from_dict(raw, tmp_path / "p.toml")
    return problem.run(out=tmp_path / "out")


def test_force_driven_plate_is_in_equilibrium(tmp_path):
    """A rigid plate pushed down by a force: the contact resultant equals the force, the support reaction
    carries it, and the plate sinks by the block's compression (uniaxial stress of Neo-Hooke + penalty)."""
    raw = _problem({"name": "plate", "shape": "plane", "point": [0.0, 0.0, 1.0], "normal": [0.0, 0.0, -1.0],
                    "free": ["z"], "force": [0.0, 0.0, -10.0]},
                   {"slave": "block.zmax", "master": "plate", "penalty": 1e5, "weighting": "area"})
    raw["steps"] = {"count": 2}
    res = _run(raw, tmp_path)
    assert res.exit_code == 0
    last = res.summary["steps"][-1]
    rb = last["rigid_bodies"]["plate"]
    np.testing.assert_allclose(rb["contact_force"], [0.0, 0.0, 10.0], atol=1e-8)
    np.testing.assert_allclose(last["reactions"]["block.zmin"], [0.0, 0.0, 10.0], atol=1e-8)
    # the block's height after compression by 10 on area 1, plus the penetration p / eps
    assert -0.0105 < rb["displacement"][2] < -0.0095
    assert all(s["iterations"] <= 4 for s in res.summary["steps"])  # quadratic convergence


def test_displacement_driven_tool_reports_its_force(tmp_path):
    raw = _problem({"name": "plate", "shape": "plane", "point": [0.0, 0.0, 1.0], "normal": [0.0, 0.0, -1.0],
                    "free": ["x"], "motion": {"translation": [0.0, 0.0, -0.01]}},
                   {"slave": "block.zmax", "master": "plate", "penalty": 1e5, "weighting": "area"})
    res = _run(raw, tmp_path)
    assert res.exit_code == 1  # x is free and a frictionless plane does not restrain it
    assert "free in x but nothing restrains it" in res.summary["steps"][-1]["failure"]
    raw["rigid"][0]["free"] = ["z"]
    raw["rigid"][0]["force"] = [0.0, 0.0, -5.0]
    raw["rigid"][0].pop("motion")
    res = _run(raw, tmp_path)
    assert res.exit_code == 0


@pytest.mark.parametrize("change, message", [
    ({"force": [1.0, 0.0, 0.0], "free": ["z"]}, "x component given, but that component follows the motion"),
    ({"free": ["q"]}, "'q' is not a component"),
    ({"free": ["z", "z"]}, "names a component twice"),
])
def test_bad_reference_input(tmp_path, change, message):
    rigid = {"name": "plate", "shape": "plane", "point": [0.0, 0.0, 1.0], "normal": [0.0, 0.0, -1.0]}
    rigid.update(change)
    raw = _problem(rigid, {"slave": "block.zmax", "master": "plate", "penalty": 1e5})
    with pytest.raises(InputError, match=message):
        problem_from_dict(raw, tmp_path / "p.toml")


def test_free_body_without_partner_is_refused(tmp_path):
    raw = _problem({"name": "plate", "shape": "plane", "point": [0.0, 0.0, 1.0], "normal": [0.0, 0.0, -1.0]},
                   {"slave": "block.zmax", "master": "plate", "penalty": 1e5})
    raw["rigid"].append({"name": "ball", "shape": "sphere", "center": [0.0, 0.0, 3.0], "radius": 0.5,
                         "free": ["z"], "force": [0.0, 0.0, -1.0]})
    with pytest.raises(InputError, match="'ball' has free components but no contact pair"):
        problem_from_dict(raw, tmp_path / "p.toml")


def test_stage_targets_and_removes_the_force_of_a_rigid_body(tmp_path):
    """The force of a free rigid body is a load: a later stage gives it a new target or removes it; the
    contact force follows (equilibrium) and the plate goes back to where the force first put it."""
    raw = _problem({"name": "plate", "shape": "plane", "point": [0.0, 0.0, 1.0], "normal": [0.0, 0.0, -1.0],
                    "free": ["z"], "force": [0.0, 0.0, -10.0]},
                   {"slave": "block.zmax", "master": "plate", "penalty": 1e5, "weighting": "area"})
    raw["stages"] = [{"name": "more", "targets": {"plate": [0.0, 0.0, -20.0]}},
                     {"name": "less", "targets": {"plate": [0.0, 0.0, -10.0]}},
                     {"name": "off", "steps": {"count": 2}, "remove": ["plate"]}]
    res = _run(raw, tmp_path)
    assert res.exit_code == 0
    rows = [(e["stage"], e["rigid_bodies"]["plate"]) for e in res.summary["steps"]]
    expected = {"stage1": 10.0, "more": 20.0, "less": 10.0}
    for stage, rb in rows[:3]:
        assert rb["contact_force"][2] == pytest.approx(expected[stage], rel=1e-9)
        assert rb["applied_force"][2] == pytest.approx(-expected[stage], rel=1e-12)
    assert rows[2][1]["displacement"][2] == pytest.approx(rows[0][1]["displacement"][2], rel=1e-9)  # elastic
    assert rows[-1][1]["contact_force"][2] == pytest.approx(0.0, abs=1e-9)


def test_target_on_a_moved_component_is_refused(tmp_path):
    raw = _problem({"name": "plate", "shape": "plane", "point": [0.0, 0.0, 1.0], "normal": [0.0, 0.0, -1.0],
                    "free": ["z"], "force": [0.0, 0.0, -10.0]},
                   {"slave": "block.zmax", "master": "plate", "penalty": 1e5})
    raw["stages"] = [{"name": "bad", "targets": {"plate": [1.0, 0.0, -10.0]}}]
    with pytest.raises(InputError, match="force x component given, but rigid body 'plate' is moved in 'x'"):
        problem_from_dict(raw, tmp_path / "p.toml")


def test_stage_targets_a_moment(tmp_path):
    """A rigid plate pressed by a force, then tilted by a moment given as a stage target: in each stage the
    contact force and moment balance the applied ones on the free components, and the plate turns."""
    raw = _problem({"name": "plate", "shape": "plane", "point": [0.0, 0.0, 1.0], "normal": [0.0, 0.0, -1.0],
                    "free": ["z", "rx", "ry"], "force": [0.0, 0.0, -10.0], "reference": [0.5, 0.5, 1.0]},
                   {"slave": "block.zmax", "master": "plate", "penalty": 1e5, "weighting": "area"})
    raw["problem"]["stage"] = "press"
    raw["steps"] = {"count": 2}
    raw["stages"] = [{"name": "tilt", "steps": {"count": 2}, "targets": {"plate": {"moment": [0.0, 0.3, 0.0]}}}]
    res = _run(raw, tmp_path)
    assert res.exit_code == 0
    steps = res.summary["steps"]
    for s in steps:
        rb = s["rigid_bodies"]["plate"]
        np.testing.assert_allclose(np.add(rb["contact_force"], rb["applied_force"])[2], 0.0, atol=1e-6)
        np.testing.assert_allclose(np.add(rb["contact_moment"], rb["applied_moment"])[:2], 0.0, atol=1e-6)
    pressed, tilted = steps[1]["rigid_bodies"]["plate"], steps[-1]["rigid_bodies"]["plate"]
    np.testing.assert_allclose(pressed["applied_moment"], 0.0, atol=1e-12)
    np.testing.assert_allclose(tilted["applied_moment"], [0.0, 0.3, 0.0], atol=1e-12)
    np.testing.assert_allclose(tilted["applied_force"], [0.0, 0.0, -10.0], atol=1e-12)  # held
    # pressed, it tilts only slightly (the block's lateral expansion shifts the pressure centre); the
    # moment turns it about +y by a good deal more
    assert tilted["rotation"][1] - pressed["rotation"][1] > 10 * abs(pressed["rotation"][1])


def test_moment_target_on_a_moved_component_is_refused(tmp_path):
    raw = _problem({"name": "plate", "shape": "plane", "point": [0.0, 0.0, 1.0], "normal": [0.0, 0.0, -1.0],
                    "free": ["z"], "force": [0.0, 0.0, -10.0]},
                   {"slave": "block.zmax", "master": "plate", "penalty": 1e5, "weighting": "area"})
    raw["stages"] = [{"name": "tilt", "targets": {"plate": {"moment": [0.0, 0.3, 0.0]}}}]
    with pytest.raises(InputError, match="moment y component given, but rigid body 'plate' is moved in 'ry'"):
        problem_from_dict(raw, tmp_path / "p.toml")


def test_force_driven_body_is_parked_when_its_pairs_are_off(tmp_path):
    """A stage that switches off every pair of a force-driven plate holds the plate where it is (nothing
    else would restrain it); the block, unloaded, springs back to its original height; resume-safe state."""
    raw = _problem({"name": "plate", "shape": "plane", "point": [0.0, 0.0, 1.0], "normal": [0.0, 0.0, -1.0],
                    "free": ["z"], "force": [0.0, 0.0, -10.0]},
                   {"name": "press", "slave": "block.zmax", "master": "plate", "penalty": 1e5,
                    "weighting": "area"})
    raw["problem"]["stage"] = "press"
    raw["steps"] = {"count": 2}
    raw["stages"] = [{"name": "lift", "steps": {"count": 2}, "contacts": {"press": False}}]
    res = _run(raw, tmp_path)
    assert res.exit_code == 0, res.summary["steps"][-1].get("failure")
    pressed, lifted = res.summary["steps"][1], res.summary["steps"][-1]
    z_pressed = pressed["rigid_bodies"]["plate"]["displacement"][2]
    assert z_pressed < -0.009
    # parked: the plate stays where the press left it, the block is free of load
    assert lifted["rigid_bodies"]["plate"]["displacement"][2] == pytest.approx(z_pressed, abs=1e-14)
    np.testing.assert_allclose(lifted["reactions"]["block.zmin"], 0.0, atol=1e-8)
    assert lifted["active_contacts"] == 0
