"""``[[contact]] adjust``: slave nodes moved onto their meshed master before the first step (docs/input.md)."""

from __future__ import annotations

import numpy as np
import pytest

from covcontact.io.loader import load_problem
from covcontact.io.validate import InputError

PUNCH = """
[problem]
name = "adjusted"
[[bodies]]
name = "base"
element = "hex8"
material = { model = "svk", E = 1000.0, nu = 0.3 }
mesh = { generator = "block", lx = 2.0, ly = 2.0, lz = 1.0, nx = 4, ny = 4, nz = 2 }
[[bodies]]
name = "punch"
element = "hex8"
material = { model = "svk", E = 1000.0, nu = 0.3 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 0.5, nx = 3, ny = 3, nz = 1, origin = [0.5, 0.5, Z0] }
[[dirichlet]]
set = "punch.zmax"
components = "xy"
[[dirichlet]]
set = "base.zmin"
[[pressure]]
set = "punch.zmax"
value = 10.0
[[contact]]
slave = "punch.zmin"
master = "base.zmax"
penalty = 1.0e5
weighting = "area"
ADJUST
[steps]
count = 2
"""


def _write(tmp_path, z0: float, adjust: str):
    path = tmp_path / "p.toml"
    path.write_text(PUNCH.replace("Z0", repr(z0)).replace("ADJUST", adjust))
    return path


@pytest.mark.parametrize("z0, adjust", [(1.01, "adjust = 0.02"), (0.995, "adjust = 0.02"),
                                        (1.01, 'adjust = "zmin"')], ids=["gap", "overlap", "node-set"])
def test_slave_nodes_start_on_the_master(tmp_path, z0, adjust):
    """A punch meshed 0.01 above (or 0.005 into) the flat top of a block: its 16 bottom nodes start on it (z = 1 to
    1e-12), said at the start of the run, and the pressure is carried from the first step (every slave active, the
    support's reaction 10 A to 1e-9) with no rigid-body motion of the punch to find first."""
    path = _write(tmp_path, z0, adjust)
    problem = load_problem(path)
    res = problem.run(out=tmp_path / "out", quiet=True)
    assert res.exit_code == 0
    pts = problem.bodies[1].mesh.points
    bottom = pts[np.isclose(pts[:, 2], pts[:, 2].min(), atol=0.02)]
    assert len(bottom) == 16 and np.abs(bottom[:, 2] - 1.0).max() < 1e-12
    (line,) = res.summary["warnings"]
    assert f"16 slave node(s) moved onto the master before the first step (adjust), by {abs(z0 - 1.0):.3g}" in line
    first = res.summary["steps"][0]
    assert first["pairs"]["contact1"]["active_contacts"] == 16
    assert res.summary["steps"][-1]["reactions"]["base.zmin"][2] == pytest.approx(10.0, rel=1e-9)


def test_adjust_leaves_farther_nodes_and_rejects_what_it_cannot_do(tmp_path):
    """A distance below the gap moves nothing (the nodes keep their places); one-line errors for a negative distance,
    an unknown node set (with a suggestion), an analytic master and self-contact."""
    from covcontact.solvers.model import Model

    problem = load_problem(_write(tmp_path, 1.01, "adjust = 0.005"))
    Model(problem)
    assert problem.adjusted == ["contact pair 'contact1': 0 slave node(s) moved onto the master before the first step "
                                "(adjust), by 0 at most"]
    assert np.isclose(problem.bodies[1].mesh.points[:, 2].min(), 1.01)
    text = PUNCH.replace("Z0", "1.0")
    cases = {
        text.replace("ADJUST", "adjust = -0.1"): "must be >= 0",
        text.replace("ADJUST", 'adjust = "zmn"'): "has no node set 'zmn'; did you mean 'zmin'",
        text.replace("ADJUST", "adjust = 0.1").replace('master = "base.zmax"', 'master = "floor"')
        + '[[rigid]]\nname = "floor"\nshape = "plane"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\n':
            "'floor' is an analytic surface",
        text.replace("ADJUST", "adjust = 0.1").replace('slave = "punch.zmin"\nmaster = "base.zmax"',
                                                        'self = "punch.zmin"'): "not for self-contact",
    }
    path = tmp_path / "bad.toml"
    for bad, words in cases.items():
        path.write_text(bad)
        with pytest.raises(InputError) as err:
            load_problem(path)
        assert words in str(err.value) and "\n" not in str(err.value), (words, str(err.value))
