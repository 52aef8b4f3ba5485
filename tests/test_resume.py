"""Checkpoints, --resume and signals, through the command line in subprocesses.

A run stopped by SIGTERM half-way and resumed must give what a run that was never stopped gives: the same
Newton iterations in every step and the same final displacements, bit for bit;
with friction and a rigid path (ironing), the augmented Lagrangian, solid-shells, petsc-gamg, PETSc's MUMPS (the
distributed model on one process) and two deformable blocks. Checkpoints of another or a changed
problem, damaged or missing ones are refused with exit code 2 and one line.
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"


def _variant(src: str, tmp: Path, name: str, subs: list[tuple[str, str]]) -> Path:
    text = (EXAMPLES / src).read_text()
    for pat, rep in subs:
        text, n = re.subn(pat, rep, text, count=1, flags=re.S)
        assert n == 1, f"{src}: pattern {pat!r} not found"
    path = tmp / f"{name}.toml"
    path.write_text(text)
    return path


def _steps(n: int, final: float = 1.0) -> str:
    return "[steps]\nfactors = [" + ", ".join(f"{final * (k + 1) / n:.10g}" for k in range(n)) + "]\n"


def ironing(tmp: Path) -> Path:
    """The ironing set-up on a coarse slab: press to 0.2, slide to 0.6 (friction, rigid path)."""
    press = [0.2 * (k + 1) / 4 for k in range(4)]
    slide = [0.2 + 0.3 * (k + 1) / 8 for k in range(8)]
    factors = ", ".join(f"{f:.10g}" for f in press + slide)
    return _variant("verification/ironing.toml", tmp, "ironing", [
        (r"nx = 18, ny = 2, nz = 6", "nx = 9, ny = 1, nz = 3"),
        (r"\[steps\]\nfactors = \[[^\]]*\]", f"[steps]\nfactors = [{factors}]")])


def ironing_extrapolated(tmp: Path) -> Path:
    """Ironing with the extrapolating predictor: its memory of the last increment is in the checkpoint."""
    path = ironing(tmp)
    text = path.read_text()
    text = text.replace("[solver]\n", "[solver]\npredictor = \"extrapolate\"\n", 1) if "[solver]" in text \
        else text + '\n[solver]\npredictor = "extrapolate"\n'
    out = tmp / "ironing_extrapolated.toml"
    out.write_text(text)
    return out


def augmented(tmp: Path) -> Path:
    return _variant("contact/block_on_plane_augmented.toml", tmp, "augmented",
                    [(r"\[steps\][^\[]*", _steps(12) + "\n")])


def shells(tmp: Path) -> Path:
    """The paper's shell over the rigid sphere (solid-shells), the first 10 of its 100 load steps."""
    return _variant("paper/sphere_q4.toml", tmp, "shells", [(r"\[steps\][^\[]*", _steps(10, 0.1) + "\n"),
                                                             (r"every = 10\npictures = true", "vtu = false")])


def gamg(tmp: Path) -> Path:
    """Two deformable blocks with petsc-gamg: the distributed model on one process (what ``linear = "auto"``
    picks for large solid problems), its AMG solves inexact (CG to Newton's forcing term)."""
    path = tmp / "gamg.toml"
    path.write_text((EXAMPLES / "contact" / "two_blocks.toml").read_text() + '\n[solver]\nlinear = "petsc-gamg"\n')
    return path


def mumps(tmp: Path) -> Path:
    """Two deformable blocks with PETSc's MUMPS: the distributed model on one process, whose matrix keeps the
    contact entries met so far; the checkpoint keeps them, so the resumed run factorises the same structure."""
    path = tmp / "mumps.toml"
    path.write_text((EXAMPLES / "contact" / "two_blocks.toml").read_text() + '\n[solver]\nlinear = "petsc"\n')
    return path


def two_blocks(tmp: Path) -> Path:
    """Two deformable blocks (mesh-facet master), the serial direct solver: the contact couplings met so far
    are part of the checkpoint, so the resumed run's matrices have the uninterrupted run's structure."""
    path = tmp / "two_blocks.toml"
    path.write_text((EXAMPLES / "contact" / "two_blocks.toml").read_text())
    return path


