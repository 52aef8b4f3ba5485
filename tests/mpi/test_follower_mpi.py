"""Follower pressures in distributed runs: ``mpiexec -n 2 ... --solver petsc`` equals the serial run and the closed
form of a cube under a hydrostatic pressure on its current faces (tests/unit/test_follower.py). The pressure's
blocks are assembled once, on rank 0; every rank keeps the load's values for its convergence checks.

Needs the ``mpi`` extra (mpi4py, petsc4py) and ``mpiexec``: skipped without them, unless COVCONTACT_REQUIRE_MPI=1."""

from __future__ import annotations

import os

import numpy as np
import pytest
from test_dynamics import MISSING, _mpiexec

from covcontact.io.loader import load_problem


@pytest.fixture(autouse=True)
def _need_mpi():
    if MISSING:
        if os.environ.get("COVCONTACT_REQUIRE_MPI") == "1":
            pytest.fail(f"COVCONTACT_REQUIRE_MPI=1 but the MPI extra is missing: {MISSING}")
        pytest.skip(f"MPI extra not installed ({MISSING}); bash tools/install-mpi.sh installs it (PETSc from source)")


CUBE = """
[problem]
name = "cube"
[[bodies]]
name = "c"
element = "hex8"
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 1.0, nx = 4, ny = 4, nz = 4 }
material = { model = "svk", E = 1000.0, nu = 0.3 }
[[dirichlet]]
set = "c.xmin"
components = "x"
[[dirichlet]]
set = "c.ymin"
components = "y"
[[dirichlet]]
set = "c.zmin"
components = "z"
[[pressure]]
set = "c.xmax"
value = 150.0
follower = true
[[pressure]]
set = "c.ymax"
value = 150.0
follower = true
[[pressure]]
set = "c.zmax"
value = 150.0
follower = true
[steps]
count = 3
[output]
vtu = false
"""


def test_follower_pressure_two_ranks(tmp_path):
    """The cube of tests/unit/test_follower.py (4 x 4 x 4 hex8) on two ranks: the same iterations as the serial run,
    the closed-form stretch s = (-p + sqrt(p^2 + K3^2)) / K3 at every node to 1e-9 and the support force p s^2."""
    path = tmp_path / "cube.toml"
    path.write_text(CUBE)
    ref = load_problem(path).run(out=tmp_path / "serial", quiet=True)
    assert ref.exit_code == 0
    summary = _mpiexec(path, tmp_path / "mpi")
    assert summary["status"] == "completed" and summary["parallel"]["ranks"] == 2
    assert [s["iterations"] for s in summary["steps"]] == [s["iterations"] for s in ref.summary["steps"]]
    p, K3 = 150.0, 1000.0 / 0.4
    s = (-p + np.sqrt(p * p + K3 * K3)) / K3
    u = np.load(tmp_path / "mpi" / "checkpoint.rank0-of-2.npz")["u"].reshape(-1, 3)
    X = load_problem(path).bodies[0].mesh.points
    assert np.abs(u[: len(X)] - (s - 1) * X).max() < 1e-9
    assert summary["steps"][-1]["reactions"]["c.xmin"][0] == pytest.approx(p * s * s, rel=1e-9)
