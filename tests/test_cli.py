"""The command line: a run of an example, and every bad-input case giving exit code 2 and one line."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

from covcontact.cli import main

ROOT = Path(__file__).resolve().parents[1]

GOOD = """
[problem]
name = "tiny"

[[bodies]]
name = "cube"
element = "hex8"
material = { model = "svk", E = 100.0, nu = 0.3 }
mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 1.0, nx = 2, ny = 2, nz = 2 }

[[dirichlet]]
set = "cube.zmin"
components = "xyz"

[[pressure]]
set = "cube.zmax"
value = 1.0

[steps]
count = 2
"""


def write(tmp_path: Path, text: str, name: str = "p.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def run_cli(args, capsys):
    code = main([str(a) for a in args])
    cap = capsys.readouterr()
    return code, cap.out, cap.err


def test_run_good_problem(tmp_path, capsys):
    path = write(tmp_path, GOOD)
    code, _, err = run_cli(["run", path, "--out", tmp_path / "out"], capsys)
    assert code == 0, err
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["converged"] and len(summary["steps"]) == 2
    assert (tmp_path / "out" / "result.pvd").exists()
    assert (tmp_path / "out" / "step_0002.vtu").exists()
    lines = (tmp_path / "out" / "convergence.csv").read_text().splitlines()
    assert lines[0] == ("step,iteration,residual_norm,energy_norm,active_contacts,linear,krylov_iterations,"
                        "status_changes")
    # the predictor row, then a factorisation; no contact, so no status changes
    assert lines[1].split(",")[5:] == ["", "0", "0"] and lines[2].split(",")[5:] == ["factor", "0", "0"]
    assert "step    1/2" in err and "time:" in err
    # pressure 1 pushes the unit top face down; the support pushes the body up by 1
    react = summary["steps"][-1]["reactions"]["cube.zmin"]
    assert react[2] == pytest.approx(1.0, rel=1e-8)


def test_quiet_prints_nothing(tmp_path, capsys):
    path = write(tmp_path, GOOD)
    code, out, err = run_cli(["run", path, "--out", tmp_path / "o", "--quiet"], capsys)
    assert code == 0 and err == "" and out == ""


BAD_CASES = {
    "missing-key": (GOOD.replace('name = "tiny"', ""), "problem.name: missing required key"),
    "unknown-key": (GOOD.replace("count = 2", "count = 2\ncuont = 3"), "steps.cuont: unknown key"),
    "misspelled-material-key": (GOOD.replace("E = 100.0", "EE = 100.0"), "bodies[0].material"),
    "wrong-type": (GOOD.replace("count = 2", 'count = "two"'), "steps.count: must be an integer"),
    "zero-modulus": (GOOD.replace("E = 100.0", "E = 0.0"), "bodies[0].material.E: must be > 0"),
    "bad-poisson": (GOOD.replace("nu = 0.3", "nu = 0.5"), "bodies[0].material.nu"),
    "negative-thickness": (GOOD.replace('generator = "block", lx = 1.0, ly = 1.0, lz = 1.0, nx = 2, ny = 2, nz = 2',
                                        'generator = "plate", lx = 1.0, ly = 1.0, t = -0.1, nx = 2, ny = 2'),
                           "bodies[0].mesh"),
    "unknown-element": (GOOD.replace('element = "hex8"', 'element = "hex64"'), "bodies[0].element"),
    "unknown-set": (GOOD.replace('set = "cube.zmin"', 'set = "cube.bottom"'), "has no node set 'bottom'"),
    "unknown-body": (GOOD.replace('set = "cube.zmin"', 'set = "ball.zmin"'), "no body named 'ball'"),
    "unknown-generator": (GOOD.replace('generator = "block"', 'generator = "brick"'), "generator"),
    "generator-arg": (GOOD.replace("nz = 2 }", "nz = 2, nw = 3 }"), "nw: unknown key for generator"),
    "bad-components": (GOOD.replace('components = "xyz"', 'components = "xq"'), "components"),
    "bad-steps": (GOOD.replace("count = 2", "factors = [0.5, 0.2]"), "steps.factors"),
    "missing-mesh-file": (GOOD.replace('mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 1.0, nx = 2, '
                                       'ny = 2, nz = 2 }', 'mesh = { file = "nowhere.msh" }'),
                          "does not exist"),
    "mesh-path-shown": (GOOD.replace('mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 1.0, nx = 2, '
                                     'ny = 2, nz = 2 }', 'mesh = { file = "meshes/nowhere.msh" }'),
                        "meshes/nowhere.msh; a relative path is taken from the problem file's folder"),
    "suggest-key": (GOOD.replace('components = "xyz"', 'component = "xyz"'),
                    "dirichlet[0].component: unknown key; did you mean 'components'?"),
    "suggest-misspelt-required": (GOOD.replace("material = {", "materal = {"),
                                  "bodies[0].material: missing required key (found 'materal'"),
    "suggest-section": (GOOD.replace("[steps]", "[step]"), "step: unknown section; did you mean 'steps'?"),
    "suggest-set": (GOOD.replace('set = "cube.zmin"', 'set = "cube.zmni"'), "did you mean 'zmin'?"),
    "suggest-body": (GOOD.replace('set = "cube.zmin"', 'set = "cueb.zmin"'),
                     "no body named 'cueb'; did you mean 'cube'?"),
    "suggest-choice": (GOOD.replace('model = "svk"', 'model = "SVK"'), "did you mean 'svk'?"),
    "suggest-generator-key": (GOOD.replace("nz = 2 }", "nzz = 2 }"), "did you mean 'nz'?"),
    "bad-tangent": (GOOD + '\n[[rigid]]\nname = "floor"\nshape = "plane"\npoint = [0.0, 0.0, 0.0]\n'
                           'normal = [0.0, 0.0, 1.0]\n\n[[contact]]\nslave = "cube.zmin"\nmaster = "floor"\n'
                           'penalty = 1.0\ntangent = "e"\n', "contact[0].tangent"),
    "same-surface": (GOOD + '\n[[contact]]\nslave = "cube.zmax"\nmaster = "cube.zmax"\npenalty = 1.0\n',
                     "contact[0].master: slave and master are the same surface 'cube.zmax': a surface in contact "
                     "with itself is self-contact: write self = \"cube.zmax\""),
    "area-weighting-on-nodes": (GOOD.replace("[steps]", '[bodies.sets]\ntop = { box = [[-1.0, -1.0, 0.9], [2.0, 2.0, '
                                                       '1.1]] }\n\n[steps]') + '\n[[rigid]]\nname = "floor"\n'
                                'shape = "plane"\npoint = [0.0, 0.0, 2.0]\nnormal = [0.0, 0.0, -1.0]\n\n[[contact]]\n'
                                'slave = "cube.top"\nmaster = "floor"\npenalty = 1.0\nweighting = "area"\n',
                                'contact[0].slave: weighting = "area" needs the slave\'s faces, but cube.top is a node '
                                "set only: give a face set of 'cube'"),
}


@pytest.mark.parametrize("case", sorted(BAD_CASES))
def test_bad_input_one_line_exit_2(tmp_path, capsys, case):
    text, expect = BAD_CASES[case]
    path = write(tmp_path, text)
    code, out, err = run_cli(["run", path, "--out", tmp_path / "o"], capsys)
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert str(path) in lines[0]
    assert expect in lines[0], lines[0]
    assert "Traceback" not in err


def test_missing_file_and_syntax_error(tmp_path, capsys):
    code, _, err = run_cli(["run", tmp_path / "none.toml"], capsys)
    assert code == 2 and "does not exist" in err and len(err.strip().splitlines()) == 1
    path = write(tmp_path, GOOD.replace("count = 2", "count = = 2"))
    code, _, err = run_cli(["run", path], capsys)
    assert code == 2 and "TOML syntax error" in err and "line" in err
    assert len(err.strip().splitlines()) == 1


def test_mesh_file_that_does_not_parse(tmp_path, capsys):
    (tmp_path / "junk.msh").write_text("this is not a mesh\n")
    text = GOOD.replace('mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 1.0, nx = 2, ny = 2, nz = 2 }',
                        'mesh = { file = "junk.msh" }')
    path = write(tmp_path, text)
    code, _, err = run_cli(["run", path], capsys)
    assert code == 2 and "junk.msh" in err and len(err.strip().splitlines()) == 1


def test_empty_node_set(tmp_path, capsys):
    inp = ["*NODE"]
    k = 1
    for z in (0, 1):
        for y in (0, 1):
            for x in (0, 1):
                inp.append(f"{k}, {x}.0, {y}.0, {z}.0")
                k += 1
    inp += ["*ELEMENT, TYPE=C3D8, ELSET=ALL", "1, 1, 2, 4, 3, 5, 6, 8, 7",
            "*NSET, NSET=BASE", "1, 2, 3, 4", "*NSET, NSET=NOTHING"]
    (tmp_path / "cube.inp").write_text("\n".join(inp) + "\n")
    text = GOOD.replace('mesh = { generator = "block", lx = 1.0, ly = 1.0, lz = 1.0, nx = 2, ny = 2, nz = 2 }',
                        'mesh = { file = "cube.inp" }')
    text = text.replace('set = "cube.zmin"', 'set = "cube.NOTHING"')
    path = write(tmp_path, text)
    code, _, err = run_cli(["run", path], capsys)
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "NOTHING" in err


def test_unknown_solver_and_case(tmp_path, capsys):
    path = write(tmp_path, GOOD)
    code, _, err = run_cli(["run", path, "--solver", "nonesuch"], capsys)
    assert code == 2 and "nonesuch" in err
    code, _, err = run_cli(["study", path, "--cases", "a,q"], capsys)
    assert code == 2 and "'q'" in err


def test_ranks_refused_with_one_line(tmp_path, capsys):
    # checked before MPI is looked for: a count below 1, more than 8 ranks per core
    path = write(tmp_path, GOOD)
    code, _, err = run_cli(["run", path, "--ranks", "0"], capsys)
    assert code == 2 and err.count("\n") == 1 and "at least 1" in err
    code, _, err = run_cli(["run", path, "--ranks", "100000"], capsys)
    assert code == 2 and err.count("\n") == 1 and "cores" in err


def test_nonconverging_step_exit_1(tmp_path, capsys):
    # a load far beyond what the tiny budget of iterations and cutbacks can carry
    text = GOOD.replace("value = 1.0", "value = 80.0").replace(
        "count = 2", "count = 2\n\n[solver]\nmax_iterations = 2\nmax_cutbacks = 1")
    path = write(tmp_path, text)
    code, _, err = run_cli(["run", path, "--out", tmp_path / "o"], capsys)
    assert code == 1
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["converged"] is False
    assert summary["steps"][-1]["converged"] is False
    assert "FAILED" in err


def test_info(capsys):
    code, out, _ = run_cli(["info"], capsys)
    assert code == 0 and "covcontact" in out and "superlu" in out and "threads" in out
    assert "MPI ranks: " in out  # what --ranks auto may start here


def test_console_script_runs(tmp_path):
    """The installed entry point, as a user calls it."""
    path = write(tmp_path, GOOD)
    proc = subprocess.run([sys.executable, "-m", "covcontact.cli", "run", str(path), "--out",
                           str(tmp_path / "o"), "--quiet"], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "o" / "summary.json").exists()


def test_module_command_flushes_and_keeps_the_exit_code(tmp_path):
    """``python -m covcontact`` leaves without tearing the interpreter down: what it printed is all there,
    its result files are complete and its exit code is main's."""
    path = write(tmp_path, GOOD)
    proc = subprocess.run([sys.executable, "-m", "covcontact", "run", str(path), "--out", str(tmp_path / "o")],
                          capture_output=True, text=True, check=False)
    assert proc.returncode == 0, proc.stderr
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["status"] == "completed" and f"results in {tmp_path / 'o'}" in proc.stderr
    bad = subprocess.run([sys.executable, "-m", "covcontact", "run", str(tmp_path / "missing.toml")],
                         capture_output=True, text=True, check=False)
    assert bad.returncode == 2 and bad.stderr.startswith("covcontact: error:") and "missing.toml" in bad.stderr