def sts_friction(tmp: Path) -> Path:
    """Two deformable blocks, segment-to-surface with Coulomb friction: pressed, then dragged across in 12 steps;
    the friction history lives at the slave facets' Gauss points."""
    text = (EXAMPLES / "contact" / "two_blocks.toml").read_text()
    text = text.replace('weighting = "area"\n', 'type = "sts"\nfriction = 0.2\n', 1)
    text = text.replace("components = \"xyz\"\nvalue = [0.0, 0.0, -0.02]", "components = \"xyz\"\nvalue = [0.06, 0.0, -0.02]")
    text = text.replace("[steps]\ncount = 2", _steps(12))
    path = tmp / "sts_friction.toml"
    path.write_text(text)
    return path


def self_friction(tmp: Path) -> Path:
    """The same drag with the two blocks' faces merged into one self-contact surface (both sides slaves)."""
    text = sts_friction(tmp).read_text().replace('slave = "punch.zmin"\nmaster = "base.zmax"\n',
                                                 'self = ["punch.zmin", "base.zmax"]\n')
    path = tmp / "self_friction.toml"
    path.write_text(text)
    return path


def two_materials(tmp: Path) -> Path:
    """The two blocks with the base in two materials by element set: an elastic lower layer and a J2 upper layer
    that yields under the punch (the composite body's history)."""
    text = (EXAMPLES / "contact" / "two_blocks.toml").read_text()
    base = 'mesh = { generator = "block", lx = 2.0, ly = 2.0, lz = 0.5, nx = 4, ny = 4, nz = 2, origin = [-1.0, -1.0, -0.5] }\n'
    assert base in text
    text = text.replace(base, base + 'materials = { top = { model = "j2", E = 1000.0, nu = 0.3, yield_stress = 5.0, '
                        'hardening = { law = "linear", modulus = 100.0 } } }\n'
                        '[bodies.cells]\ntop = { box = [[-2.0, -2.0, -0.25], [2.0, 2.0, 0.1]] }\n', 1)
    text = text.replace("value = [0.0, 0.0, -0.02]", "value = [0.0, 0.0, -0.04]").replace("[steps]\ncount = 2",
                                                                                         _steps(12))
    path = tmp / "two_materials.toml"
    path.write_text(text)
    return path


def mixed(tmp: Path) -> Path:
    """A Gmsh block of bricks and wedges (tests/data/mixed_block.msh) pressed by a rigid plate, the wedges in J2
    (history of two cell types side by side), the bricks elastic."""
    mesh = Path(__file__).parent / "data" / "mixed_block.msh"
    J2_HARDENING = '{ law = "linear", modulus = 10.0 }'  # noqa: N806
    text = f"""
[problem]
name = "mixed"
[[bodies]]
name = "block"
mesh = {{ file = "{mesh}" }}
material = {{ model = "neo-hooke", E = 100.0, nu = 0.3 }}
materials = {{ wedges = {{ model = "j2", E = 100.0, nu = 0.3, yield_stress = 1.0, hardening = {J2_HARDENING} }} }}
[bodies.cells]
wedges = {{ box = [[1.0, -1.0, -1.0], [3.0, 2.0, 2.0]] }}
[[rigid]]
name = "plate"
shape = "plane"
point = [0.0, 0.0, 1.0]
normal = [0.0, 0.0, -1.0]
motion = {{ translation = [0.0, 0.0, -0.05] }}
[[contact]]
slave = "block.zmax"
master = "plate"
penalty = 1.0e4
[[dirichlet]]
set = "block.zmin"
components = "xyz"
{_steps(10)}"""
    path = tmp / "mixed.toml"
    path.write_text(text)
    return path


def dynamic(tmp: Path) -> Path:
    """A static preload, then a dynamic stage: the bar of the impact test pushed against a block by its end, then
    let go (the kinematic state u, v, a and the energy account are part of the committed state)."""
    text = """
[problem]
name = "dynamic-resume"
[[bodies]]
name = "bar"
material = { model = "svk", E = 1.0, nu = 0.0, density = 1.0 }
mesh = { generator = "block", lx = 1.0, ly = 0.1, lz = 0.1, nx = 20, ny = 1, nz = 1 }
[[rigid]]
name = "wall"
shape = "plane"
point = [1.0, 0.0, 0.0]
normal = [-1.0, 0.0, 0.0]
[[contact]]
slave = "bar.xmax"
master = "wall"
penalty = 1.0e4
weighting = "area"
[[dirichlet]]
name = "push"
set = "bar.xmin"
components = "x"
value = 0.002
[[dirichlet]]
set = "bar.ymin"
components = "y"
[[dirichlet]]
set = "bar.zmin"
components = "z"
[steps]
count = 2
[[stages]]
name = "let-go"
release = ["push"]
procedure = "dynamic"
dt = 0.05
t_end = 1.2
method = "generalized-alpha"
rho_inf = 0.8
mass = "redistributed"
"""
    path = tmp / "dynamic.toml"
    path.write_text(text)
    return path


