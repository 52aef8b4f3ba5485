"""Distributed runs on PETSc: ``--solver petsc`` on one process equals the default solver, and
``mpiexec -n 2 ... --solver petsc`` equals the serial run (same Newton iterations per step, displacements
to solver tolerance), for a deformable contact pair, a frictional pair, GAMG, and a failing step.

Needs the ``mpi`` extra (mpi4py, petsc4py) and ``mpiexec``. Without them the tests are skipped, unless
COVCONTACT_REQUIRE_MPI=1 (CI after installing the extra): then they fail.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import meshio
import numpy as np
import pytest

from covcontact.io.loader import load_problem

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
TWO_BLOCKS = EXAMPLES / "contact" / "two_blocks.toml"
SLIDING = EXAMPLES / "friction" / "block_sliding.toml"


def _missing() -> str:
    try:
        import mpi4py  # noqa: F401
        import petsc4py  # noqa: F401
    except ImportError as exc:
        return f"{exc}"
    if shutil.which("mpiexec") is None:
        return "mpiexec not found"
    from covcontact.solvers.linear import available

    if "petsc" not in available():
        return "the petsc backend is not available (PETSc without MUMPS?)"
    return ""


MISSING = _missing()


@pytest.fixture(autouse=True)
def _need_mpi():
    if MISSING:
        if os.environ.get("COVCONTACT_REQUIRE_MPI") == "1":
            pytest.fail(f"COVCONTACT_REQUIRE_MPI=1 but the MPI extra is missing: {MISSING}")
        pytest.skip(f"MPI extra not installed ({MISSING}); bash tools/install-mpi.sh installs it (PETSc from source)")


def _serial(path: Path, out: Path, solver: str | None = None):
    problem = load_problem(path)
    return problem.run(out=out, quiet=True, solver=solver)


def _mpiexec_proc(path: Path, out: Path, solver: str, n: int = 2, extra: tuple[str, ...] = ()
                  ) -> subprocess.CompletedProcess:
    env = dict(os.environ)
    if hasattr(os, "geteuid") and os.geteuid() == 0:
        env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    cmd = ["mpiexec", "-n", str(n), "--oversubscribe", "--bind-to", "none", sys.executable, "-m",
           "covcontact.cli", "run", str(path), "--solver", solver, "--out", str(out), "--quiet", *extra]
    return subprocess.run(cmd, check=False, env=env, capture_output=True, text=True, timeout=300)


def _mpiexec(path: Path, out: Path, solver: str, n: int = 2, extra: tuple[str, ...] = ()) -> int:
    proc = _mpiexec_proc(path, out, solver, n, extra)
    assert proc.returncode in (0, 1), proc.stderr[-3000:]
    return proc.returncode


def _iterations(summary: dict) -> list[int]:
    return [s["iterations"] for s in summary["steps"]]


def _final_displacement(out: Path) -> np.ndarray:
    last = max(out.glob("step_*.vtu"))
    return meshio.read(last).point_data["displacement"]


def test_serial_petsc_matches_default(tmp_path):
    ref = _serial(TWO_BLOCKS, tmp_path / "ref")
    res = _serial(TWO_BLOCKS, tmp_path / "petsc", solver="petsc")
    assert res.summary["linear_solver"] == "petsc" and res.summary["parallel"]["ranks"] == 1
    assert res.exit_code == ref.exit_code == 0
    assert _iterations(res.summary) == _iterations(ref.summary)
    assert np.linalg.norm(res.u - ref.u) <= 1e-8 * np.linalg.norm(ref.u)
    # the output fields gathered by the distributed model equal the serial ones
    np.testing.assert_allclose(_final_displacement(tmp_path / "petsc"), _final_displacement(tmp_path / "ref"),
                               rtol=0, atol=1e-8 * np.abs(ref.u).max())


@pytest.mark.parametrize(("path", "solver", "tol"), [
    (TWO_BLOCKS, "petsc", 1e-9),        # deformable master, MUMPS Cholesky (LDL^T)
    (SLIDING, "petsc", 1e-7),           # Coulomb friction: non-symmetric, MUMPS LU, path-dependent
    (TWO_BLOCKS, "petsc-gamg", 1e-8),   # CG + GAMG with rigid-body modes
    ("sts", "petsc", 1e-7),             # segment-to-surface with friction: points split by their facet's owner
    ("self", "petsc", 1e-7),            # self-contact of both blocks' faces merged, with friction
    ("materials", "petsc", 1e-7),       # the base in two materials by element set, one of them plastic
    ("mixed", "petsc", 1e-7),           # a body of bricks and wedges, the wedges plastic, under a rigid plate
], ids=["deformable-pair", "friction", "gamg", "sts-friction", "self-contact", "two-materials", "mixed-cells"])
def test_two_ranks_match_serial(tmp_path, path, solver, tol):
    if path in ("materials", "mixed"):  # the resume test's set-ups (tests/test_resume.py)
        import importlib.util

        spec = importlib.util.spec_from_file_location("resume_setups", ROOT / "tests" / "test_resume.py")
        setups = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(setups)
        path = setups.two_materials(tmp_path) if path == "materials" else setups.mixed(tmp_path)
    if path in ("sts", "self"):
        text = TWO_BLOCKS.read_text()
        pair = 'slave = "punch.zmin"\nmaster = "base.zmax"\n'
        assert pair in text
        new = 'type = "sts"\n' + pair if path == "sts" else 'self = ["punch.zmin", "base.zmax"]\n'
        text = text.replace(pair, new + "friction = 0.2\n").replace("value = [0.0, 0.0, -0.02]",
                                                                      "value = [0.02, 0.0, -0.02]")
        path = tmp_path / f"{path}.toml"
        path.write_text(text)
    if path == SLIDING:  # half the load steps: a shorter test, still sticking and then sliding
        text = path.read_text().replace("count = 10", "count = 5")
        path = tmp_path / path.name
        path.write_text(text)
    ref = _serial(path, tmp_path / "ref")
    assert _mpiexec(path, tmp_path / "mpi", solver) == 0
    summary = json.loads((tmp_path / "mpi" / "summary.json").read_text())
    assert summary["converged"] and summary["linear_solver"] == solver
    par = summary["parallel"]
    assert par["ranks"] == 2 and min(par["elements"]) > 0 and min(par["owned_dofs"]) > 0
    assert _iterations(summary) == _iterations(ref.summary)
    for a, b in zip(summary["steps"], ref.summary["steps"]):
        assert a["active_contacts"] == b["active_contacts"]
        np.testing.assert_allclose(a["contact_force"], b["contact_force"], rtol=tol,
                                   atol=tol * np.abs(b["contact_force"]).max())
    u = _final_displacement(tmp_path / "mpi")
    u_ref = _final_displacement(tmp_path / "ref")
    assert np.abs(u - u_ref).max() <= tol * np.abs(u_ref).max()
    # rank 0 alone writes: one summary, one VTU per converged step
    assert len(list((tmp_path / "mpi").glob("step_*.vtu"))) == len(ref.summary["steps"]) + 1


def _ranks(path: Path, out: Path, *extra: str) -> subprocess.CompletedProcess:
    """``covcontact run --ranks 2``: the command starts mpiexec itself."""
    cmd = [sys.executable, "-m", "covcontact.cli", "run", str(path), "--ranks", "2", "--out", str(out), *extra]
    return subprocess.run(cmd, check=False, capture_output=True, text=True, timeout=300)


def test_ranks_option_equals_mpiexec(tmp_path):
    """``--ranks 2`` is ``mpiexec -n 2 ... run``: the same iterations and displacements; without a solver it picks
    the distributed direct one (MUMPS) for this small problem and says so."""
    proc = _ranks(TWO_BLOCKS, tmp_path / "ranks")
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert "linear solver: petsc (auto, 2 MPI ranks" in proc.stderr
    assert proc.stdout == ""  # plain text: no colour codes from numba under mpiexec
    summary = json.loads((tmp_path / "ranks" / "summary.json").read_text())
    assert summary["linear_solver"] == "petsc" and summary["parallel"]["ranks"] == 2
    assert _mpiexec(TWO_BLOCKS, tmp_path / "mpi", "petsc") == 0
    ref = json.loads((tmp_path / "mpi" / "summary.json").read_text())
    assert _iterations(summary) == _iterations(ref)
    u, u_ref = _final_displacement(tmp_path / "ranks"), _final_displacement(tmp_path / "mpi")
    assert np.abs(u - u_ref).max() <= 1e-12 * np.abs(u_ref).max()


def _processes_with(text: str) -> list[str]:
    """Command lines of the running processes that mention ``text`` (Linux /proc)."""
    found = []
    for cmdline in Path("/proc").glob("[0-9]*/cmdline"):
        try:
            args = cmdline.read_bytes().replace(b"\0", b" ").decode(errors="replace")
        except OSError:
            continue
        if text in args:
            found.append(args)
    return found


def test_ranks_stopped_by_sigterm(tmp_path):
    """SIGTERM to ``covcontact run --ranks 2``: the ranks stop together at their next Newton iteration, as a serial
    run does: exit code 143, summary "interrupted" with the converged steps, no process left; ``--resume`` then
    ends as the uninterrupted run (the same iterations, the displacements to 1e-12)."""
    path = ROOT / "benchmarks" / "problems" / "two_blocks_5k.toml"
    out = tmp_path / "stopped"
    cmd = [sys.executable, "-m", "covcontact.cli", "run", str(path), "--ranks", "2", "--out", str(out)]
    proc = subprocess.Popen(cmd, stderr=subprocess.PIPE, text=True)
    watchdog = threading.Timer(300, proc.kill)  # a hung run fails the test instead of hanging it
    watchdog.start()
    for line in proc.stderr:
        if line.startswith("step    1/"):
            break
    proc.send_signal(signal.SIGTERM)
    rest = proc.stderr.read()
    assert proc.wait(timeout=60) == 143
    watchdog.cancel()
    proc.stderr.close()
    deadline = time.monotonic() + 20
    while _processes_with(str(out)) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert _processes_with(str(out)) == []
    assert "stopped by SIGTERM: the step in flight is dropped; resume with --resume" in rest
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "interrupted" and 1 <= len(summary["steps"]) < 10
    assert all(s["converged"] for s in summary["steps"])
    resumed = _ranks(path, out, "--resume", "--quiet")
    assert resumed.returncode == 0, resumed.stderr[-3000:]
    ref = _ranks(path, tmp_path / "ref", "--quiet")
    assert ref.returncode == 0, ref.stderr[-3000:]
    a, b = (json.loads((d / "summary.json").read_text()) for d in (out, tmp_path / "ref"))
    assert a["status"] == b["status"] == "completed" and _iterations(a) == _iterations(b)
    for rank in (0, 1):
        ua, ub = (np.load(d / f"checkpoint.rank{rank}-of-2.npz")["u"] for d in (out, tmp_path / "ref"))
        # not bit for bit: MUMPS on two ranks differs from run to run by about 3e-17 (uninterrupted runs too)
        assert np.abs(ua - ub).max() <= 1e-12 * np.abs(ub).max()


def test_auto_starts_one_rank_per_core(tmp_path):
    """Without ``--ranks`` a problem that ``auto`` hands to petsc-gamg (two blocks, 107,760 dofs) runs as one MPI
    rank per core of its thread budget (NUMBA_NUM_THREADS = 2: two, each with one numba thread), and says so."""
    from covcontact.parallel.launcher import cores_here

    text = (ROOT / "benchmarks" / "problems" / "two_blocks_5k.toml").read_text()
    for old, new in (("nx = 10, ny = 10, nz = 5", "nx = 32, ny = 32, nz = 15"),
                     ("nx = 11, ny = 11, nz = 5", "nx = 33, ny = 33, nz = 15"), ("count = 10", "count = 1"),
                     ("value = [0.0, 0.0, -0.05]", "value = [0.0, 0.0, -0.01]")):
        assert old in text
        text = text.replace(old, new)
    path = tmp_path / "big.toml"
    path.write_text(text)
    env = dict(os.environ, NUMBA_NUM_THREADS="2")
    cmd = [sys.executable, "-m", "covcontact.cli", "run", str(path), "--out", str(tmp_path / "o")]
    proc = subprocess.run(cmd, check=False, capture_output=True, text=True, timeout=300, env=env)
    assert proc.returncode == 0, proc.stderr[-3000:]
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    ranks = min(2, cores_here())
    assert summary["dofs"] == 107_760 and summary["linear_solver"] == "petsc-gamg"
    assert summary.get("parallel", {}).get("ranks", 1) == ranks
    if ranks == 2:
        assert "linear solver: petsc-gamg (auto, 2 MPI ranks" in proc.stderr and "`--ranks 1`" in proc.stderr
        assert summary["parallel"]["numba_threads"] == 1


def test_launcher_of_another_mpi_refused(tmp_path):
    """A process that a launcher says is one of two ranks, but whose MPI sees one rank (an mpiexec of another MPI
    than mpi4py's, whose processes would each run the whole problem into one folder): one line, exit 2."""
    env = dict(os.environ, MPI_LOCALNRANKS="2")  # what MPICH's launcher sets; this process's MPI is a singleton
    cmd = [sys.executable, "-m", "covcontact.cli", "run", str(TWO_BLOCKS), "--solver", "petsc", "--quiet",
           "--out", str(tmp_path / "o")]
    proc = subprocess.run(cmd, check=False, capture_output=True, text=True, timeout=120, env=env)
    assert proc.returncode == 2, proc.stderr[-2000:]
    assert proc.stderr.count("\n") == 1 and "another MPI than mpi4py's" in proc.stderr
    assert not (tmp_path / "o" / "summary.json").exists()


def test_serial_solver_refused_under_ranks(tmp_path):
    """A solver that runs in one process is refused with one line and exit 2, by ``--ranks`` before it starts
    mpiexec, and by the ranks themselves under ``mpiexec`` (instead of two serial runs writing one folder)."""
    proc = _ranks(TWO_BLOCKS, tmp_path / "a", "--solver", "superlu")
    assert proc.returncode == 2 and "runs in one process" in proc.stderr
    assert proc.stderr.count("covcontact: error") == 1 and not (tmp_path / "a").exists()
    proc = _mpiexec_proc(TWO_BLOCKS, tmp_path / "b", "superlu")
    assert proc.returncode == 2 and "runs in one process" in proc.stderr and not (tmp_path / "b").exists()


def test_two_ranks_fail_together(tmp_path):
    """A step that cannot converge: the same cutbacks and exit code 1 as the serial run, no hang."""
    text = TWO_BLOCKS.read_text() + "\n[solver]\nmax_iterations = 2\nmax_cutbacks = 1\n"
    path = tmp_path / "two_blocks_failing.toml"
    path.write_text(text)
    ref = _serial(path, tmp_path / "ref")
    assert ref.exit_code == 1
    assert _mpiexec(path, tmp_path / "mpi", "petsc") == 1
    summary = json.loads((tmp_path / "mpi" / "summary.json").read_text())
    assert not summary["converged"]
    assert [s["cutbacks"] for s in summary["steps"]] == [s["cutbacks"] for s in ref.summary["steps"]]
    assert _iterations(summary) == _iterations(ref.summary)


STAGED = """
[problem]
name = "staged"
[[bodies]]
name = "block"
material = { model = "neo-hooke", E = 1000.0, nu = 0.3 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 1.0, nx = 3, ny = 3, nz = 4 }
[[rigid]]
name = "plate"
shape = "plane"
point = [0.0, 0.0, 1.0]
normal = [0.0, 0.0, -1.0]
motion = { translation = [0.0, 0.0, -0.02] }
[[contact]]
name = "touch"
slave = "block.zmax"
master = "plate"
penalty = 1.0e5
[[dirichlet]]
set = "block.zmin"
components = "z"
[[dirichlet]]
set = "block.ymin"
components = "y"
[[dirichlet]]
name = "side"
set = "block.xmin"
components = "x"
[[dirichlet]]
name = "pull"
set = "block.xmax"
components = "x"
value = 0.01
[steps]
count = 2
[[stages]]
name = "release"
steps = { count = 2 }
release = ["pull"]
[[stages]]
name = "lift"
steps = { count = 2 }
motions = { plate = { translation = [0.0, 0.0, 0.05] } }
"""


def test_two_ranks_match_serial_across_stages(tmp_path):
    """Stages under mpiexec: a release (the freed dofs change the distributed elimination) and a rigid
    motion continuing from its pose; the same iterations and displacements as the serial run."""
    path = tmp_path / "staged.toml"
    path.write_text(STAGED)
    ref = _serial(path, tmp_path / "ref")
    assert ref.exit_code == 0
    assert _mpiexec(path, tmp_path / "mpi", "petsc") == 0
    summary = json.loads((tmp_path / "mpi" / "summary.json").read_text())
    assert [s["stage"] for s in summary["steps"]] == [s["stage"] for s in ref.summary["steps"]]
    assert _iterations(summary) == _iterations(ref.summary)
    assert summary["stages"] == ref.summary["stages"]
    u = _final_displacement(tmp_path / "mpi")
    u_ref = _final_displacement(tmp_path / "ref")
    assert np.abs(u - u_ref).max() <= 1e-8 * np.abs(u_ref).max()
