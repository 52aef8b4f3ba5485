"""What the distributed solvers (``petsc``, ``petsc-gamg``, ``--ranks N``) run and what they refuse: dynamic stages
and gravity run (tests/mpi/test_dynamics.py); springs and dashpots are refused before anything starts, with one line
and exit code 2 naming the feature and the fix (a serial solver). No MPI needed: the refusal comes first."""

from __future__ import annotations

import subprocess
import sys

import pytest

from covcontact.io.loader import load_problem
from covcontact.io.validate import InputError
from covcontact.solvers.choice import check_distributable

BAR = """
[problem]
name = "bar"
procedure = "dynamic"
gravity = [0.0, 0.0, -1.0]
dt = 0.1
t_end = 0.5
mass = "lumped"
[[bodies]]
name = "bar"
material = { model = "svk", E = 1.0, nu = 0.0, density = 1.0 }
mesh = { generator = "block", lx = 1.0, ly = 0.1, lz = 0.1, nx = 4, ny = 1, nz = 1 }
[[initial_velocity]]
body = "bar"
value = [0.01, 0.0, 0.0]
[output]
vtu = false
"""

DASHPOT = """
[[dashpot]]
nodes = ["bar.xmin"]
anchor = [-1.0, 0.0, 0.0]
coefficient = 0.1
"""


def test_dynamics_and_gravity_are_distributable(tmp_path):
    path = tmp_path / "bar.toml"
    path.write_text(BAR)
    problem = load_problem(path)
    for linear in ("petsc", "petsc-gamg"):
        check_distributable(problem, linear, 2)  # no longer refused


def test_dashpots_refused_with_one_line(tmp_path):
    path = tmp_path / "dashpot.toml"
    path.write_text(BAR + DASHPOT)
    with pytest.raises(InputError) as err:
        check_distributable(load_problem(path), "petsc", 2)
    message = str(err.value)
    assert "\n" not in message and "dashpot" in message and "serial solver" in message
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "covcontact.cli", "run", str(path), "--solver", "petsc", "--quiet", "--out", str(out)]
    proc = subprocess.run(cmd, check=False, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc.stderr[-2000:]
    assert proc.stderr.count("\n") == 1 and "covcontact: error" in proc.stderr and "[[dashpot]]" in proc.stderr
    assert "use a serial solver" in proc.stderr and not out.exists()