def dynamic_auto(tmp: Path) -> Path:
    """The dynamic maker's run with automatic time steps (their control's state is part of the checkpoint)."""
    path = tmp / "dynamic_auto.toml"
    path.write_text(dynamic(tmp).read_text().replace("dt = 0.05", "dt = 0.05\ndt_min = 0.005\ndt_max = 0.2"))
    return path


def _run(problem: Path, out: Path, *extra: str, wait=None) -> subprocess.CompletedProcess:
    cmd = [sys.executable, "-m", "covcontact.cli", "run", str(problem), "--out", str(out), *extra]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=900)


def _run_and_stop(problem: Path, out: Path, after: int, sig=signal.SIGTERM):
    """Start a run, send ``sig`` once ``after`` steps are in summary.json; (exit code, stderr)."""
    cmd = [sys.executable, "-m", "covcontact.cli", "run", str(problem), "--out", str(out)]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    summary = out / "summary.json"
    t0 = time.monotonic()
    while proc.poll() is None and time.monotonic() - t0 < 600:
        try:
            if len(json.loads(summary.read_text())["steps"]) >= after:
                break
        except (OSError, ValueError):
            pass
        time.sleep(0.01)
    assert proc.poll() is None, "the run ended before it could be stopped"
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=600)
    return proc.returncode, err


def _final_u(out: Path) -> np.ndarray:
    with np.load(out / "checkpoint.npz") as data:
        return data["u"]


def _summary(out: Path) -> dict:
    return json.loads((out / "summary.json").read_text())


def _has_solver(name: str) -> bool:
    from covcontact.solvers.linear import available

    return name in available()


def _has_gamg() -> bool:
    return _has_solver("petsc-gamg")


@pytest.mark.parametrize("make", [ironing, ironing_extrapolated, augmented, shells, gamg, mumps, two_blocks,
                                  sts_friction, self_friction, two_materials, mixed, dynamic, dynamic_auto],
                         ids=["ironing", "ironing-extrapolate", "augmented", "solid-shells", "petsc-gamg",
                              "petsc-mumps", "two-blocks", "sts-friction", "self-friction", "two-materials", "mixed", "dynamic",
                              "dynamic-auto"])
