"""Guard rails: a legal set-up that is almost certainly wrong starts with a warning (stderr and summary.json)."""

from __future__ import annotations

from pathlib import Path

import pytest

from covcontact.io.loader import problem_from_dict


def _raw(outside: bool, center_z: float) -> dict:
    return {
        "problem": {"name": "ball"},
        "bodies": [{"name": "block", "material": {"model": "neo-hooke", "E": 1000.0, "nu": 0.3},
                    "mesh": {"generator": "block", "lx": 1.0, "ly": 1.0, "lz": 1.0, "nx": 3, "ny": 3, "nz": 2}}],
        "rigid": [{"name": "ball", "shape": "sphere", "center": [0.5, 0.5, center_z], "radius": 0.5,
                   "outside": outside, "motion": {"translation": [0.0, 0.0, -0.02]}}],
        "contact": [{"name": "indent", "slave": "block.zmax", "master": "ball", "penalty": 1e5}],
        "dirichlet": [{"set": "block.zmin"}],
        "output": {"vtu": False},
    }


def test_inside_out_sphere_is_warned(tmp_path, capsys):
    problem = problem_from_dict(_raw(False, 1.5), tmp_path / "p.toml")
    res = problem.run(out=tmp_path / "out", quiet=False)
    warnings = res.summary["warnings"]
    assert len(warnings) == 1
    assert "contact 'indent'" in warnings[0] and "outside = false" in warnings[0]
    assert "slave nodes start inside the analytic sphere 'ball'" in warnings[0]
    assert "warning: contact 'indent'" in capsys.readouterr().err


@pytest.mark.parametrize("center_z", [1.5, 1.49])  # touching, and pressed in by 0.01 (shallow)
def test_a_correct_set_up_is_not_warned(tmp_path, center_z):
    problem = problem_from_dict(_raw(True, center_z), tmp_path / "p.toml")
    res = problem.run(out=tmp_path / "out")
    assert res.exit_code == 0 and "warnings" not in res.summary


def test_overlapping_bodies_are_warned(tmp_path):
    """The master block placed 0.2 into the slave block (misplaced, or a mesh in other units): every slave
    node of the top starts 0.2 deep in it (node spacing 0.5)."""
    raw = {
        "problem": {"name": "overlap"},
        "bodies": [{"name": "low", "material": {"model": "neo-hooke", "E": 1000.0, "nu": 0.3},
                    "mesh": {"generator": "block", "lx": 1.0, "ly": 1.0, "lz": 1.0, "nx": 2, "ny": 2, "nz": 2}},
                   {"name": "up", "material": {"model": "neo-hooke", "E": 1000.0, "nu": 0.3},
                    "mesh": {"generator": "block", "lx": 1.0, "ly": 1.0, "lz": 1.0, "nx": 2, "ny": 2, "nz": 2,
                             "origin": [0.0, 0.0, 0.8]}}],
        "contact": [{"name": "stack", "slave": "low.zmax", "master": "up.zmin", "penalty": 1e4}],
        "dirichlet": [{"set": "low.zmin"}, {"set": "up.zmax"}],
        "output": {"vtu": False},
    }
    from covcontact.solvers.model import Model

    model = Model(problem_from_dict(raw, tmp_path / "p.toml"))
    warnings = model.start_warnings(model.prescribed(0.0), model.initial_state())
    assert len(warnings) == 1 and "9 of 9 slave nodes start inside the faces up.zmin" in warnings[0]
    raw["bodies"][1]["mesh"]["origin"] = [0.0, 0.0, 1.0]  # placed right: touching
    model = Model(problem_from_dict(raw, tmp_path / "p.toml"))
    assert model.start_warnings(model.prescribed(0.0), model.initial_state()) == []


def test_a_few_nodes_deep_inside_are_warned():
    """A minority of slave nodes starting deeper than a tenth of the node spacing inside the master is warned
    too (with how many, how deep and the deepest node); touching or grazing is not."""
    from covcontact.solvers.model import Model

    for dip, warned in ((0.05, True), (0.01, False)):  # node spacing about 0.28: 0.05 is 18 % of it, 0.01 4 %
        raw = _raw(True, 1.0 + 0.3 - dip)
        raw["rigid"][0]["radius"] = 0.3
        raw["bodies"][0]["mesh"].update(nx=4, ny=4)  # a node at the centre of the top, under the sphere
        model = Model(problem_from_dict(raw, Path("dip.toml")))
        warnings = model.start_warnings(model.prescribed(0.0), model.initial_state())
        if warned:
            assert len(warnings) == 1 and "slave nodes start inside the analytic sphere 'ball'" in warnings[0]
            assert "1 of 25 slave nodes start inside" in warnings[0] and "down to -0.05 (node" in warnings[0]
            assert "move the bodies apart or check the geometry" in warnings[0]
        else:
            assert warnings == []


@pytest.mark.parametrize("E, warned", [(206000.0, False), (206.0, True), (2.06e11, True)])
def test_mixed_units_of_a_plastic_material_are_warned(tmp_path, E, warned):
    """A J2 bar with the yield stress in MPa and E in MPa (fine), GPa or Pa (E / sigma_y0 = 0.8 or 8e8: mixed
    units): the run goes on, with a warning naming the body and the ratio."""
    raw = {"problem": {"name": "bar"},
           "bodies": [{"name": "bar", "material": {"model": "j2", "E": E, "nu": 0.3, "yield_stress": 250.0,
                                                   "hardening": {"law": "linear", "modulus": 1000.0}},
                       "mesh": {"generator": "block", "lx": 1.0, "ly": 1.0, "lz": 1.0, "nx": 1, "ny": 1, "nz": 1}}],
           "dirichlet": [{"set": "bar.zmin"}, {"set": "bar.zmax", "components": "z", "value": 1e-4}],
           "output": {"vtu": False}}
    res = problem_from_dict(raw, tmp_path / "p.toml").run(out=tmp_path / "out")
    assert res.exit_code == 0
    warnings = res.summary.get("warnings", [])
    assert bool(warnings) == warned
    if warned:
        assert "body 'bar'" in warnings[0] and "same units" in warnings[0]
