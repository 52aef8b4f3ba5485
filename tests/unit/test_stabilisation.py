"""Bodies held by contact alone (docs/input.md, "Bodies held by contact alone"): a block that rests on a
frictionless rigid floor with nothing else holding it, pressed onto it from a small gap. The tangent is
singular until the block touches (and stays singular in the sliding directions); Newton then ties the block
to where it started with soft springs, converges, takes the springs off and converges again: the answer is
the problem's own."""

from __future__ import annotations

import numpy as np
import pytest

from covcontact.io.loader import problem_from_dict
from covcontact.solvers.linear import available

#: the direct solvers of this installation (PARDISO is an optional extra)
SOLVERS = [s for s in ("superlu", "pardiso") if s in available()]


def _raw(floor_z: float, friction: float = 0.0) -> dict:
    return {
        "problem": {"name": "rest"},
        "bodies": [{"name": "block", "material": {"model": "neo-hooke", "E": 1000.0, "nu": 0.3},
                    "mesh": {"generator": "block", "lx": 1.0, "ly": 1.0, "lz": 1.0, "nx": 2, "ny": 2, "nz": 2}}],
        "rigid": [{"name": "floor", "shape": "plane", "point": [0.0, 0.0, floor_z], "normal": [0.0, 0.0, 1.0]}],
        "contact": [{"name": "rest", "slave": "block.zmin", "master": "floor", "penalty": 1.0e5,
                     "friction": friction}],
        "pressure": [{"set": "block.zmax", "value": 10.0}],
        "steps": {"count": 2},
        "output": {"vtu": False},
    }


@pytest.mark.parametrize("solver", SOLVERS)
@pytest.mark.parametrize("friction", [0.0, 0.3])
def test_block_pressed_onto_a_floor_from_a_gap(tmp_path, solver, friction):
    gap = 1e-3
    touching = problem_from_dict(_raw(0.0, friction), tmp_path / "a.toml").run(out=tmp_path / "a", solver=solver)
    apart = problem_from_dict(_raw(-gap, friction), tmp_path / "b.toml").run(out=tmp_path / "b", solver=solver)
    assert touching.exit_code == 0 and apart.exit_code == 0, apart.summary["steps"][-1]
    first = apart.summary["steps"][0]
    assert first["stabilised"] and first["cutbacks"] == 0
    assert "stabilised" not in apart.summary["steps"][1]  # in contact from then on: a regular tangent
    # the floor moved down by the gap: the same equilibrium moved down by the gap (nothing else holds it) ...
    ua, ub = touching.u.reshape(-1, 3), apart.u.reshape(-1, 3)
    np.testing.assert_allclose(ub[:, 2], ua[:, 2] - gap, atol=1e-9)
    assert abs(apart.summary["steps"][-1]["pairs"]["rest"]["contact_force"][2]) == pytest.approx(10.0, rel=1e-8)
    if friction == 0.0:
        # ... up to a rigid motion in the plane of the floor, which nothing determines without friction
        X = apart.model.system.X
        pa, pb = X[:, :2] + ua[:, :2], X[:, :2] + ub[:, :2]
        ca, cb = pa.mean(axis=0), pb.mean(axis=0)
        U, _, Vt = np.linalg.svd((pb - cb).T @ (pa - ca))  # the rotation taking pa onto pb (Kabsch)
        R = U @ Vt
        assert np.abs((pa - ca) @ R.T + cb - pb).max() < 1e-9