def test_stopped_and_resumed_equals_uninterrupted(tmp_path, make):
    if make is gamg and not _has_gamg():
        pytest.skip("petsc4py not installed (the `mpi` extra)")
    if make is mumps and not _has_solver("petsc"):
        pytest.skip("PETSc with MUMPS not installed (the `mpi` extra)")
    problem = make(tmp_path)
    ref = _run(problem, tmp_path / "ref")
    assert ref.returncode == 0, ref.stderr
    n = len(_summary(tmp_path / "ref")["steps"])
    out = tmp_path / "stopped"
    code, err = _run_and_stop(problem, out, after=n // 2)
    assert code == 143, err
    assert "Traceback" not in err
    stopped = _summary(out)
    assert stopped["status"] == "interrupted"
    assert 1 <= len(stopped["steps"]) < n
    res = _run(problem, out, "--resume")
    assert res.returncode == 0, res.stderr
    a, b = _summary(tmp_path / "ref"), _summary(out)
    assert b["status"] == "completed"
    assert [s["step"] for s in b["steps"]] == list(range(1, n + 1))
    assert [s["iterations"] for s in b["steps"]] == [s["iterations"] for s in a["steps"]]
    assert b["total_iterations"] == a["total_iterations"]
    if "uzawa_iterations" in a["steps"][0]:
        assert [s["uzawa_iterations"] for s in b["steps"]] == [s["uzawa_iterations"] for s in a["steps"]]
    ua, ub = _final_u(tmp_path / "ref"), _final_u(out)
    np.testing.assert_array_equal(ub, ua)  # bit for bit
    rows = (out / "convergence.csv").read_text().splitlines()
    ref_rows = (tmp_path / "ref" / "convergence.csv").read_text().splitlines()
    assert [r.split(",")[:2] for r in rows] == [r.split(",")[:2] for r in ref_rows]


def test_sigint_exit_code_and_status(tmp_path):
    problem = ironing(tmp_path)
    _run(problem, tmp_path / "warm")  # compiled kernels cached: the stop comes during the steps
    out = tmp_path / "int"
    code, err = _run_and_stop(problem, out, after=2, sig=signal.SIGINT)
    assert code == 130, err
    assert "Traceback" not in err
    s = _summary(out)
    assert s["status"] == "interrupted" and s["converged"] is False
    # every file on disk is valid: the summary parsed above, the checkpoint loads, the CSV is complete
    with np.load(out / "checkpoint.npz") as data:
        assert np.all(np.isfinite(data["u"]))
    rows = (out / "convergence.csv").read_text().splitlines()
    for row in rows[1:]:
        assert len(row.split(",")) == len(rows[0].split(",")) == 8


def _one_error_line(res: subprocess.CompletedProcess, *words: str) -> None:
    assert res.returncode == 2, res.stderr
    lines = [ln for ln in res.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1, res.stderr
    assert "Traceback" not in res.stderr
    for w in words:
        assert w in lines[0], lines[0]


def test_refused_checkpoints(tmp_path):
    problem = augmented(tmp_path)
    out = tmp_path / "out"
    assert _run(problem, out, "--quiet").returncode == 0
    # no checkpoint at all
    _one_error_line(_run(problem, tmp_path / "empty", "--resume", "--quiet"), "no checkpoint")
    # a changed problem (another penalty)
    changed = tmp_path / "changed.toml"
    text = problem.read_text()
    changed.write_text(re.sub(r"penalty = [^\n]+", "penalty = 123.0", text, count=1))
    assert changed.read_text() != text
    _one_error_line(_run(changed, out, "--resume", "--quiet"), "another problem")
    # another tangent case than the one the checkpoint was written with
    _one_error_line(_run(problem, out, "--resume", "--quiet", "--tangent", "d"), "another problem")
    # output options may change between a run and its resume
    quieter = tmp_path / "quieter.toml"
    quieter.write_text(text + "\n[output]\nvtu = false\ncheckpoint_every = 3\n")
    assert _run(quieter, out, "--resume", "--quiet").returncode == 0
    # a damaged checkpoint
    ck = out / "checkpoint.npz"
    ck.write_bytes(ck.read_bytes()[: os.path.getsize(ck) // 2])
    _one_error_line(_run(problem, out, "--resume", "--quiet"), "damaged")


def test_resume_of_a_completed_run_changes_nothing(tmp_path):
    problem = augmented(tmp_path)
    out = tmp_path / "out"
    assert _run(problem, out, "--quiet").returncode == 0
    before = _summary(out)
    res = _run(problem, out, "--resume", "--quiet")
    assert res.returncode == 0, res.stderr
    after = _summary(out)
    assert after["status"] == "completed"
    assert [s["iterations"] for s in after["steps"]] == [s["iterations"] for s in before["steps"]]


def test_checkpoint_every(tmp_path):
    problem = augmented(tmp_path)
    text = problem.read_text()
    assert "[output]" not in text
    problem.write_text(text + "\n[output]\ncheckpoint_every = 5\n")
    out = tmp_path / "out"
    code, _ = _run_and_stop(problem, out, after=7)
    assert code == 143
    with np.load(out / "checkpoint.npz") as data:
        assert int(data["step.step"]) % 5 == 0
    res = _run(problem, out, "--resume", "--quiet")
    assert res.returncode == 0, res.stderr
    assert [s["step"] for s in _summary(out)["steps"]] == list(range(1, 13))


def test_a_signal_inside_compiled_code_is_an_interruption():
    """A stop signal that lands while compiled code calls back into Python arrives as a SystemError whose cause is
    the Interrupted of the handler; the run treats it as the stop (exit code 143, resumable), not as a crash."""
    import signal

    from covcontact.solvers.run import _interruption
    from covcontact.solvers.signals import Interrupted

    stop = Interrupted(signal.SIGTERM)
    try:
        try:
            raise stop
        except Interrupted as inner:
            raise SystemError("returned a result with an exception set") from inner
    except SystemError as wrapped:
        assert _interruption(wrapped) is stop
    assert _interruption(SystemError("something else")) is None
    assert _interruption(stop).exit_code == 143
