"""Follower pressures in distributed runs: ``mpiexec -n 2 ... --solver petsc`` equals the serial run and the closed
form of a cube under a hydrostatic pressure on its current faces (tests/unit/test_follower.py). The pressure's
blocks are assembled once, on rank 0; every rank keeps the load's values for its convergence checks.

Needs the ``mpi`` extra (mpi4py, petsc4py) and ``mpiexec``: skipped without them, unless COVCONTACT_REQUIRE_MPI=1."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from test_dynamics import _mpiexec, _need_mpi  # noqa: F401  (the fixture skips without the MPI extra)

from covcontact.io.loader import load_problem

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "unit"))
from test_follower import _CUBE, _hydrostatic  # noqa: E402

#: the unit test's cube on a 4 x 4 x 4 mesh, three steps, no VTU
CUBE = (_CUBE.replace("CELL", "hex8").replace("nx = 2, ny = 2, nz = 2", "nx = 4, ny = 4, nz = 4")
        .replace("LOADS", _hydrostatic(150.0, True)).replace("count = 4", "count = 3\n[output]\nvtu = false"))


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
