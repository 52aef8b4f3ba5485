"""A new user's first hour on a small problem: the CLI run, its Python twin, check-tangent and the study;
every output exists, parses and agrees with the others."""

import csv
import json
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import meshio
import numpy as np

from covcontact.cli import main
from covcontact.io.loader import load_problem

ROOT = Path(__file__).resolve().parents[1]
PROBLEM = ROOT / "examples" / "contact" / "block_on_sphere.toml"


def cli(args, capsys):
    code = main([str(a) for a in args])
    cap = capsys.readouterr()
    return code, cap.out, cap.err


def test_first_hour(tmp_path, capsys):
    # 1. the command line run: exit 0, a progress line per step, the files the README promises
    code, _, err = cli(["run", PROBLEM, "--out", tmp_path / "cli", "--tangent", "exact"], capsys)
    assert code == 0, err
    out = tmp_path / "cli"
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "completed" and summary["converged"] is True
    steps = summary["steps"]
    assert len(steps) == len(load_problem(PROBLEM).steps.factors)
    progress = [ln for ln in err.splitlines() if re.match(r"step\s+\d+/\d+", ln)]
    assert [int(re.match(r"step\s+(\d+)/", ln).group(1)) for ln in progress] == [s["step"] for s in steps]
    with open(out / "convergence.csv") as fh:
        rows = list(csv.DictReader(fh))
    # one row per iteration plus the predictor row (iteration 0) of every step
    assert len(rows) == summary["total_iterations"] + len(steps)
    assert {int(r["step"]) for r in rows} == {s["step"] for s in steps}
    pvd = ET.parse(out / "result.pvd").getroot()
    files = [d.get("file") for d in pvd.iter("DataSet")]
    assert files and all((out / f).exists() for f in files)
    last = meshio.read(out / files[-1])
    assert np.isfinite(last.point_data["displacement"]).all()
    assert np.nanmax(last.point_data["contact_pressure"]) > 0
    # the contact force acts on the block (slave side) and, opposite, on the sphere
    on = steps[-1]["contact_force_on"]
    np.testing.assert_allclose(on["block"], steps[-1]["contact_force"], rtol=1e-12)
    np.testing.assert_allclose(on["ball"], -np.array(steps[-1]["contact_force"]), rtol=1e-12)

    # 2. the same from Python: the same iterations per step and the same contact force
    result = load_problem(PROBLEM).run(out=tmp_path / "api", tangent="exact", quiet=True)
    assert result.exit_code == 0
    api = result.summary["steps"]
    assert [s["iterations"] for s in api] == [s["iterations"] for s in steps]
    np.testing.assert_allclose(np.array(api[-1]["contact_force"]), np.array(steps[-1]["contact_force"]),
                               rtol=1e-10, atol=1e-12)

    # 3. check-tangent at the last step: the exact tangent passes the default tolerance
    code, text, _ = cli(["check-tangent", PROBLEM, "--step", str(len(steps)), "--columns", "20"], capsys)
    assert code == 0 and "PASS" in text

    # 4. the study on three cases: the exact case repeats the run's iterations; the files parse
    code, _, err = cli(["study", PROBLEM, "--cases", "a,d,exact", "--out", tmp_path / "study", "--quiet"],
                       capsys)
    assert code == 0, err
    study = tmp_path / "study"
    with open(study / "table.csv") as fh:
        table = list(csv.DictReader(fh))
    exact = [int(r["iterations"]) for r in table if r["case"] == "exact"]
    assert exact == [s["iterations"] for s in steps]
    assert {r["case"] for r in table} == {"a", "d", "exact"}
    assert (study / "table.md").read_text().count("|") > 10
    assert (study / "iterations.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
