"""Staged analyses (docs/theory.md section 13): each stage continues from the end of the one before.

Closed forms used here:
- a released Dirichlet condition hands its reaction r to a force (1 - lam) r: on an elastic body the
  reaction of the remaining supports falls linearly to zero and the body returns to its reference shape;
- uniaxial tension in logarithmic strain with linear hardening (as in
  tests/verification/test_plasticity_problems.py): loaded to eps = ln(1 + s), the equivalent plastic strain
  is alpha = eps - tau / E with tau = E (sigma_y0 + H eps) / (E + H); released, the elastic stretch goes
  back to 1 (the unloading is elastic), so the bar keeps the length exp(alpha) and the cross-section
  stretch exp(-alpha / 2) (isochoric plastic flow);
- a node set moved by a rigid motion lands where the motion puts it.
"""

from __future__ import annotations

import json
from pathlib import Path

import meshio
import numpy as np
import pytest

from covcontact.io.loader import load_problem
from covcontact.io.validate import InputError
from covcontact.solvers import run as run_module
from covcontact.solvers.signals import Interrupted

E, NU, SY0, H = 200.0, 0.3, 0.4, 2.0
S = 0.2  # end displacement of the unit-length bar

BAR = """
[problem]
name = "bar"
stage = "pull"

[[bodies]]
name = "bar"
formulation = "FORM"
material = MATERIAL
mesh = {{ generator = "block", lx = 1.0, ly = 1.0, lz = 1.0, nx = 2, ny = 1, nz = 1 }}

[[dirichlet]]
name = "left"
set = "bar.xmin"
components = "x"

[[dirichlet]]
set = "bar.ymin"
components = "y"

[[dirichlet]]
set = "bar.zmin"
components = "z"

[[dirichlet]]
name = "pull"
set = "bar.xmax"
components = "x"
value = {s}

[solver]
rtol = 1.0e-12

[steps]
count = 4
"""

J2 = f'{{ model = "j2", E = {E}, nu = {NU}, yield_stress = {SY0}, hardening = {{ law = "linear", modulus = {H} }} }}'
SVK = f'{{ model = "neo-hooke", E = {E}, nu = {NU} }}'


def _problem(tmp_path: Path, stages: str, material: str = J2, form: str = "fbar", s: float = S, name="p"):
    text = BAR.format(s=s).replace("MATERIAL", material).replace("FORM", form) + stages
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    return load_problem(path)


def _final_points(out: Path) -> tuple[np.ndarray, np.ndarray]:
    vtus = sorted(out.glob("step_*.vtu"))
    m = meshio.read(vtus[-1])
    return m.points + m.point_data["displacement"], m.points


RELEASE = """
[[stages]]
name = "release"
steps = { count = 3 }
release = ["pull"]
"""


def test_release_of_an_elastic_bar_ramps_the_reaction_to_zero(tmp_path):
    problem = _problem(tmp_path, RELEASE, SVK, "solid")
    res = problem.run(out=tmp_path / "out")
    assert res.exit_code == 0
    steps = res.summary["steps"]
    assert [s["stage"] for s in steps] == ["pull"] * 4 + ["release"] * 3
    r0 = steps[3]["reactions"]["bar.xmin"][0]
    assert r0 < 0.0
    for k, lam in zip((4, 5, 6), (1 / 3, 2 / 3, 1.0)):
        assert "bar.xmax" not in steps[k]["reactions"]  # released: no reaction any more
        assert steps[k]["reactions"]["bar.xmin"][0] == pytest.approx((1.0 - lam) * r0, rel=1e-9, abs=1e-11)
    x, X = _final_points(tmp_path / "out")
    np.testing.assert_allclose(x, X, atol=1e-10)  # elastic: back to the reference shape
    st = {s["name"]: s for s in res.summary["stages"]}
    assert st["pull"]["steps"] == 4 and st["release"]["steps"] == 3 and st["release"]["released"] == ["pull"]
    # output numbering continues across stages and the PVD times increase
    assert len(list((tmp_path / "out").glob("step_*.vtu"))) == 8
    times = [s["time"] for s in steps]
    assert times == sorted(times) and times[-1] == pytest.approx(2.0)


