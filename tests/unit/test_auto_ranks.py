"""``covcontact run`` without ``--ranks`` (``--ranks auto``, solvers/run.py auto_ranks): one MPI rank per core
where ``auto`` hands the problem to petsc-gamg, else one process; and the thread variables shared among ranks."""

from __future__ import annotations

import shutil
from types import SimpleNamespace

import numpy as np
import pytest

from covcontact.cli import main
from covcontact.parallel import launcher
from covcontact.parallel.launcher import threads_per_rank
from covcontact.solvers import choice as run_mod
from covcontact.solvers.choice import AUTO_DOFS_PER_RANK, auto_ranks, checkpoint_ranks, thread_budget


def _problem(dofs: int, linear: str | None = None):
    """What auto_ranks reads of a problem: its bodies' node counts, the solver asked for, the name."""
    mesh = SimpleNamespace(points=np.zeros((-(-dofs // 3), 3)))  # at least ``dofs`` dofs
    return SimpleNamespace(bodies=[SimpleNamespace(mesh=mesh)], solver=SimpleNamespace(linear=linear), name="p")


@pytest.fixture
def machine(monkeypatch):
    """Four cores, mpiexec on the PATH, not under a launcher, no thread variables; ``auto`` picks petsc-gamg
    (as it does for a large frictionless problem of bulky solid bodies with PETSc installed)."""
    for key in (*launcher._SIZE, *launcher.THREAD_VARS):
        monkeypatch.delenv(key, raising=False)
    monkeypatch.setattr(launcher, "cores_here", lambda: 4)
    monkeypatch.setattr(shutil, "which", lambda name: "/bin/" + name)
    monkeypatch.setattr(run_mod, "resolve_linear", lambda problem, linear, ranks=None: "petsc-gamg")
    return monkeypatch


def test_one_rank_per_core_and_enough_dofs_per_rank(machine, tmp_path):
    assert thread_budget() == 4
    assert auto_ranks(_problem(4 * AUTO_DOFS_PER_RANK), None, tmp_path, False) == 4
    assert auto_ranks(_problem(10 * AUTO_DOFS_PER_RANK), None, tmp_path, False) == 4  # no more than the cores
    assert auto_ranks(_problem(2 * AUTO_DOFS_PER_RANK + 3), None, tmp_path, False) == 2
    assert auto_ranks(_problem(AUTO_DOFS_PER_RANK // 2), None, tmp_path, False) == 1


def test_thread_variable_is_the_budget(machine, tmp_path):
    machine.setenv("NUMBA_NUM_THREADS", "2")
    assert thread_budget() == 2
    assert auto_ranks(_problem(10 * AUTO_DOFS_PER_RANK), None, tmp_path, False) == 2
    machine.setenv("NUMBA_NUM_THREADS", "1")  # a one-thread run stays one process
    assert auto_ranks(_problem(10 * AUTO_DOFS_PER_RANK), None, tmp_path, False) == 1


def test_one_process_otherwise(machine, tmp_path):
    big = 10 * AUTO_DOFS_PER_RANK
    assert auto_ranks(_problem(big, linear="petsc-gamg"), None, tmp_path, False) == 1  # a solver asked for
    assert auto_ranks(_problem(big), "pardiso", tmp_path, False) == 1  # on the command line
    machine.setattr(run_mod, "resolve_linear", lambda problem, linear, ranks=None: "auto")  # a direct solver
    assert auto_ranks(_problem(big), None, tmp_path, False) == 1
    machine.setattr(run_mod, "resolve_linear", lambda problem, linear, ranks=None: "petsc-gamg")
    machine.setattr(shutil, "which", lambda name: None)  # no mpiexec
    assert auto_ranks(_problem(big), None, tmp_path, False) == 1
    machine.setattr(shutil, "which", lambda name: "/bin/" + name)
    machine.setenv("OMPI_COMM_WORLD_SIZE", "2")  # a rank of an MPI job
    assert auto_ranks(_problem(big), None, tmp_path, False) == 1


def test_resume_takes_the_checkpoints_ranks(machine, tmp_path):
    big = 10 * AUTO_DOFS_PER_RANK
    assert checkpoint_ranks(tmp_path) is None
    assert auto_ranks(_problem(big), None, tmp_path, True) == 4  # nothing to resume: the rule (load then refuses)
    (tmp_path / "checkpoint.rank0-of-3.npz").write_bytes(b"")
    (tmp_path / "checkpoint.rank1-of-3.npz").write_bytes(b"")
    assert checkpoint_ranks(tmp_path) == 3
    assert auto_ranks(_problem(big), None, tmp_path, True) == 3
    assert auto_ranks(_problem(big), None, tmp_path, False) == 4  # a fresh run: the rule
    one = tmp_path / "one"
    one.mkdir()
    (one / "checkpoint.npz").write_bytes(b"")
    assert auto_ranks(_problem(big), None, one, True) == 1


def test_threads_shared_among_ranks():
    env = {"NUMBA_NUM_THREADS": "4", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "3", "PATH": "/bin"}
    assert threads_per_rank(env, 2) == {"NUMBA_NUM_THREADS": "2", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
    assert threads_per_rank({"PATH": "/bin"}, 2) == {}


def test_ranks_option(tmp_path, capsys):
    path = tmp_path / "p.toml"
    path.write_text(
        '[problem]\nname = "tiny"\n\n[[bodies]]\nname = "cube"\nelement = "hex8"\n'
        'material = { model = "svk", E = 100.0, nu = 0.3 }\n'
        'mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 1.0, nx = 2, ny = 2, nz = 2 }\n\n'
        '[[dirichlet]]\nset = "cube.zmin"\ncomponents = "xyz"\n\n[[pressure]]\nset = "cube.zmax"\nvalue = 1.0\n')
    with pytest.raises(SystemExit) as exc:
        main(["run", str(path), "--ranks", "two"])
    err = capsys.readouterr().err
    assert exc.value.code == 2 and err.count("\n") == 1 and "number of ranks or auto" in err
    # auto on a small problem: this process, as before
    assert main(["run", str(path), "--ranks", "auto", "--quiet", "--out", str(tmp_path / "o")]) == 0
    assert (tmp_path / "o" / "summary.json").is_file()


def test_cgroup_quota(tmp_path):
    """A container's CPU quota bounds the cores (cgroup v2 cpu.max, v1 cfs quota / period; none: no bound)."""
    from covcontact.parallel.launcher import cgroup_cpus

    assert cgroup_cpus(str(tmp_path)) is None
    (tmp_path / "cpu.max").write_text("max 100000\n")
    assert cgroup_cpus(str(tmp_path)) is None
    (tmp_path / "cpu.max").write_text("150000 100000\n")
    assert cgroup_cpus(str(tmp_path)) == 2
    v1 = tmp_path / "v1"
    (v1 / "cpu").mkdir(parents=True)
    (v1 / "cpu" / "cpu.cfs_quota_us").write_text("-1\n")
    (v1 / "cpu" / "cpu.cfs_period_us").write_text("100000\n")
    assert cgroup_cpus(str(v1)) is None
    (v1 / "cpu" / "cpu.cfs_quota_us").write_text("400000\n")
    assert cgroup_cpus(str(v1)) == 4
