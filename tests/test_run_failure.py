"""Every way a run can end leaves summary.json saying so: a step that does not converge after its cutbacks (exit 1)
and an unexpected exception (exit 3, one line on stderr, the traceback in traceback.txt) both write
``"status": "failed"`` with the reason and the last converged step (docs/input.md, "Stopping and resuming a run")."""

import json
from pathlib import Path

from covcontact.cli import main

PROBLEM = """
[problem]
name = "tiny"

[[bodies]]
name = "cube"
element = "hex8"
material = { model = "svk", E = 100.0, nu = 0.3 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 1.0, nx = 1, ny = 1, nz = 1 }

[[dirichlet]]
set = "cube.zmin"
components = "xyz"

[[pressure]]
set = "cube.zmax"
value = 60.0

[steps]
factors = [0.02, 1.0]
"""


def _run(tmp_path: Path, capsys, text: str) -> tuple[int, str, dict]:
    path = tmp_path / "p.toml"
    path.write_text(text)
    code = main(["run", str(path), "--out", str(tmp_path / "o"), "--quiet"])
    err = capsys.readouterr().err
    return code, err, json.loads((tmp_path / "o" / "summary.json").read_text())


def test_a_step_that_does_not_converge_is_recorded(tmp_path, capsys):
    # the second step (pressure 60 on E = 100, 60 % strain) needs more than 4 iterations, and no cutback is allowed
    code, err, s = _run(tmp_path, capsys, PROBLEM + "\n[solver]\nmax_iterations = 4\nmax_cutbacks = 0\n")
    assert code == 1
    assert s["status"] == "failed" and s["converged"] is False
    assert s["last_converged"] == {"step": 1, "stage": "stage1", "load_factor": 0.02}
    assert s["failed_step"] == {"step": 2, "stage": "stage1", "load_factor": 1.0}
    assert s["reason"].startswith("step 2 (load factor 1) failed after")
    assert "no convergence in 4 iterations" in s["reason"]
    assert "error" not in s
    assert [st["converged"] for st in s["steps"]] == [True, False]
    assert "failed after" in err


def test_an_unexpected_exception_is_recorded(tmp_path, capsys, monkeypatch):
    """A bug in compiled code as numba reports it (a SystemError whose cause is the kernel's exception), raised in
    the second step's Newton iteration: exit 3, one line naming the kernel's exception, summary.json failed after
    step 1, the traceback beside it."""
    from covcontact.solvers.model import Model

    calls = {"n": 0}
    evaluate = Model.evaluate

    def failing(self, u, lam, *args, **kwargs):
        if lam > 0.5:  # the second step (load factor 1): its first evaluation fails
            calls["n"] += 1
            try:
                raise ZeroDivisionError("division by zero")
            except ZeroDivisionError as exc:
                raise SystemError("CPUDispatcher(<function kernel>) returned a result with an exception set") from exc
        return evaluate(self, u, lam, *args, **kwargs)

    monkeypatch.setattr(Model, "evaluate", failing)
    code, err, s = _run(tmp_path, capsys, PROBLEM)
    assert code == 3 and calls["n"] == 1
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("covcontact: internal error: ZeroDivisionError: division by zero at ")
    assert "Traceback" not in err and str(tmp_path / "o" / "traceback.txt") in lines[0]
    assert s["status"] == "failed" and s["converged"] is False
    assert s["last_converged"] == {"step": 1, "stage": "stage1", "load_factor": 0.02}
    assert s["error"]["type"] == "ZeroDivisionError" and s["error"]["message"] == "division by zero"
    assert s["error"]["where"].endswith("in failing") and s["error"]["traceback"] == "traceback.txt"
    assert s["reason"].startswith("ZeroDivisionError: division by zero (")
    assert [st["converged"] for st in s["steps"]] == [True]
    assert "timing" in s  # the run's end was recorded as for any other ending
    tb = (tmp_path / "o" / "traceback.txt").read_text()
    assert "ZeroDivisionError: division by zero" in tb and "SystemError" in tb


def test_an_exception_before_the_first_step_is_recorded(tmp_path, capsys, monkeypatch):
    """Even a failure in the run's set-up (its start warnings) leaves a summary that says failed, at step 0."""
    from covcontact.solvers.model import Model

    def broken(self, *args, **kwargs):
        raise KeyError("no such thing")

    monkeypatch.setattr(Model, "start_warnings", broken)
    code, err, s = _run(tmp_path, capsys, PROBLEM)
    assert code == 3 and len(err.strip().splitlines()) == 1
    assert "KeyError: 'no such thing' at " in err
    assert s["status"] == "failed" and s["last_converged"] == {"step": 0, "stage": "stage1", "load_factor": 0.0}
    assert s["error"]["type"] == "KeyError" and s["steps"] == []


def test_a_completed_run_has_no_failure_fields(tmp_path, capsys):
    (tmp_path / "o").mkdir()
    (tmp_path / "o" / "traceback.txt").write_text("of an earlier run")
    code, _, s = _run(tmp_path, capsys, PROBLEM.replace("value = 60.0", "value = 1.0"))
    assert code == 0 and s["status"] == "completed" and s["converged"] is True
    assert not {"reason", "last_converged", "failed_step", "error"} & set(s)
    assert not (tmp_path / "o" / "traceback.txt").exists()
