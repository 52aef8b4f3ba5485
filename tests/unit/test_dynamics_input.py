"""Bad input of dynamic stages: one line naming the key (docs/input.md, "Dynamics")."""

from __future__ import annotations

import pytest

from covcontact.io.loader import load_problem
from covcontact.io.validate import InputError

BASE = """
[problem]
name = "dyn"
procedure = "dynamic"
dt = 0.1
t_end = 1.0
[[bodies]]
name = "bar"
material = { model = "svk", E = 1.0, nu = 0.0, density = 1.0 }
mesh = { generator = "block", lx = 1.0, ly = 0.1, lz = 0.1, nx = 4, ny = 1, nz = 1 }
[[dirichlet]]
set = "bar.xmin"
[[initial_velocity]]
set = "bar.xmax"
value = [0.0, 0.0, 0.1]
"""


@pytest.mark.parametrize("change, key, message", [
    ((", density = 1.0", ""), "bodies[0].material.density", "missing: a dynamic stage needs the mass density"),
    (("dt = 0.1", "dt = -0.1"), "problem.dt", "must be > 0"),
    (("dt = 0.1", "dt = 2.0"), "problem.dt", "exceeds the stage's duration"),
    (("t_end = 1.0", "t_end = 1.0\nrho_inf = 1.5"), "problem.rho_inf", "must lie in [0, 1]"),
    (("t_end = 1.0", 't_end = 1.0\nmethod = "hht"\nrho_inf = 0.3'), "problem.rho_inf", "must lie in [0.5, 1]"),
    (("t_end = 1.0", 't_end = 1.0\nmethod = "newmark"\nrho_inf = 0.8'), "problem.rho_inf", "no numerical damping"),
    (("t_end = 1.0", 't_end = 1.0\nmethod = "central"'), "problem.method", "is not one of"),
    (('set = "bar.xmax"', 'set = "bar.xmux"'), "initial_velocity[0].set", "has no node set 'xmux'"),
    (('procedure = "dynamic"\n', ""), "problem.dt", "belongs to a dynamic stage"),
    (("[[dirichlet]]", "[steps]\ncount = 3\n[[dirichlet]]"), "steps", "takes its steps from dt and t_end"),
    (("t_end = 1.0", "t_end = 1.0\ndt_min = 0.01"), "problem.dt_min", "need both dt_min and dt_max"),
    (("t_end = 1.0", "t_end = 1.0\ndt_min = 0.2\ndt_max = 0.5"), "problem.dt", "must lie between dt_min"),
    (("t_end = 1.0", "t_end = 1.0\ndt_min = 0.01\ndt_max = 2.0"), "problem.dt_max", "must not exceed"),
])
def test_one_line(tmp_path, change, key, message):
    path = tmp_path / "p.toml"
    path.write_text(BASE.replace(*change, 1))
    with pytest.raises(InputError) as err:
        load_problem(path)
    msg = str(err.value)
    assert key in msg and message in msg, msg
    assert "\n" not in msg


def test_initial_velocity_needs_a_dynamic_stage(tmp_path):
    path = tmp_path / "p.toml"
    path.write_text(BASE.replace('procedure = "dynamic"\ndt = 0.1\nt_end = 1.0\n', ""))
    with pytest.raises(InputError) as err:
        load_problem(path)
    assert "initial_velocity" in str(err.value) and "need a dynamic stage" in str(err.value)


def test_a_good_file_loads(tmp_path):
    path = tmp_path / "p.toml"
    path.write_text(BASE)
    prob = load_problem(path)
    assert prob.dynamics.dt == 0.1 and prob.dynamics.method == "generalized-alpha"
    assert prob.dynamics.mass == "auto"  # (consistent-redistributed with contact, consistent without)
    assert len(prob.steps.factors) == 10 and prob.steps.factors[-1] == 1.0
    assert prob.initial_velocity[0].value == (0.0, 0.0, 0.1)