def test_springback_of_a_plastic_bar_keeps_the_plastic_stretch(tmp_path):
    problem = _problem(tmp_path, RELEASE)
    res = problem.run(out=tmp_path / "out")
    assert res.exit_code == 0
    eps = np.log(1.0 + S)
    tau = E * (SY0 + H * eps) / (E + H)
    alpha = eps - tau / E
    assert tau > SY0  # the bar yielded
    x, X = _final_points(tmp_path / "out")
    end = np.isclose(X[:, 0], 1.0)
    np.testing.assert_allclose(x[end, 0], np.exp(alpha), rtol=1e-8)
    top = np.isclose(X[:, 1], 1.0)
    np.testing.assert_allclose(x[top, 1], np.exp(-alpha / 2.0), rtol=1e-8)
    m = meshio.read(sorted((tmp_path / "out").glob("step_*.vtu"))[-1])
    eq = np.concatenate([np.ravel(a) for a in m.cell_data["equivalent_plastic_strain"]])
    np.testing.assert_allclose(eq, alpha, rtol=1e-8)
    # unloading is elastic: no dissipation in the release stage
    st = {s["name"]: s for s in res.summary["stages"]}
    assert st["pull"]["plastic_dissipation"] > 0.0
    assert abs(st["release"]["plastic_dissipation"]) < 1e-12 * st["pull"]["plastic_dissipation"]


def test_new_target_and_hold(tmp_path):
    stages = """
[[stages]]
name = "back"
steps = { count = 2 }
targets = { pull = 0.05 }

[[stages]]
name = "hold"
steps = { count = 1 }
"""
    problem = _problem(tmp_path, stages, SVK, "solid")
    res = problem.run(out=tmp_path / "out")
    assert res.exit_code == 0
    x, X = _final_points(tmp_path / "out")
    end = np.isclose(X[:, 0], 1.0)
    np.testing.assert_allclose(x[end, 0] - X[end, 0], 0.05, rtol=1e-12)
    # the hold stage changes nothing: the same reaction as at the end of "back"
    steps = res.summary["steps"]
    assert steps[-1]["stage"] == "hold" and steps[-1]["iterations"] <= 1
    np.testing.assert_allclose(steps[-1]["reactions"]["bar.xmin"], steps[-2]["reactions"]["bar.xmin"],
                               rtol=1e-9)


def test_motion_of_a_node_set_turns_the_clamp(tmp_path):
    """A clamped end turned by 30 degrees about the z axis through its centre, then translated."""
    path = tmp_path / "turn.toml"
    path.write_text("""
[problem]
name = "turn"
[[bodies]]
name = "bar"
material = { model = "neo-hooke", E = 100.0, nu = 0.3 }
mesh = { generator = "block", lx = 4.0, ly = 1.0, lz = 1.0, nx = 4, ny = 1, nz = 1 }
[[dirichlet]]
set = "bar.xmin"
[[dirichlet]]
name = "clamp"
set = "bar.xmax"
motion = { rotation = [0.0, 0.0, 0.5235987755982988], center = [4.0, 0.5, 0.5] }
[steps]
count = 3
[[stages]]
name = "shift"
steps = { count = 2 }
motions = { clamp = { translation = [0.0, 0.3, 0.0], rotation = [0.0, 0.0, -0.2], center = [4.0, 0.5, 0.5] } }
""")
    res = load_problem(path).run(out=tmp_path / "out")
    assert res.exit_code == 0
    x, X = _final_points(tmp_path / "out")
    end = np.isclose(X[:, 0], 4.0)
    c = np.array([4.0, 0.5, 0.5])

    def rot(t):
        return np.array([[np.cos(t), -np.sin(t), 0.0], [np.sin(t), np.cos(t), 0.0], [0.0, 0.0, 1.0]])

    first = c + (X[end] - c) @ rot(np.pi / 6).T  # stage 1: about the centre
    c2 = c  # the centre is a point of the clamp: it did not move in stage 1
    expected = c2 + (first - c2) @ rot(-0.2).T + np.array([0.0, 0.3, 0.0])
    np.testing.assert_allclose(x[end], expected, atol=1e-12)


PRESS = """
[problem]
name = "press"
[[bodies]]
name = "block"
material = { model = "svk", E = 1000.0, nu = 0.3 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 1.0, nx = 2, ny = 2, nz = 2 }
[[rigid]]
name = "plate"
shape = "plane"
point = [0.0, 0.0, 1.0]
normal = [0.0, 0.0, -1.0]
PLATE
[[contact]]
name = "touch"
slave = "block.zmax"
master = "plate"
penalty = 1.0e6
[[dirichlet]]
set = "block.zmin"
components = "z"
[[dirichlet]]
set = "block.xmin"
components = "x"
[[dirichlet]]
set = "block.ymin"
components = "y"
[solver]
rtol = 1.0e-12
[steps]
count = 2
"""

