"""Automatic incrementation (docs/input.md, ``[steps]``): ``initial``, ``min``, ``max`` instead of ``count``;
the increment grows after easy steps, is cut back on failure and goes on with what converged, ends exactly at
the stage's end; summary.json reports it; a resumed run repeats the uninterrupted one."""

from __future__ import annotations

import itertools
import json
from pathlib import Path

import numpy as np
import pytest

from covcontact.cli import main
from covcontact.io.loader import load_problem
from covcontact.io.validate import InputError
from covcontact.solvers import run as run_module
from covcontact.solvers.newton import StepOutcome
from covcontact.solvers.procedure import AutomaticIncrements, FixedIncrements, Increment
from covcontact.solvers.signals import Interrupted

#: an elastic block pressed by a rigid plane, then the plane lifted off (STEPS, LIFT: the steps tables)
BLOCK = """
[problem]
name = "press"
stage = "press"
[[bodies]]
name = "block"
material = { model = "neo-hooke", E = 1000.0, nu = 0.3 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 1.0, nx = 2, ny = 2, nz = 2 }
[[rigid]]
name = "plate"
shape = "plane"
point = [0.0, 0.0, 1.0]
normal = [0.0, 0.0, -1.0]
motion = { translation = [0.0, 0.0, -0.2] }
[[contact]]
name = "touch"
slave = "block.zmax"
master = "plate"
penalty = 1.0e5
[[dirichlet]]
set = "block.zmin"
components = "z"
[[dirichlet]]
set = "block.xmin"
components = "x"
[[dirichlet]]
set = "block.ymin"
components = "y"
[steps]
STEPS
[[stages]]
name = "lift"
steps = LIFT
motions = { plate = { translation = [0.0, 0.0, 0.5] } }
"""


def _problem(tmp_path: Path, steps: str, lift: str = "{ count = 2 }", extra: str = "", name: str = "p.toml"):
    path = tmp_path / name
    path.write_text(BLOCK.replace("STEPS", steps).replace("LIFT", lift) + extra)
    return path


def _inc(success=True, cutbacks=0, iterations=3) -> Increment:
    return Increment(1, 0.0, 0.1, success, [StepOutcome(converged=success, iterations=iterations)], cutbacks, "",
                     None)


def test_control_grows_shrinks_and_ends_exactly():
    c = AutomaticIncrements(0.1, 0.01, 0.4, 1.0)
    assert c.target(0.0) == pytest.approx(0.1)
    c.record(_inc(iterations=3), [(0.0, 0.1)])
    assert c.increment == pytest.approx(0.1)  # one easy step is not enough
    c.record(_inc(iterations=3), [(0.1, 0.2)])
    assert c.increment == pytest.approx(0.15)  # two in a row: grown by 1.5
    for _ in range(10):
        c.record(_inc(iterations=2), [(0.0, 0.1)])
    assert c.increment == pytest.approx(0.4)  # never above max
    c.record(_inc(iterations=20), [(0.0, 0.1)])
    assert c.increment == pytest.approx(0.3)  # a hard step: shrunk by 0.75
    c.record(_inc(cutbacks=2), [(0.5, 0.55), (0.55, 0.575)])
    assert c.increment == pytest.approx(0.025)  # after cutbacks: what finally converged
    c.record(_inc(cutbacks=5), [(0.5, 0.501)])
    assert c.increment == pytest.approx(0.01)  # never below min
    c.increment = 0.3
    assert c.target(0.6) == pytest.approx(0.9)
    assert c.target(0.75) == 1.0  # the remainder (0.25) is not below min: taken as the increment's rest
    assert c.target(0.995) == 1.0  # a remainder below min goes with this step
    assert c.target(1.0) is None
    state = c.state()
    d = AutomaticIncrements(0.1, 0.01, 0.4, 1.0)
    d.restore(state)
    assert d.state() == state
    f = FixedIncrements((0.25, 0.5, 1.0))
    assert [f.target(x) for x in (0.0, 0.25, 0.5 - 1e-15, 1.0)] == [0.25, 0.5, 1.0, None]


def test_control_shrinks_when_the_active_set_moves_a_lot():
    """A step of 6-12 iterations (neither easy nor hard) in which more than a quarter of the contact nodes
    (and more than 8) opened or closed shrinks the next increment; a small change, a few nodes, or an easy
    step (a face touching at once) does not."""
    c = AutomaticIncrements(0.1, 0.01, 0.4, 1.0)
    for its, changed, active, expect in ((8, 20, 40, 0.075), (8, 5, 40, 0.075), (8, 6, 10, 0.075),
                                         (8, 12, 40, 0.05625), (3, 40, 40, 0.05625)):
        inc = _inc(iterations=its)
        inc.opened_closed, inc.active = changed, active
        c.record(inc, [(0.0, 0.1)])
        assert c.increment == pytest.approx(expect), (its, changed, active)
    assert c.easy == 1  # the easy step counted towards growth
    inc = _inc(iterations=8)
    inc.plastic_changed, inc.yielding = 40, 60  # two thirds of the plastic zone moved (more than half)
    c.record(inc, [(0.0, 0.1)])
    assert c.increment == pytest.approx(0.05625 * 0.75) and c.easy == 0


