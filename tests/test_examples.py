"""Every example problem runs with `covcontact run` and converges."""

import json
from pathlib import Path

import pytest

from covcontact.cli import main
from covcontact.io.loader import load_problem

ROOT = Path(__file__).resolve().parents[1]
#: examples that take minutes; each is run at a CI size by its own test (same file, shorter loading)
LONG = {"forming/uchannel": "tests/verification/test_uchannel.py",
        "contact/oring_groove": "tests/verification/test_oring.py",  # (these tests run them whole)
        "contact/tube_crush": "tests/verification/test_tube_crush.py",
        "contact/tube_crush_half": "tests/verification/test_tube_crush.py"}
EXAMPLES = sorted(p for sub in ("solid", "contact", "verification", "plasticity", "forming", "dynamics")
                  for p in (ROOT / "examples" / sub).glob("*.toml") if f"{sub}/{p.stem}" not in LONG)


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: f"{p.parent.name}/{p.stem}")
def test_example_runs(tmp_path, path):
    code = main(["run", str(path), "--out", str(tmp_path), "--quiet"])
    assert code == 0
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["converged"]
    assert all(s["converged"] for s in summary["steps"])
    assert "warnings" not in summary, summary["warnings"]  # no example looks wrong to the guard rails
    if load_problem(path).output.vtu:
        assert (tmp_path / "result.pvd").exists()


@pytest.mark.parametrize("path", sorted((ROOT / "examples").rglob("*.toml")), ids=lambda p: p.stem)
def test_header_true_to_the_file(path):
    """What an example's header comment says about the Newton criterion is what the file sets."""
    header = " ".join(line.lstrip("# ") for line in path.read_text().splitlines() if line.startswith("#"))
    criterion = load_problem(path).solver.criterion
    if "with the energy criterion" in header:
        assert criterion in ("energy", "both"), path
    if "on the residual" in header:
        assert criterion in ("residual", "both"), path


@pytest.mark.parametrize("name", sorted(LONG))
def test_long_examples_have_a_ci_size_test(name):
    test = ROOT / LONG[name]
    assert (ROOT / "examples" / f"{name}.toml").exists() and f"{name}.toml" in test.read_text()


@pytest.mark.parametrize("path", sorted((ROOT / "examples" / "decks").glob("*.inp")), ids=lambda p: p.stem)
def test_deck_example_runs(tmp_path, path):
    """Every example deck runs as it is (`covcontact run DECK.inp`) and prints its requests to the .dat table."""
    code = main(["run", str(path), "--out", str(tmp_path), "--quiet"])
    assert code == 0
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["converged"] and all(s["converged"] for s in summary["steps"])
    dat = (tmp_path / f"{path.stem}.dat").read_text()
    requests = path.read_text().upper().count("*NODE PRINT")
    assert dat.count(" for set ") >= requests > 0