#: the block pressed by a plane moved 0.001 down, then its pair released over four steps
PRESS_RELEASE = PRESS.replace("PLATE", 'motion = { translation = [0.0, 0.0, -0.001] }') + """
[[stages]]
name = "unload"
steps = { count = 4 }
release = ["touch"]
"""


def test_rigid_body_motion_continues_and_pair_switches_off(tmp_path):
    """A plane presses a block, then lifts beyond it (stage 2), or the pair is switched off (stage 2')."""
    base = PRESS.replace("PLATE", "motion = { translation = [0.0, 0.0, -0.02] }")
    lift = base + """
[[stages]]
name = "lift"
steps = { count = 2 }
motions = { plate = { translation = [0.0, 0.0, 0.05] } }
"""
    off = base + """
[[stages]]
name = "off"
steps = { count = 1 }
contacts = { touch = false }
"""
    for name, text in (("lift", lift), ("off", off)):
        path = tmp_path / f"{name}.toml"
        path.write_text(text)
        res = load_problem(path).run(out=tmp_path / name)
        assert res.exit_code == 0, name
        steps = res.summary["steps"]
        assert steps[1]["reactions"]["block.zmin"][2] > 10.0  # pressed: about E * 0.02 * area = 20
        assert steps[-1]["active_contacts"] == 0
        if name == "lift":  # the plate 0.03 above the block's (unloaded) top
            assert steps[-1]["min_gap"] == pytest.approx(0.03, rel=1e-9)
        assert abs(steps[-1]["reactions"]["block.zmin"][2]) < 1e-9
        x, X = _final_points(tmp_path / name)
        np.testing.assert_allclose(x[:27], X[:27], atol=1e-9)  # the block (27 nodes) is unloaded
    # where the plate went: stage 1 moved it by -0.02, stage 2 by +0.05 from there
    m = meshio.read(sorted((tmp_path / "lift").glob("step_*.vtu"))[-1])
    plate = m.point_data["displacement"][27:]  # after the block's 27 nodes: the drawn plane
    assert len(plate) > 0
    np.testing.assert_allclose(plate, np.tile([0.0, 0.0, 0.03], (len(plate), 1)), atol=1e-14)


def test_released_pair_ramps_its_force_to_zero(tmp_path):
    """release = ["touch"]: the pair is off from the start of the stage and the force it carried is applied
    as a load ramped to zero, so the block unloads gradually (against an abrupt switch-off)."""
    path = tmp_path / "rel.toml"
    path.write_text(PRESS_RELEASE)
    res = load_problem(path).run(out=tmp_path / "rel")
    assert res.exit_code == 0
    steps = res.summary["steps"]
    r0 = steps[1]["reactions"]["block.zmin"][2]
    assert r0 > 0.5  # pressed: about E * 0.001 * area = 1
    for s in steps[2:]:
        assert s["active_contacts"] == 0
        lam = s["load_factor"]
        # the released force falls linearly; the block follows it (elastic, strain 1e-3: nearly linear)
        assert s["reactions"]["block.zmin"][2] == pytest.approx((1.0 - lam) * r0, rel=2e-3, abs=1e-9)
    assert steps[-1]["iterations"] <= 3
    x, X = _final_points(tmp_path / "rel")
    np.testing.assert_allclose(x[:27], X[:27], atol=1e-9)  # unloaded: back to the reference shape
    assert res.summary["stages"][1]["released"] == ["touch"]


def test_motion_takes_over_the_free_component_of_a_pressed_tool(tmp_path):
    """A plane pressed onto the block with a force (z free), then lifted by a stage motion: its z is held
    where the stage found it and moved by the translation; the contact opens and the block unloads."""
    text = PRESS.replace("PLATE", 'free = ["z"]\nforce = [0.0, 0.0, -1.0]') + """
[[stages]]
name = "lift"
steps = { count = 2 }
motions = { plate = { translation = [0.0, 0.0, 0.05] } }
"""
    path = tmp_path / "lift.toml"
    path.write_text(text)
    res = load_problem(path).run(out=tmp_path / "lift")
    assert res.exit_code == 0
    steps = res.summary["steps"]
    pressed = steps[1]["rigid_bodies"]["plate"]
    assert pressed["contact_force"][2] == pytest.approx(1.0, rel=1e-6)  # balances the applied force
    z1 = pressed["displacement"][2]
    assert z1 < 0.0
    for s, lam in zip(steps[2:], (0.5, 1.0)):
        assert s["rigid_bodies"]["plate"]["displacement"][2] == pytest.approx(z1 + 0.05 * lam, abs=1e-12)
    assert steps[-1]["active_contacts"] == 0
    assert abs(steps[-1]["reactions"]["block.zmin"][2]) < 1e-9