def test_closed_output_pipe_is_no_traceback():
    """``covcontact info | head -1``: the reader leaves early; the command stops without a traceback."""
    proc = subprocess.Popen([sys.executable, "-m", "covcontact", "info"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    proc.stdout.close()  # before the command writes: its first write meets a closed pipe
    err = proc.stderr.read()
    proc.stderr.close()
    assert proc.wait(timeout=120) in (0, 141) and "Traceback" not in err, err


def test_every_option_has_help():
    """`covcontact CMD --help` explains every option (argparse shows no text for options without help)."""
    from covcontact.cli import _parser

    parser = _parser()
    subs = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    for name, sub in subs.choices.items():
        assert sub.description, name
        for action in sub._actions:
            assert action.help, f"{name}: {action.dest} has no help text"


def test_check_tangent_verdict_and_exit_code(tmp_path, capsys):
    problem = ROOT / "examples" / "contact" / "block_on_sphere.toml"
    code, out, _ = run_cli(["check-tangent", problem, "--step", "1", "--columns", "12"], capsys)
    err = float(out.splitlines()[0].split("relative error")[1])
    assert code == 0 and out.splitlines()[1].startswith("PASS") and err < 1e-6
    # the main part alone is not the consistent tangent of a curved surface: a verdict of failure, exit 1
    code, out, _ = run_cli(["check-tangent", problem, "--step", "1", "--columns", "12", "--tangent", "d"], capsys)
    assert code == 1 and out.splitlines()[1].startswith("FAIL") and "--tangent exact" in out
    # a tolerance below the measured error of the exact tangent fails too
    code, out, _ = run_cli(["check-tangent", problem, "--step", "1", "--columns", "12", "--tol",
                            f"{err / 10:.3e}"], capsys)
    assert code == 1 and "FAIL" in out
    code, _, stderr = run_cli(["check-tangent", problem, "--tol", "-1"], capsys)
    assert code == 2 and "--tol" in stderr


def test_output_files_have_the_users_permissions(tmp_path, capsys):
    """Every file of a run gets 0666 less the umask, as the pictures do, not a temporary file's 0600."""
    import os
    import stat

    path = write(tmp_path, GOOD.replace("count = 2", "count = 2\n\n[output]\npictures = true"))
    old = os.umask(0o027)
    try:
        code, _, _ = run_cli(["run", path, "--out", tmp_path / "o", "--quiet"], capsys)
    finally:
        os.umask(old)
    assert code == 0
    files = [f for f in (tmp_path / "o").rglob("*") if f.is_file()]
    names = {f.name for f in files}
    assert {"summary.json", "convergence.csv", "result.pvd", "step_0001.vtu", "checkpoint.npz"} <= names, names
    assert any(n.endswith(".png") for n in names), names
    for f in files:
        assert stat.S_IMODE(f.stat().st_mode) == 0o640, (f.name, oct(f.stat().st_mode))


def test_compile_command(capsys):
    """`covcontact compile` runs its warm-up problems (here one of them) and says what it did, and leaves the
    bytecode of every covcontact module written (as a pip installation has it), even where Python itself writes
    none (PYTHONDONTWRITEBYTECODE)."""
    import importlib.util

    import covcontact

    package = Path(covcontact.__file__).parent
    sources = sorted(package.rglob("*.py"))
    probe = Path(importlib.util.cache_from_source(str(package / "warmup.py")))
    probe.unlink(missing_ok=True)
    code, _, err = run_cli(["compile", "--only", "plane with friction"], capsys)
    assert code == 0, err
    assert "compiled hex8 on a plane with friction" in err and "1 warm-up problems" in err
    missing = [str(p) for p in sources if not Path(importlib.util.cache_from_source(str(p))).is_file()]
    assert probe.is_file() and missing == []
    code, _, err = run_cli(["compile", "--only", "no such label"], capsys)
    assert code == 2 and "--only" in err and len(err.strip().splitlines()) == 1


def test_warmup_problems_are_quiet_and_converge(capsys):
    """Every warm-up problem is a valid, converging problem without start warnings."""
    from covcontact.warmup import PROBLEMS, warm

    done = warm()
    assert [label for label, _ in done] == [label for label, _ in PROBLEMS]
    err = capsys.readouterr().err
    assert "warning" not in err and err.count("covcontact: compiled") == len(PROBLEMS)


def test_parallel_warm_up_runs_every_problem():
    """`covcontact compile` on several cores: worker processes share the warm-up problems by whole groups of kernels
    (each problem in exactly one group), and every problem converges (a failing one raises in its worker)."""
    from covcontact.warmup import GROUPS, PROBLEMS, warm_parallel

    members = sorted(i for group, _ in GROUPS for i in group)
    assert members == list(range(len(PROBLEMS)))
    done = warm_parallel(2, quiet=True)
    assert [label for label, _ in done] == [label for label, _ in PROBLEMS]


RATTLE = """
[problem]
name = "rattle"
procedure = "dynamic"
dt = 0.02
t_end = 0.3
method = "newmark"
mass = "consistent"
[[bodies]]
name = "bar"
material = { model = "svk", E = 1.0, nu = 0.0, density = 1.0 }
mesh = { generator = "block", lx = 1.0, ly = 0.1, lz = 0.1, nx = 50, ny = 1, nz = 1 }
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
[[initial_velocity]]
body = "bar"
value = [0.01, 0.0, 0.0]
[output]
vtu = false
"""


def test_energy_growth_warns_and_strict_fails(tmp_path, capsys):
    """A bar on a wall with the consistent mass chosen (tests/verification/test_bar_impact.py): the run says at its
    start that the mass can rattle, warns once when the energy grows and completes; with --strict it ends there as
    failed (exit 1) with the step and the growth, the converged steps kept."""
    path = write(tmp_path, RATTLE)
    code, _, err = run_cli(["run", path, "--out", tmp_path / "a"], capsys)
    assert code == 0, err
    assert "note: mass = \"consistent\" with contact" in err
    assert err.count("warning: step") == 1 and "the bodies' energy grows" in err
    s = json.loads((tmp_path / "a" / "summary.json").read_text())
    assert s["status"] == "completed" and s["energy_growth"]["step"] >= 1
    code, _, err = run_cli(["run", path, "--out", tmp_path / "b", "--strict", "--quiet"], capsys)
    assert code == 1
    s = json.loads((tmp_path / "b" / "summary.json").read_text())
    assert s["status"] == "failed" and s["reason"].startswith(f"--strict: step {s['energy_growth']['step']}:")
    assert len(s["steps"]) == s["energy_growth"]["step"]


def test_ranks_with_a_deck_is_said_not_ignored(tmp_path, capsys):
    """`covcontact run DECK.inp --ranks 2`: a deck runs in one process, so the option is one line (exit 2), not
    dropped in silence."""
    deck = Path(__file__).resolve().parents[1] / "examples" / "decks" / "punch_slide.inp"
    assert main(["run", str(deck), "--out", str(tmp_path), "--ranks", "2", "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--ranks 2: a deck runs in one process" in err[0]