def test_run_with_automatic_increments(tmp_path):
    """The press grows its increment from 0.05 (the elastic block converges in two iterations a step: every two
    steps by 1.5) and ends exactly at 1; the lift stage (initial 1.0) is one step; every step reports its increment, which
    adds up to the stage's end; the contact force at the end of the press equals the fixed-step run's."""
    auto = load_problem(_problem(tmp_path, "initial = 0.05\nmin = 0.001\nmax = 0.4", "{ initial = 1.0 }"))
    res = auto.run(out=tmp_path / "auto")
    assert res.exit_code == 0
    steps = res.summary["steps"]
    press = [s for s in steps if s["stage"] == "press"]
    incs = [s["increment"] for s in press]
    assert incs[0] == pytest.approx(0.05) and max(incs) > 3 * incs[0]
    assert all(b >= a - 1e-12 for a, b in itertools.pairwise(incs[:-1]))  # grows (the last one may be the rest)
    assert press[-1]["load_factor"] == 1.0 and sum(incs) == pytest.approx(1.0, abs=1e-12)
    assert len(press) < 10  # fewer steps than the 20 of a fixed 0.05
    lift = [s for s in steps if s["stage"] == "lift"]
    assert len(lift) == 1 and lift[0]["load_factor"] == 1.0 and lift[0]["increment"] == 1.0
    fixed = load_problem(_problem(tmp_path, "count = 4", name="fixed.toml")).run(out=tmp_path / "fixed")
    ref = [s for s in fixed.summary["steps"] if s["stage"] == "press"][-1]
    np.testing.assert_allclose(press[-1]["contact_force"], ref["contact_force"], rtol=1e-5)  # Newton's tolerance
    assert "increment" not in ref  # fixed steps keep their records as they were


def test_cutback_goes_on_with_the_increment_that_converged(tmp_path):
    """Lifting the plate off a block pressed by 40 % in one increment, with four Newton iterations allowed,
    fails; the step ends at the cut increment that converged and the stage goes on from there with that
    increment to exactly 1; with min above it the stage fails (exit 1, the converged steps kept)."""
    text = BLOCK.replace("translation = [0.0, 0.0, -0.2]", "translation = [0.0, 0.0, -0.4]")
    solver = "\n[solver]\nmax_iterations = 4\nmax_cutbacks = 20\n"
    for name, lift in (("cut", "{ initial = 1.0, min = 0.001 }"), ("min", "{ initial = 1.0, min = 0.9 }")):
        path = tmp_path / f"{name}.toml"
        path.write_text(text.replace("STEPS", "initial = 1.0").replace("LIFT", lift) + solver)
        res = load_problem(path).run(out=tmp_path / name)
        lifts = [s for s in res.summary["steps"] if s["stage"] == "lift"]
        if name == "cut":
            assert res.exit_code == 0, res.summary["steps"][-1]
            assert lifts[0]["cutbacks"] >= 1 and lifts[0]["increment"] < 1.0
            assert lifts[0]["load_factor"] == pytest.approx(lifts[0]["increment"])
            assert lifts[1]["increment"] == pytest.approx(lifts[0]["increment"])  # goes on with what converged
            assert lifts[-1]["load_factor"] == 1.0 and len(lifts) >= 3
        else:
            assert res.exit_code == 1 and res.summary["status"] == "failed"
            assert res.summary["steps"][0]["converged"] and not lifts[-1]["converged"]


def test_resume_with_automatic_increments_is_exact(tmp_path, monkeypatch):
    problem = load_problem(_problem(tmp_path, "initial = 0.05\nmin = 0.001\nmax = 0.4", "{ initial = 0.3 }"))
    ref = problem.run(out=tmp_path / "ref")
    advance = run_module.QuasiStatic.advance
    calls = {"n": 0}

    def stopping(self, *args, **kwargs):
        calls["n"] += 1
        if calls["n"] == 5:
            raise Interrupted(15)
        return advance(self, *args, **kwargs)

    monkeypatch.setattr(run_module.QuasiStatic, "advance", stopping)
    stopped = problem.run(out=tmp_path / "cut")
    assert stopped.exit_code == 143 and len(stopped.summary["steps"]) == 4
    monkeypatch.setattr(run_module.QuasiStatic, "advance", advance)
    resumed = problem.run(out=tmp_path / "cut", resume=True)
    assert resumed.exit_code == 0
    a = json.loads((tmp_path / "ref" / "summary.json").read_text())["steps"]
    b = json.loads((tmp_path / "cut" / "summary.json").read_text())["steps"]
    keys = ("step", "load_factor", "increment", "iterations", "residual_norms", "contact_force")
    assert [[s[k] for k in keys] for s in a] == [[s[k] for k in keys] for s in b]
    np.testing.assert_array_equal(ref.u, resumed.u)