@pytest.mark.parametrize("stages, message", [
    ('[[stages]]\nname = "a"\ncontacts = { touch = false }\n[[stages]]\nname = "b"\nrelease = ["touch"]\n',
     "contact pair 'touch' is off at the start of this stage"),
    ('[[stages]]\nname = "a"\nrelease = ["touch"]\ncontacts = { touch = true }\n',
     "released and switched in 'contacts'"),
    ('[[stages]]\nname = "a"\nrelease = ["touch"]\n[[stages]]\nname = "b"\nrelease = ["touch"]\n',
     "contact pair 'touch' was released in stage 'a'"),
    ('[[stages]]\nname = "a"\nrelease = ["tuch"]\n', "contact pair named 'tuch'; did you mean 'touch'?"),
    ('[[stages]]\nname = "a"\nmotions = { plate = { rotation = [0.0, 0.1, 0.0] } }\n',
     "rigid body 'plate' has free components: a stage motion holds them and may only translate it"),
])
def test_bad_pair_release_and_free_body_motion(tmp_path, stages, message):
    path = tmp_path / "bad.toml"
    path.write_text(PRESS.replace("PLATE", 'free = ["z"]\nforce = [0.0, 0.0, -1.0]') + stages)
    with pytest.raises(InputError) as err:
        load_problem(path)
    assert message in str(err.value) and "\n" not in str(err.value), str(err.value)


def test_loads_take_new_targets_and_are_removed(tmp_path):
    path = tmp_path / "loads.toml"
    path.write_text("""
[problem]
name = "loads"
[[bodies]]
name = "bar"
material = { model = "neo-hooke", E = 1000.0, nu = 0.3 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 1.0, nx = 1, ny = 1, nz = 1 }
[[dirichlet]]
set = "bar.xmin"
[[force]]
name = "push"
set = "bar.xmax"
value = [0.0, 1.0, 0.0]
distribution = "total"
[[pressure]]
name = "p"
set = "bar.xmax"
value = 1.0
[steps]
count = 1
[[stages]]
name = "double"
targets = { push = [0.0, 2.0, 0.0], p = 3.0 }
[[stages]]
name = "remove"
remove = ["push", "p"]
""")
    res = load_problem(path).run(out=tmp_path / "out")
    assert res.exit_code == 0
    steps = res.summary["steps"]
    # the support carries the applied forces: y exactly, x by the dead pressure on the unit face
    np.testing.assert_allclose(steps[0]["reactions"]["bar.xmin"][:2], [1.0, -1.0], rtol=1e-9)
    np.testing.assert_allclose(steps[1]["reactions"]["bar.xmin"][:2], [3.0, -2.0], rtol=1e-9)
    np.testing.assert_allclose(steps[2]["reactions"]["bar.xmin"], 0.0, atol=1e-9)


def _stop_and_resume(problem, tmp_path: Path, monkeypatch, stop_at: int):
    """Run ``problem`` once to the end ("ref"), once stopped by a signal at the ``stop_at``-th load step
    ("cut"), then resume "cut"; returns (ref, stopped, resumed, ref summary, resumed summary)."""
    ref = problem.run(out=tmp_path / "ref")
    advance = run_module.Newton.advance
    calls = {"n": 0}

    def stopping(self, *args, **kwargs):
        calls["n"] += 1
        if calls["n"] == stop_at:
            raise Interrupted(15)
        return advance(self, *args, **kwargs)

    monkeypatch.setattr(run_module.Newton, "advance", stopping)
    stopped = problem.run(out=tmp_path / "cut")
    monkeypatch.setattr(run_module.Newton, "advance", advance)
    resumed = problem.run(out=tmp_path / "cut", resume=True)
    a = json.loads((tmp_path / "ref" / "summary.json").read_text())
    b = json.loads((tmp_path / "cut" / "summary.json").read_text())
    return ref, stopped, resumed, a, b


