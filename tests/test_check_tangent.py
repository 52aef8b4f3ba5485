"""``covcontact check-tangent`` on plastic contact problems, single and staged (docs/input.md, "Checking the
tangent"): the step is reached as ``covcontact run`` reaches it, columns whose perturbation crosses a kink
(yielding, contact, stick/slip) are told from tangent errors, and the exact tangent passes at 1e-6 inside
every kind of stage."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from covcontact.cli import main
from covcontact.io.loader import load_problem
from covcontact.tangent_check import check_tangent, report_lines

TOL = 1e-6

#: the plate pressed by a rigid roller of the issue that asked for this check (F-bar, J2 with linear
#: hardening); "lift" raises the roller from where the first stage left it
ROLLER = """
[problem]
name = "roller-on-plate"
stage = "press"
[[bodies]]
name = "plate"
element = "hex8"
formulation = "FORMULATION"
material = { model = "j2", E = 70000.0, nu = 0.33, yield_stress = 150.0, hardening = { law = "linear", modulus = 1000.0 } }
mesh = { generator = "block", lx = 20.0, ly = 2.0, lz = 5.0, nx = 20, ny = 1, nz = 10, origin = [0.0, 0.0, -5.0] }
[[rigid]]
name = "roller"
shape = "cylinder"
center = [0.0, 0.0, 5.0]
axis = [0.0, 1.0, 0.0]
radius = 5.0
motion = { translation = [0.0, 0.0, -0.3] }
[[contact]]
name = "tool"
slave = "plate.zmax"
master = "roller"
penalty = 1.0e5
weighting = "area"
[[dirichlet]]
set = "plate.zmin"
components = "xyz"
[[dirichlet]]
set = "plate.xmin"
components = "x"
[[dirichlet]]
set = "plate.ymin"
components = "y"
[[dirichlet]]
set = "plate.ymax"
components = "y"
[steps]
count = 10
"""
LIFT = """
[[stages]]
name = "lift"
steps = { count = 5 }
motions = { roller = { translation = [0.0, 0.0, 1.0] } }
"""


def _write(tmp_path: Path, text: str, name: str = "p.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def _run_cli(args, capsys) -> tuple[int, str, str]:
    code = main([str(a) for a in args])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_kink_at_the_edge_of_the_plastic_zone_is_reported_not_failed(tmp_path):
    """Plain hex8, step 8: a Gauss point at the edge of the plastic zone lies within h = 2e-6 of the yield
    surface, so a backward difference unloads it; those columns are listed with the status that changed
    and judged at a smaller step, the verdict on all columns passes."""
    prob = load_problem(_write(tmp_path, ROLLER.replace("FORMULATION", "solid")))
    rep = check_tangent(prob, step=8, columns=None)
    assert rep["converged"] and rep["columns"] == rep["judged"]
    assert rep["relative_error"] <= TOL, rep["relative_error"]
    kinks = rep["kinks"]
    assert kinks, "the state has Gauss points within h of yielding: some column must cross the kink"
    for k in kinks:
        assert any("Gauss point" in c and "elastic" in c for c in k["changes"]), k
        assert k["judged_at"] is not None and k["judged_at"] < rep["h"][0] and k["error"] <= TOL, k
    # the columns that change no status agree at every step size, to O(h^2) centrally, O(h) one-sided
    rows = rep["by_step_size"]
    assert all(r["central"] <= TOL for r in rows)
    assert rows[1]["forward"] < 0.2 * rows[0]["forward"]
    text = "\n".join(report_lines(rep, TOL))
    assert "kinks: " in text and "yielding -> elastic" in text and text.splitlines()[1].startswith("PASS")


def test_staged_roller_every_stage_and_points_left_on_the_yield_surface(tmp_path, capsys):
    """The staged roller problem checked inside both stages (--step counted over the stages and --stage):
    PASS at 1e-6. In the lift stage the plate springs back at its first step, with reverse yielding at
    some Gauss points; the later steps do not move it, so those points stay exactly on the yield surface,
    where R has no derivative: a perturbation in any loading direction yields them at every step size. They
    are listed as kinks, not judged, and the one-sided difference on their elastic side agrees."""
    path = _write(tmp_path, ROLLER.replace("FORMULATION", "fbar") + LIFT)
    code, out, err = _run_cli(["check-tangent", path, "--step", "8"], capsys)
    assert code == 0 and out.splitlines()[1].startswith("PASS"), out + err
    assert "stage 'press', load factor 0.8" in out.splitlines()[0]
    code, out, err = _run_cli(["check-tangent", path, "--stage", "lift", "--step", "2", "--json",
                               tmp_path / "rep.json"], capsys)
    assert code == 0 and out.splitlines()[1].startswith("PASS"), out + err
    rep = json.loads((tmp_path / "rep.json").read_text())
    assert rep["step"] == 12 and rep["stage"] == "lift" and rep["load_factor"] == pytest.approx(0.4)
    at_kink = [k for k in rep["kinks"] if k["judged_at"] is None]
    assert at_kink, "Gauss points on the yield surface: some columns are at the kink at every step size"
    assert all(any("elastic -> yielding" in c for c in k["changes"]) for k in at_kink)
    one_sided = [k["one_sided"]["error"] for k in at_kink if "one_sided" in k]
    assert one_sided and max(one_sided) <= TOL
    assert "at the kink" in out
    # the same step counted over both stages
    code, out2, _ = _run_cli(["check-tangent", path, "--step", "12"], capsys)
    assert code == 0 and out2.splitlines()[0] == out.splitlines()[0]


#: a J2 block pressed by a rigid plane (PLATE: its motion or force), with a side support "side" and a
#: contact pair "touch" that later stages change
BLOCK = """
[problem]
name = "press"
stage = "press"
[[bodies]]
name = "block"
formulation = "fbar"
material = { model = "j2", E = 1000.0, nu = 0.3, yield_stress = 2.0, hardening = { law = "voce", sigma_inf = 3.0, delta = 20.0, modulus = 10.0 } }
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
penalty = 1.0e5
FRICTION
[[dirichlet]]
set = "block.zmin"
components = "z"
[[dirichlet]]
set = "block.xmin"
components = "x"
[[dirichlet]]
set = "block.ymin"
components = "y"
[[dirichlet]]
name = "side"
set = "block.xmax"
components = "x"
value = 0.0
[steps]
count = 3
"""
PRESSED = 'motion = { translation = [0.0, 0.0, -0.02] }'
FORCED = 'free = ["z"]\nforce = [0.0, 0.0, -4.0]'
STAGES = {
    "target": (PRESSED, 'targets = { side = -0.01 }'),
    "release": (PRESSED, 'release = ["side"]'),
    "pair-release": (PRESSED, 'release = ["touch"]'),
    "motion": (PRESSED, 'motions = { plate = { translation = [0.0, 0.0, 0.01] } }'),
    "parked": (FORCED, 'motions = { plate = { translation = [0.0, 0.0, 0.004] } }'),
    "switched-off": (FORCED, 'contacts = { touch = false }'),
}


def _block(plate: str, stage: str, friction: str = "") -> str:
    return (BLOCK.replace("PLATE", plate).replace("FRICTION", friction)
            + f'[[stages]]\nname = "later"\nsteps = {{ count = 3 }}\n{stage}\n')


@pytest.mark.parametrize("kind", sorted(STAGES))
def test_exact_tangent_inside_every_kind_of_stage(tmp_path, kind):
    """New targets, a support released with its reaction ramped, a pair released, a tool moved from its
    stage pose, a force-driven tool parked and moved, a pair switched off: the exact tangent at the last
    step of the first stage and at the first and last steps of the later one matches the residual's
    differences (the release ramps and held forces do not depend on u, so no stage adds a tangent term)."""
    plate, stage = STAGES[kind]
    prob = load_problem(_write(tmp_path, _block(plate, stage)))
    plastic = False
    for step in (3, 4, 6):
        rep = check_tangent(prob, step=step, columns=None)
        assert rep["converged"], rep.get("reason")
        assert rep["stage"] == ("press" if step == 3 else "later")
        assert rep["judged"] >= rep["columns"] - len([k for k in rep["kinks"] if k["judged_at"] is None])
        assert rep["judged"] > 0 and rep["relative_error"] <= TOL, (kind, step, rep["relative_error"])
        plastic = plastic or rep["zones"]["plastic"] > 0
    assert plastic  # the block yields: the check covers the plastic tangent


@pytest.mark.parametrize("stage", [STAGES["motion"][1], 'motions = { plate = { translation = [0.05, 0.0, 0.0] } }'],
                         ids=["lift", "slide"])
def test_frictional_contact_tangent_and_stick_slip(tmp_path, stage):
    """Coulomb friction (non-symmetric tangent) on the plastic block: the plate slides over it (slip) or lifts
    off; the exact tangent passes at 1e-6 where the friction status does not change under the perturbation."""
    from covcontact.tangent_check import reach, statuses

    prob = load_problem(_write(tmp_path, _block(PRESSED, stage, "friction = 0.3")))
    for step in (3, 5):
        rep = check_tangent(prob, step=step, columns=None)
        assert rep["converged"] and rep["judged"] > 0, rep.get("reason")
        assert rep["relative_error"] <= TOL, (step, rep["relative_error"])
    # the state the slide's step 5 checks slips (status 2) at its closed nodes: the slip tangent is covered
    reached = reach(prob, 5)
    friction = statuses(reached.model, reached.guess)["touch|friction"]
    assert (2 in friction) == (stage.startswith("motions = { plate = { translation = [0.05"))


def test_a_wrong_tangent_fails(tmp_path, monkeypatch):
    """The verdict can fail: a tangent off by 1e-4 (relative) is caught at every step size."""
    from covcontact.solvers.model import Model

    prob = load_problem(_write(tmp_path, _block(PRESSED, STAGES["motion"][1])))
    original = Model.evaluate

    def skewed(self, *args, **kwargs):
        R, K, trial = original(self, *args, **kwargs)
        if K is not None:
            K = K * (1.0 + 1e-4)
        return R, K, trial
    monkeypatch.setattr(Model, "evaluate", skewed)
    rep = check_tangent(prob, step=2, columns=20)
    assert rep["relative_error"] == pytest.approx(1e-4, rel=0.05)
    assert all(r["central"] > 5e-5 for r in rep["by_step_size"])
    assert report_lines(rep, TOL)[1].startswith("FAIL")


def test_cli_step_arguments_and_a_run_that_fails_before_the_step(tmp_path, capsys):
    path = _write(tmp_path, _block(PRESSED, STAGES["motion"][1]))
    code, _, err = _run_cli(["check-tangent", path, "--stage", "lift", "--step", "1"], capsys)
    assert code == 2 and "--stage: no stage named 'lift'" in err and "press, later" in err
    code, _, err = _run_cli(["check-tangent", path, "--stage", "later", "--step", "4"], capsys)
    assert code == 2 and "stage 'later' has steps 1 to 3" in err
    code, _, err = _run_cli(["check-tangent", path, "--step", "7"], capsys)
    assert code == 2 and "between 0 and 6" in err
    code, _, err = _run_cli(["check-tangent", path, "--columns", "some"], capsys)
    assert code == 2 and "--columns" in err
    # two Newton iterations and no cutback do not reach the plastic state: step 1 fails, the check says so
    bad = _write(tmp_path, _block(PRESSED, STAGES["motion"][1]).replace(
        "[steps]", "[solver]\nmax_cutbacks = 0\nmax_iterations = 2\n\n[steps]"), "bad.toml")
    code, out, err = _run_cli(["check-tangent", bad, "--step", "2"], capsys)
    assert code == 1 and "Traceback" not in err, err
    assert "not reached: step 1 did not converge" in out and "check-tangent: step 1 did not converge" in err


def test_columns_cover_the_contact_and_plastic_zones(tmp_path):
    prob = load_problem(_write(tmp_path, ROLLER.replace("FORMULATION", "fbar")))
    rep = check_tangent(prob, step=5, columns=30)
    zones = rep["zones"]
    assert rep["columns"] == 30 and zones["contact"] > 0 and zones["plastic"] > 0
    assert sum(zones.values()) == 30
    np.testing.assert_array_less(0.0, [r["h"] for r in rep["by_step_size"]])


#: a strip of Swift-hardening solid-shells bent by two rigid cylinders (half of a three-point bend,
#: frictionless): plastic hinge under the punch, the support's contact zone moving along the strip
SHELL = """
[problem]
name = "shell-three-point-bend"
[[bodies]]
name = "strip"
element = "hex8"
formulation = "solid-shell"
material = { model = "j2", E = 210000.0, nu = 0.3, yield_stress = 238.86430233209836, hardening = { law = "swift", K = 600.0, eps0 = 0.01, n = 0.2 } }
mesh = { generator = "block", lx = 45.0, ly = 2.0, lz = 1.0, nx = 15, ny = 1, nz = 1 }
[[rigid]]
name = "punch"
shape = "cylinder"
center = [0.0, 0.0, 6.0]
axis = [0.0, 1.0, 0.0]
radius = 5.0
motion = { translation = [0.0, 0.0, -4.0] }
[[rigid]]
name = "support"
shape = "cylinder"
center = [35.0, 0.0, -5.0]
axis = [0.0, 1.0, 0.0]
radius = 5.0
[[contact]]
name = "top"
slave = "strip.zmax"
master = "punch"
penalty = 1.0e5
weighting = "area"
[[contact]]
name = "bottom"
slave = "strip.zmin"
master = "support"
penalty = 1.0e5
weighting = "area"
[[dirichlet]]
set = "strip.xmin"
components = "x"
[[dirichlet]]
set = "strip.ymin"
components = "y"
[[dirichlet]]
set = "strip.ymax"
components = "y"
[steps]
count = 8
"""


def test_solid_shell_strip_with_contact_kinks(tmp_path):
    """Swift-hardening solid-shells (EAS, 5 thickness points) bent by two cylinders: the run needs cutbacks
    (inverted elements in its first attempts), which the check makes as the run does; at the last step the
    support's contact zone has slave nodes within h of opening, listed as contact kinks; PASS at 1e-6."""
    prob = load_problem(_write(tmp_path, SHELL))
    rep = check_tangent(prob, step=8, columns=None)
    assert rep["converged"] and rep["load_factor"] == 1.0 and rep["cutbacks"] > 0
    assert rep["relative_error"] <= TOL and rep["judged"] == rep["columns"]
    contact = [k for k in rep["kinks"] if any("contact bottom" in c for c in k["changes"])]
    assert contact and all(k["error"] <= TOL for k in contact)
    assert rep["zones"]["plastic"] > 0 and rep["zones"]["contact"] > 0