def test_output_at_ends_increments_there_and_writes_them(tmp_path):
    """output_at: the automatic increments end exactly at each listed load factor and those steps are written
    (with [output] every = 1000 only they, the start and the stage ends); with fixed steps an output_at that is
    a step's end is written, one that is not is an input error."""
    c = AutomaticIncrements(0.3, 0.01, 0.4, 1.0, (0.45, 0.5))
    assert c.target(0.0) == pytest.approx(0.3)
    assert c.target(0.3) == 0.45 and c.target(0.45) == 0.5  # cut to the marks
    assert c.target(0.444) == 0.45  # a remainder below min goes with this step
    assert c.is_mark(0.45) and not c.is_mark(0.46)
    out = "\n[output]\nevery = 1000\n"
    path = _problem(tmp_path, "initial = 0.3\nmin = 0.001\nmax = 0.4\noutput_at = [0.45, 0.5]", extra=out)
    res = load_problem(path).run(out=tmp_path / "auto")
    assert res.exit_code == 0
    press = [s for s in res.summary["steps"] if s["stage"] == "press"]
    lams = [s["load_factor"] for s in press]
    assert 0.45 in lams and 0.5 in lams and lams[-1] == 1.0
    written = sorted(int(f.stem.split("_")[1]) for f in (tmp_path / "auto").glob("step_*.vtu"))
    marks = [s["step"] for s in press if s["load_factor"] in (0.45, 0.5)]
    ends = [press[-1]["step"], res.summary["steps"][-1]["step"]]
    assert written == sorted({0, *marks, *ends})
    fixed = _problem(tmp_path, "count = 4\noutput_at = [0.5]", extra=out, name="fixed.toml")
    res = load_problem(fixed).run(out=tmp_path / "fixed")
    written = sorted(int(f.stem.split("_")[1]) for f in (tmp_path / "fixed").glob("step_*.vtu"))
    assert written == [0, 2, 4, 6]
    with pytest.raises(InputError, match="steps.output_at: 0.3 is not the end of a step"):
        load_problem(_problem(tmp_path, "count = 4\noutput_at = [0.3]", name="bad.toml"))
    with pytest.raises(InputError, match="steps.output_at: must be a strictly increasing"):
        load_problem(_problem(tmp_path, "initial = 0.1\noutput_at = [0.5, 0.2]", name="bad2.toml"))


@pytest.mark.parametrize("steps, message", [
    ("initial = 0.1\nmin = 0.5\nmax = 0.2", "steps.min: min = 0.5 is above max = 0.2"),
    ("initial = 0.1\ncount = 3", "give either count or automatic increments"),
    ("initial = 0.5\nmax = 0.2", "steps.initial: must lie between min"),
    ("min = 0.01", "steps.initial: missing required key"),
    ("initial = 0.1\nmax = 2.0", "steps.max: must not exceed the stage's final load factor 1"),
])
def test_bad_increments(tmp_path, steps, message):
    with pytest.raises(InputError) as err:
        load_problem(_problem(tmp_path, steps))
    assert message in str(err.value) and "\n" not in str(err.value), str(err.value)


def test_check_tangent_inside_an_automatic_stage(tmp_path, capsys):
    path = _problem(tmp_path, "initial = 0.05\nmin = 0.001\nmax = 0.4")
    code = main(["check-tangent", str(path), "--stage", "press", "--step", "3"])
    out = capsys.readouterr().out
    assert code == 0 and out.splitlines()[1].startswith("PASS"), out
    assert "step 3 (stage 'press', load factor 0.175)" in out  # 0.05 + 0.05 + 0.075: grown after two easy steps


def test_quiet_run_still_says_why_it_failed(tmp_path, capsys):
    """--quiet silences the progress lines, never the reason a run failed (exit 1)."""
    text = BLOCK.replace("translation = [0.0, 0.0, -0.2]", "translation = [0.0, 0.0, -0.4]")
    path = tmp_path / "fail.toml"
    path.write_text(text.replace("STEPS", "initial = 1.0").replace("LIFT", "{ initial = 1.0, min = 0.9 }")
                    + "\n[solver]\nmax_iterations = 4\n")
    code = main(["run", str(path), "--quiet", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert code == 1
    lines = [ln for ln in err.splitlines() if "failed after" in ln]
    assert len(lines) == 1 and lines[0].startswith("step 2 (load factor 1) failed after")
    assert "step    1" not in err  # no progress lines