@pytest.mark.parametrize("stop_at", [5, 6])
def test_resume_across_stages_is_exact(tmp_path, monkeypatch, stop_at):
    """Stopped at the first step of the release stage (checkpoint: the end of the pull stage) or at its
    second (checkpoint inside the stage, with the released reactions in the state): resumed, the run
    ends exactly where the run that was never stopped ends."""
    ref, stopped, resumed, a, b = _stop_and_resume(_problem(tmp_path, RELEASE), tmp_path, monkeypatch, stop_at)
    assert stopped.exit_code == 143 and stopped.summary["status"] == "interrupted"
    assert resumed.exit_code == 0
    # the same steps from the same committed state; the direct solver's fresh analysis after the restart
    # may order its pivots differently, hence round-off, not bitwise equality
    np.testing.assert_allclose(resumed.u, ref.u, rtol=1e-10, atol=1e-14)
    assert [s["iterations"] for s in a["steps"]] == [s["iterations"] for s in b["steps"]]
    assert [s["stage"] for s in a["steps"]] == [s["stage"] for s in b["steps"]]
    assert a["stages"] == b["stages"]


@pytest.mark.parametrize("stages, message", [
    ('[[stages]]\nname = "a"\nrelease = ["nope"]\n', "no Dirichlet condition or contact pair named 'nope'"),
    ('[[stages]]\nname = "a"\nrelease = ["pull"]\n[[stages]]\nname = "b"\nrelease = ["pull"]\n',
     "'pull' was released in stage 'a'"),
    ('[[stages]]\nname = "a"\nrelease = ["pull", "pull"]\n', "names a condition twice"),
    ('[[stages]]\nname = "a"\nrelease = ["pull"]\n[[stages]]\nname = "b"\ntargets = { pull = 0.1 }\n',
     "'pull' was released in stage 'a'"),
    ('[[stages]]\nname = "a"\nrelease = ["pull"]\ntargets = { pull = 0.1 }\n', "released and given a target"),
    ('[[stages]]\nname = "a"\ntargets = { pul = 0.1 }\n', "no Dirichlet condition, load or equation named 'pul'"),
    ('[[stages]]\nname = "a"\nmotions = { pull = { translation = [1.0, 0.0, 0.0] } }\n',
     "no rigid body or Dirichlet condition with a motion named 'pull'"),
    ('[[stages]]\nname = "pull"\n', "duplicate stage name 'pull'"),
    ('[[stages]]\nname = "a"\ncontacts = { c = false }\n', "no contact pair named 'c'"),
    ('[[stages]]\nname = "a"\nrelase = ["pull"]\n', "unknown key"),
    ('[[stages]]\nname = "a"\ntargets = { pull = [0.1, 0.2] }\n', "must have 1 entries"),
])
def test_bad_stage_input(tmp_path, stages, message):
    with pytest.raises(InputError) as err:
        _problem(tmp_path, stages)
    assert message in str(err.value) and "\n" not in str(err.value)
    assert "p.toml" in str(err.value)


def test_value_and_motion_together_is_refused(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text("""
[problem]
name = "bad"
[[bodies]]
name = "bar"
material = { model = "neo-hooke", E = 100.0, nu = 0.3 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 1.0, nx = 1, ny = 1, nz = 1 }
[[dirichlet]]
set = "bar.xmin"
value = 0.1
motion = { translation = [0.1, 0.0, 0.0] }
""")
    with pytest.raises(InputError, match="either 'value' or 'motion'"):
        load_problem(path)


@pytest.mark.parametrize("stop_at", [3, 5])
def test_resume_inside_a_pair_release_is_exact(tmp_path, monkeypatch, stop_at):
    """A run stopped at the first or third step of a stage that releases a contact pair (the released
    contact forces are part of the committed state) resumes to the end of the run never stopped."""
    path = tmp_path / "rel.toml"
    path.write_text(PRESS_RELEASE)
    ref, stopped, resumed, a, b = _stop_and_resume(load_problem(path), tmp_path, monkeypatch, stop_at)
    assert stopped.exit_code == 143
    assert resumed.exit_code == 0
    np.testing.assert_allclose(resumed.u, ref.u, rtol=1e-10, atol=1e-14)
    assert [s["iterations"] for s in a["steps"]] == [s["iterations"] for s in b["steps"]]
    assert [s["reactions"]["block.zmin"][2] for s in a["steps"]] == pytest.approx(
        [s["reactions"]["block.zmin"][2] for s in b["steps"]], rel=1e-9, abs=1e-12)


def test_stage_changes_the_friction_coefficient(tmp_path):
    """A block pressed and dragged across a rigid floor while sliding: the tangential contact force is mu N with mu =
    0.3 in the first stage and mu = 0.1 from the stage that changes it on (the stick history carries over)."""
    from covcontact.io.loader import load_problem

    text = (Path(__file__).resolve().parents[1] / "examples" / "friction" / "block_sliding.toml").read_text()
    assert 'friction = 0.3\n' in text and "[steps]\ncount = 10" in text
    text = text.replace('friction = 0.3\n', 'friction = 0.3\nname = "slide"\n').replace(
        "[[dirichlet]]\n", '[[dirichlet]]\nname = "drag"\n', 1)
    text += ('\n[[stages]]\nname = "slippery"\nsteps = { count = 4 }\ntargets = { drag = [0.3, 0.0, -0.01] }\n'
             'friction = { slide = 0.1 }\n')
    path = tmp_path / "p.toml"
    path.write_text(text)
    res = load_problem(path).run(out=tmp_path / "o", quiet=True)
    assert res.exit_code == 0
    steps = res.summary["steps"]
    for s, mu in ((steps[9], 0.3), (steps[-1], 0.1)):
        fx, _, fz = s["contact_force"]
        assert abs(fx) == pytest.approx(mu * abs(fz), rel=5e-4)
    path.write_text(text.replace("friction = { slide = 0.1 }", "friction = { slid = 0.1 }"))
    with pytest.raises(InputError, match="no frictional contact pair named 'slid'; did you mean 'slide'"):
        load_problem(path)


LATE = """
[problem]
name = "late"
[[bodies]]
name = "bar"
element = "hex8"
material = { model = "svk", E = 100.0, nu = 0.0 }
mesh = { generator = "block", lx = 2.0, ly = 1.0, lz = 1.0, nx = 2, ny = 1, nz = 1 }
[[dirichlet]]
set = "bar.xmin"
components = "x"
[[dirichlet]]
set = "bar.ymin"
components = "y"
[[dirichlet]]
set = "bar.zmin"
components = "z"
[[force]]
name = "pull"
set = "bar.xmax"
value = [3.0, 0.0, 0.0]
distribution = "total"
[[dirichlet]]
name = "hold"
set = "bar.xmax"
components = "x"
value = VALUE
stage = "holding"
[steps]
count = 2
[[stages]]
name = "holding"
steps = { count = 2 }
remove = ["pull"]
"""


@pytest.mark.parametrize("value", ['"held"', "0.1"])
def test_condition_that_starts_in_a_later_stage(tmp_path, value):
    """A bar pulled by a force (uniaxial SVK, nu = 0: F / A = E l (l^2 - 1) / 2); in the next stage the force goes
    and a condition that starts there holds its end: "held" keeps the end where the force left it (the reaction
    takes the force over), a value moves it there from where it was."""
    path = tmp_path / "p.toml"
    path.write_text(LATE.replace("VALUE", value))
    res = load_problem(path).run(out=tmp_path / "o", quiet=True)
    assert res.exit_code == 0
    lam = np.roots([50.0, 0.0, -50.0, -3.0])
    lam = float(lam[np.isreal(lam) & (lam.real > 1)].real[0])
    steps = res.summary["steps"]
    u = meshio.read(sorted((tmp_path / "o").glob("step_*.vtu"))[-1]).point_data["displacement"]
    end = meshio.read(sorted((tmp_path / "o").glob("step_*.vtu"))[-1]).points[:, 0] > 2.0 - 1e-9
    if value == '"held"':
        assert steps[1]["reactions"].get("bar.xmax") is None
        np.testing.assert_allclose(u[end, 0], 2.0 * (lam - 1.0), rtol=1e-8)
        assert steps[-1]["reactions"]["bar.xmax"][0] == pytest.approx(3.0, rel=1e-8)  # the force, now the support's
    else:
        np.testing.assert_allclose(u[end, 0], 0.1, rtol=1e-12)
    path.write_text(LATE.replace("VALUE", value).replace('stage = "holding"', 'stage = "holdin"'))
    with pytest.raises(InputError, match="no later stage named 'holdin'; did you mean 'holding'"):
        load_problem(path)
